//! A moving camera's frame ([`Fill::Sparse`]). The cache of `cache.rs`
//! would be refilled every frame, and there the radiosity lookup's weights
//! are the largest part of the work: here they are looked up only at every
//! other pixel in each direction (the anchors), and the pixels between take
//! the mean of their neighbouring anchors' indirect irradiance where those
//! lie on the same surface close by: bilinear interpolation across the
//! screen of a quantity that varies over the kernel's radius (a patch and a
//! half), not over a pixel. Direct light, shadows and edges stay per pixel.
//! The viewer renders so while the camera moves and goes back to
//! [`Fill::Exact`] when it stops.
//!
//! Such a frame's texels serve it alone, so none are kept: the anchors'
//! pixels are traced, looked up and shaded first, then each row's other
//! texels are made, shaded and dropped in a buffer of the thread's (a kept
//! frame of texels, 100 bytes a pixel, was written and read back through
//! memory every frame).

use super::Preview;
use super::cache::{FirstSample, Indirect, ROWS, RowScratch, Rows, Span, Texel, light_surfaces, trace_texels};
use crate::film::Image;
use crate::geometry::{Geometry, Ray, SurfaceHit};
use crate::radiosity::Radiosity;
use crate::scene::Scene;
use crate::scratch::with_scratch;
use crate::{CameraRays, Rgb};
use glam::Vec3;
use rayon::prelude::*;

#[cfg(doc)]
use super::Fill;

/// What the texels between anchors read of one, packed: its hit's point,
/// its normal on the ray's side, and the indirect irradiance there this
/// frame (None without a hit or without a patch near).
#[derive(Clone, Copy, Default)]
pub(super) struct Anchor {
    p: Vec3,
    n: Vec3,
    pub e: Option<Rgb>,
}

impl FirstSample {
    /// Sample 0 of every pixel with the indirect light interpolated
    /// between anchors (see the module documentation).
    pub(super) fn render_sparse(&mut self, scene: &Scene, solution: Option<&Radiosity>, preview: &Preview) -> Image {
        // A kept exact fill's texels stay allocated for the next one, but
        // they no longer serve this view.
        self.key = None;
        let lights = light_surfaces(scene);
        let (w, h) = (scene.settings().film.width as usize, scene.settings().film.height as usize);
        let camera = scene.camera().rays(w as u32, h as u32);
        let mut image = Image::new(w as u32, h as u32);
        if let Some(solution) = solution {
            self.shade_anchors(scene, solution, preview, &lights, &camera, &mut image);
        }
        let (objects, anchors) = (&self.objects, &self.anchors);
        image.pixels.par_chunks_mut(w.max(1)).enumerate().for_each(|(y, row)| {
            with_scratch(&ROWS, |scratch| {
                let RowScratch { tracing, light_hits, shading, texels } = scratch;
                // On an anchors' row, the anchors' pixels are done.
                let anchors_row = solution.is_some() && y.is_multiple_of(2);
                let span = if anchors_row { Span { y, first: 1, step: 2 } } else { Span::whole(y) };
                texels.resize(span.columns(w).len(), Texel::empty());
                trace_texels(scene, objects, &camera, span, tracing, texels);
                if solution.is_some() {
                    for texel in texels.iter_mut().filter(|t| t.hit.is_some()) {
                        texel.indirect = Indirect::Anchors;
                    }
                }
                light_hits.find(&lights, texels);
                let rows = Rows { scene, solution, preview, lights: &lights, weights: &[], anchors };
                rows.shade(span, texels, &light_hits.hits, row, shading);
            });
        });
        image
    }

    /// The anchors' pixels, each with its own lookup of the indirect
    /// irradiance with the solution's values now, into `image`, and the
    /// anchors, for the pixels between to read: (w/2) × (h/2) of them,
    /// rounded up.
    ///
    /// An anchor whose camera ray meets a light's surface before its object
    /// lends nothing: the ceiling behind a light is in the light's shadow,
    /// unlike the ceiling beside it that the pixels between may see.
    fn shade_anchors(
        &mut self,
        scene: &Scene,
        solution: &Radiosity,
        preview: &Preview,
        lights: &Geometry,
        camera: &CameraRays,
        image: &mut Image,
    ) {
        let (w, h) = (scene.settings().film.width as usize, scene.settings().film.height as usize);
        let (columns, rows) = (w.div_ceil(2), h.div_ceil(2));
        self.anchors.resize(columns * rows, Anchor::default());
        let objects = &self.objects;
        let pairs_of_rows = image.pixels.par_chunks_mut(2 * w.max(1));
        pairs_of_rows.zip(self.anchors.par_chunks_mut(columns.max(1))).enumerate().for_each(|(j, (pixels, row))| {
            with_scratch(&ROWS, |scratch| {
                let RowScratch { tracing, light_hits, shading, texels } = scratch;
                let span = Span { y: 2 * j, first: 0, step: 2 };
                texels.resize(columns, Texel::empty());
                trace_texels(scene, objects, camera, span, tracing, texels);
                light_hits.find(lights, texels);
                for ((anchor, texel), light) in row.iter_mut().zip(texels.iter_mut()).zip(&light_hits.hits) {
                    *anchor = match &texel.hit {
                        Some(_) if light.is_some() => Anchor::default(),
                        Some(s) => {
                            let n = s.facing(texel.ray.dir);
                            // The same bits as the exact fill's weights summed.
                            Anchor { p: s.p, n, e: solution.irradiance_at(s.p, n) }
                        }
                        None => Anchor::default(),
                    };
                    texel.indirect = Indirect::Given(anchor.e);
                }
                let rows = Rows { scene, solution: Some(solution), preview, lights, weights: &[], anchors: &[] };
                rows.shade(span, texels, &light_hits.hits, &mut pixels[..w], shading);
            });
        });
    }
}

/// The indirect irradiance at pixel (x, y) of a `w`×`h` sparse frame, a
/// texel between anchors whose ray hit `surface` (see
/// [`Indirect::Anchors`]).
pub(super) fn between_anchors(
    anchors: &[Anchor],
    solution: &Radiosity,
    surface: &SurfaceHit,
    ray: &Ray,
    at: (usize, usize),
    size: (usize, usize),
) -> Option<Rgb> {
    let ((x, y), (w, h)) = (at, size);
    let (n, radius) = (surface.facing(ray.dir), solution.lookup().radius());
    let around = |k: usize| if k.is_multiple_of(2) { ([k, k], 1) } else { ([k - 1, k + 1], 2) };
    let ((xs, nx), (ys, ny)) = (around(x), around(y));
    let mut sum = Rgb::ZERO;
    for &ay in &ys[..ny] {
        for &ax in &xs[..nx] {
            let anchor = (ax < w && ay < h).then(|| anchors[anchor_index(ax, ay, w)]);
            match anchor {
                Some(Anchor { p, n: m, e: Some(e) }) if same_surface(surface.p, n, p, m, radius) => sum += e,
                // An edge of the image, a silhouette or a crease
                // between: interpolation would reach across it.
                _ => return solution.irradiance_at(surface.p, n),
            }
        }
    }
    Some(sum / (nx * ny) as f32)
}

/// The index in a frame's anchors of the anchor at pixel (x, y)
/// (both even) of an image `w` pixels wide.
pub(super) fn anchor_index(x: usize, y: usize, w: usize) -> usize {
    y / 2 * w.div_ceil(2) + x / 2
}

/// Whether an anchor's hit at `q` (normal `m`, on the ray's side) may lend
/// its irradiance to a hit at `p` (normal `n`): nearly the same normal,
/// nearly the same plane and within half the kernel's radius, so that the
/// kernel's average changes little and smoothly between them. Across a
/// silhouette or a crease it fails, and the pixel looks up its own.
fn same_surface(p: Vec3, n: Vec3, q: Vec3, m: Vec3, radius: f32) -> bool {
    let d = q - p;
    n.dot(m) >= 0.99 && n.dot(d).abs() <= 0.02 * radius && d.length_squared() <= (0.5 * radius) * (0.5 * radius)
}

#[cfg(test)]
mod tests {
    use super::super::Fill;
    use super::*;
    use crate::film::PixelFilter;
    use crate::integrator::{AnalyticOptions, RadiosityOptions, RaymarchOptions};
    use crate::render::{RenderObserver, render_samples};
    use crate::{Camera, SceneFile};
    use glam::vec3;

    const CORNELL: &str = include_str!("../../../../scenes/cornell_box.toml");

    /// The largest error of a pixel relative to its value, the mean error
    /// relative to the mean value, and the share of pixels that differ, of
    /// a sparse render against the exact one, whose anchors must be the
    /// same bits.
    fn sparse_against_exact(scene: &Scene, sparse: &Image, exact: &Image) -> (f32, f32, f32) {
        let (w, h) = (scene.settings().film.width, scene.settings().film.height);
        let (mut differ, mut worst, mut total_error, mut total) = (0, 0.0f32, 0.0f32, 0.0f32);
        for y in 0..h {
            for x in 0..w {
                let (a, b) = (sparse.pixel(x, y), exact.pixel(x, y));
                if x % 2 == 0 && y % 2 == 0 {
                    assert_eq!(a, b, "anchor ({x}, {y})");
                }
                let error = (a - b).abs().max_element();
                differ += (error > 0.0) as u32;
                worst = worst.max(error / b.max_element().max(1e-3));
                (total_error, total) = (total_error + error, total + b.max_element());
            }
        }
        (worst, total_error / total, differ as f32 / (w * h) as f32)
    }

    /// The sparse fill against the exact one, from a camera in the room
    /// looking into a corner past the boxes (silhouettes, creases, walls at
    /// a slant), and from the scene's own camera (the ceiling and floor
    /// seen at a slant up to the back wall): the anchors' pixels are the
    /// same bits, every other pixel within a small part of its value, and
    /// an exact render of the same view refills and gives the exact image
    /// again. Camera rays through pixel centres: with jitter, the exact
    /// image's own sub-pixel offsets would be measured too.
    #[test]
    fn a_sparse_fill_interpolates_the_indirect_light_closely_and_keeps_the_anchors_exact() {
        let mut scene = SceneFile::from_toml_str(CORNELL, None).unwrap().scene;
        scene.settings_mut().film.filter = PixelFilter::Point;
        let options = RadiosityOptions::default();
        let solution = Radiosity::compile(&scene, &options).unwrap();
        let own = *scene.camera();
        let corner = Camera::look_at(vec3(2.0, 2.0, -1.0), vec3(5.56, 2.0, 2.0), glam::Vec3::Y, 39.3);
        // Measured: 3.0% and 0.017% into the corner at 192×108 (76% and
        // 0.11% if anchors across silhouettes and creases are taken too);
        // 12.7% and 0.017% from the scene's camera at the viewer's 640×360,
        // at worst on the ceiling beside the light seen at a slant (10–13%
        // there) and on the floor at a box's foot, in its shadow (8–13% of
        // a dark pixel). Anchors behind the light, which lent the shadowed
        // ceiling behind it, gave 15.0% before they were left out; 37% with
        // anchors every fourth pixel taken within the whole kernel radius.
        // That camera sees the room through its open side: the background
        // around it has no indirect light to blend.
        let views = [(corner, (192, 108), 0.05, 0.5), (own, (640, 360), 0.14, 0.15)];
        for (camera, (w, h), worst_allowed, blended) in views {
            scene.set_camera(camera);
            (scene.settings_mut().film.width, scene.settings_mut().film.height) = (w, h);
            let preview = Preview::new(&scene, Some(&solution), AnalyticOptions::default(), RaymarchOptions::default());
            let exact = render_samples(&scene, &preview, 0, 1, &RenderObserver::none());
            let mut cache = FirstSample::new(&scene);
            let sparse = cache.render(&scene, Some(&solution), &preview, Fill::Sparse);
            assert!(!cache.is_valid(&scene), "a sparse render keeps no texels");
            let (worst, mean, differ) = sparse_against_exact(&scene, &sparse, &exact);
            assert!(differ > blended, "the pixels between anchors were blended: {differ}");
            assert!(worst < worst_allowed, "{worst}");
            assert!(mean < 5e-4, "{mean}");
            let again = cache.render(&scene, Some(&solution), &preview, Fill::Exact);
            assert_eq!(again, exact);
            assert!(cache.is_valid(&scene), "an exact fill serves a sparse render too");
        }
    }

    /// From the scene's own camera, which sees the light under the
    /// ceiling, with jittered camera rays: a sparse fill's anchors and
    /// every pixel of the light are the exact image's bits.
    #[test]
    fn a_sparse_fill_sees_the_light_where_the_exact_one_does() {
        let mut scene = SceneFile::from_toml_str(CORNELL, None).unwrap().scene;
        (scene.settings_mut().film.width, scene.settings_mut().film.height) = (96, 96);
        let options = RadiosityOptions::default();
        let solution = Radiosity::compile(&scene, &options).unwrap();
        let preview = Preview::new(&scene, Some(&solution), AnalyticOptions::default(), RaymarchOptions::default());
        let exact = render_samples(&scene, &preview, 0, 1, &RenderObserver::none());
        let sparse = FirstSample::new(&scene).render(&scene, Some(&solution), &preview, Fill::Sparse);
        let mut light = 0;
        for y in 0..96 {
            for x in 0..96 {
                let (a, b) = (sparse.pixel(x, y), exact.pixel(x, y));
                // The light's radiance is (34, 24, 8); nothing else is that bright.
                if b.x > 20.0 {
                    assert_eq!(a, b, "light ({x}, {y})");
                    light += 1;
                } else if x % 2 == 0 && y % 2 == 0 {
                    assert_eq!(a, b, "anchor ({x}, {y})");
                }
            }
        }
        assert!(light > 20, "the light covers {light} pixels");
    }
}
