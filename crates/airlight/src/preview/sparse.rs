//! The preview's first sample while the camera moves ([`Fill::Sparse`]):
//! the radiosity lookup only at every other pixel in each direction (the
//! anchors, [`SPACING`]), and the pixels between taking the bilinear
//! interpolation of their neighbouring anchors' indirect irradiance where
//! all of those lie on the same surface within half the kernel's radius:
//! interpolation across the screen of a quantity that varies over the
//! kernel's radius (a patch and a half), not over a pixel. Direct light,
//! shadows and edges stay per pixel.
//!
//! Nothing is cached: a moving camera's next frame sees other hits. The
//! anchors are traced and looked up first, a quarter of the pixels; then
//! each row is traced and shaded in one pass, so the other pixels never go
//! through memory, and each pixel's generator is seeded once.
//!
//! [`Fill::Sparse`]: super::Fill::Sparse

use super::Preview;
use super::cache::{FirstSample, Texel, Traced, camera_drawn, shade, trace};
use crate::Rgb;
use crate::film::Image;
use crate::geometry::SurfaceHit;
use crate::radiosity::Radiosity;
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;

/// The anchors are the pixels of every other column of every other row: a
/// quarter of the pixels look their weights up. Sparser anchors save
/// lookups but interpolate over longer distances on surfaces seen at a
/// slant, where the irradiance bends near a crease (measured on the
/// scene's own view of the Cornell box, 640×360, worst pixel: 12.7% here;
/// 10.3% with every third pixel, 2% faster; 37% with every fourth and
/// anchors within the whole kernel radius, 8% faster; 17% with every
/// fourth within half of it, no faster, a quarter of the pixels between
/// then looking up their own).
const SPACING: usize = 2;

/// An anchor pixel: what its camera ray meets, and the indirect
/// irradiance there this frame (None without a hit, a solution or a patch
/// near).
#[derive(Clone, Copy)]
pub(super) struct Anchor {
    texel: Texel,
    e: Option<Rgb>,
}

impl FirstSample {
    /// Sample 0 with the indirect light interpolated between anchors (see
    /// the module documentation); the cache is left as it was.
    pub(super) fn render_sparse(&mut self, scene: &Scene, solution: Option<&Radiosity>, preview: &Preview) -> Image {
        let s = scene.settings();
        let (w, h) = (s.width as usize, s.height as usize);
        let columns = w.div_ceil(SPACING);
        let camera = scene.camera().rays(s.width, s.height);
        let mut anchors = std::mem::take(&mut self.anchors);
        anchors.resize(columns * h.div_ceil(SPACING), Anchor { texel: Texel::EMPTY, e: None });
        let everything = scene.geometry();
        anchors.par_chunks_mut(columns.max(1)).enumerate().for_each(|(j, row)| {
            for (i, anchor) in row.iter_mut().enumerate() {
                let (texel, _) = trace(scene, everything, &camera, SPACING * i, SPACING * j);
                // The same bits as the exact fill's weights summed; none on
                // a light's surface (it reflects nothing).
                let object = texel.hit.filter(|s| s.emitter.is_none());
                let e =
                    object.zip(solution).and_then(|(s, solution)| solution.irradiance_at(s.p, s.facing(texel.ray.dir)));
                *anchor = Anchor { texel, e };
            }
        });
        let mut image = Image::new(s.width, s.height);
        image.pixels.par_chunks_mut(w.max(1)).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let index = y * w + x;
                *out = if x % SPACING == 0 && y % SPACING == 0 {
                    let anchor = &anchors[y / SPACING * columns + x / SPACING];
                    shade(scene, preview, Traced::Everything, &anchor.texel, camera_drawn(scene, index), |_| anchor.e)
                } else {
                    let (texel, sampler) = trace(scene, everything, &camera, x, y);
                    let indirect = |surface: &SurfaceHit| {
                        let solution = solution?;
                        between_anchors(solution, &anchors, surface, surface.facing(texel.ray.dir), (x, y), (w, h))
                    };
                    shade(scene, preview, Traced::Everything, &texel, sampler, indirect)
                };
            }
        });
        self.anchors = anchors;
        image
    }
}

/// The indirect irradiance at pixel (x, y) of a `w`×`h` image, not an
/// anchor, whose ray hit `surface` (normal `n` on the ray's side): the
/// bilinear interpolation of its anchors' (the two on either side on an
/// anchor row or column, the four around it elsewhere) when all of them
/// lie on its surface near its hit; else its own lookup.
fn between_anchors(
    solution: &Radiosity,
    anchors: &[Anchor],
    surface: &SurfaceHit,
    n: Vec3,
    at: (usize, usize),
    size: (usize, usize),
) -> Option<Rgb> {
    let ((x, y), (w, h)) = (at, size);
    let radius = solution.lookup().radius();
    // The anchors' columns (or rows) on either side and the weight of each.
    let around = |k: usize| {
        let (low, offset) = (k - k % SPACING, (k % SPACING) as f32 / SPACING as f32);
        if offset == 0.0 { ([(low, 1.0), (low, 0.0)], 1) } else { ([(low, 1.0 - offset), (low + SPACING, offset)], 2) }
    };
    let ((xs, nx), (ys, ny)) = (around(x), around(y));
    let mut sum = Rgb::ZERO;
    for &(ay, wy) in &ys[..ny] {
        for &(ax, wx) in &xs[..nx] {
            let anchor = (ax < w && ay < h).then(|| &anchors[ay / SPACING * w.div_ceil(SPACING) + ax / SPACING]);
            match anchor {
                Some(Anchor { texel: Texel { hit: Some(hit), ray, .. }, e: Some(e) })
                    if same_surface(surface.p, n, hit.p, hit.facing(ray.dir), radius) =>
                {
                    sum += *e * (wx * wy)
                }
                // An edge of the image, a silhouette or a crease
                // between: interpolation would reach across it.
                _ => return solution.irradiance_at(surface.p, n),
            }
        }
    }
    Some(sum)
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
    use super::*;
    use crate::integrator::{AnalyticOptions, RadiosityOptions, RaymarchOptions};
    use crate::preview::Fill;
    use crate::render::{RenderObserver, render_samples};
    use crate::scene::PixelFilter;
    use crate::{Camera, SceneFile};
    use glam::vec3;

    const CORNELL: &str = include_str!("../../../../scenes/cornell_box.toml");

    /// The largest error of a pixel relative to its value, the mean error
    /// relative to the mean value, and the share of pixels that differ, of
    /// a sparse render against the exact one, whose anchors must be the
    /// same bits.
    fn sparse_against_exact(scene: &Scene, sparse: &Image, exact: &Image) -> (f32, f32, f32) {
        let (w, h) = (scene.settings().width, scene.settings().height);
        let (mut differ, mut worst, mut total_error, mut total) = (0, 0.0f32, 0.0f32, 0.0f32);
        for y in 0..h {
            for x in 0..w {
                let (a, b) = (sparse.pixel(x, y), exact.pixel(x, y));
                if x as usize % SPACING == 0 && y as usize % SPACING == 0 {
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
        scene.settings_mut().filter = PixelFilter::Point;
        let options = RadiosityOptions::default();
        let solution = Radiosity::compile(&scene, &options).unwrap();
        let own = *scene.camera();
        let corner = Camera::look_at(vec3(2.0, 2.0, -1.0), vec3(5.56, 2.0, 2.0), glam::Vec3::Y, 39.3);
        // Measured: 3.0% and 0.017% into the corner at 192×108 (76% and
        // 0.11% if anchors across silhouettes and creases are taken too);
        // 12.7% and 0.017% from the scene's camera at the viewer's 640×360,
        // where a pixel of the ceiling near the back wall interpolates over
        // a long stretch of a slanted surface toward the crease (37% with
        // anchors every fourth pixel, taken within the whole kernel
        // radius). That camera sees the room through its open side: the
        // background around it has no indirect light to blend.
        let views = [(corner, (192, 108), 0.05, 0.5), (own, (640, 360), 0.2, 0.15)];
        for (camera, (w, h), worst_allowed, blended) in views {
            scene.set_camera(camera);
            (scene.settings_mut().width, scene.settings_mut().height) = (w, h);
            let preview = Preview::new(&scene, Some(&solution), AnalyticOptions::default(), RaymarchOptions::default());
            let exact = render_samples(&scene, &preview, 0, 1, &RenderObserver::none());
            let mut cache = FirstSample::new(&scene);
            let sparse = cache.render(&scene, Some(&solution), &preview, Fill::Sparse);
            assert!(!cache.is_valid_for(&scene), "a sparse render fills no cache");
            let (worst, mean, differ) = sparse_against_exact(&scene, &sparse, &exact);
            assert!(differ > blended, "the pixels between anchors were blended: {differ}");
            assert!(worst < worst_allowed, "{worst}");
            assert!(mean < 5e-4, "{mean}");
            let again = cache.render(&scene, Some(&solution), &preview, Fill::Exact);
            assert_eq!(again, exact);
            assert!(cache.is_valid_for(&scene));
            let kept = cache.render(&scene, Some(&solution), &preview, Fill::Sparse);
            assert_eq!(kept, exact, "a sparse render of a cached view is the exact image");
        }
    }

    /// Traced among all the surfaces, the lights' too, the sparse render
    /// sees a light's surface where the exact one does, which tests the
    /// objects and the lights apart: from the scene's own camera, which
    /// sees the light under the ceiling, with jittered camera rays, the
    /// anchors and every pixel of the light are the exact image's bits.
    #[test]
    fn a_sparse_fill_sees_the_light_where_the_exact_one_does() {
        let mut scene = SceneFile::from_toml_str(CORNELL, None).unwrap().scene;
        (scene.settings_mut().width, scene.settings_mut().height) = (96, 96);
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
                } else if x as usize % SPACING == 0 && y as usize % SPACING == 0 {
                    assert_eq!(a, b, "anchor ({x}, {y})");
                }
            }
        }
        assert!(light > 20, "the light covers {light} pixels");
    }
}
