//! The preview's first sample, cached across frames while the camera stands
//! still: when only lights move, what each pixel's camera ray meets, and the
//! radiosity lookup's weights there, stay the same. Keeping them leaves a
//! frame one light sample with its shadow ray and a short weighted sum of
//! patch irradiances per pixel.
//!
//! Area lights are surfaces the camera can see, and they move: the cache
//! holds hits against the scene's objects only, and each frame tests the
//! camera rays against the lights' surfaces where they are now.
//!
//! A moving camera would refill the cache every frame, and there the
//! lookup's weights are the largest part of the work. [`Fill::Sparse`]
//! keeps no cache (see [`sparse`](super::sparse)): it looks the weights up
//! only at every other pixel in each direction, and traces and shades the
//! pixels between in one pass. The viewer uses it while the camera moves
//! and goes back to [`Fill::Exact`] when it stops.

use super::Preview;
use crate::Camera;
use crate::Rgb;
use crate::camera::CameraRays;
use crate::film::Image;
use crate::geometry::{Geometry, GeometryBuilder, Ray, SurfaceHit};
use crate::integrator::{surface_radiance, through_medium};
use crate::radiosity::Radiosity;
use crate::sampling::Sampler;
use crate::scene::{PixelFilter, Scene};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::FRAC_1_PI;

/// One pixel's camera ray and what it meets: among the objects in the
/// cache, among all the surfaces in a sparse render (see [`Traced`]).
#[derive(Clone, Copy)]
pub(super) struct Texel {
    pub ray: Ray,
    pub hit: Option<SurfaceHit>,
    /// The hit's distance, or how far the preview follows a ray that hits nothing.
    pub t: f32,
    /// The diffuse albedo at the hit, times 1/π.
    pub albedo: Rgb,
}

impl Texel {
    pub const EMPTY: Texel =
        Texel { ray: Ray { origin: Vec3::ZERO, dir: Vec3::Z }, hit: None, t: 0.0, albedo: Rgb::ZERO };
}

/// A cached texel's lookup weights: `weights[row][start..start + len]`,
/// times `scale`; `len` 0 where no patch is near.
#[derive(Clone, Copy, Default)]
struct Terms {
    start: u32,
    len: u32,
    scale: f32,
}

/// How the first sample finds the radiosity lookup's weights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// Each pixel's own: the first sample exactly as the renderer makes it,
    /// from the cache (refilled when the view changed).
    Exact,
    /// Each pixel's own at every other column of every other row (the
    /// anchors); a pixel between interpolates its neighbouring anchors'
    /// irradiance where all of them hit its surface close by, and looks up
    /// its own elsewhere (see [`sparse`](super::sparse)). It uses the
    /// cache if that holds the view, exactly, and fills none.
    Sparse,
}

/// What [`Camera`], size, seed and filter the cache was made for.
type Key = (Camera, u32, u32, u64, PixelFilter);

/// Sample 0 of every pixel of the preview, reusing camera-ray hits and
/// lookup weights while the view stays the same (see the module docs).
pub struct FirstSample {
    key: Option<Key>,
    /// The scene's objects without the lights' surfaces.
    objects: Geometry,
    texels: Vec<Texel>,
    terms: Vec<Terms>,
    /// Per image row, the lookup weights its texels index. Kept, with the
    /// texels, from frame to frame.
    weights: Vec<Vec<(u32, f32)>>,
    /// A sparse render's anchors, kept so that the next one reuses their
    /// memory.
    pub(super) anchors: Vec<super::sparse::Anchor>,
}

impl FirstSample {
    /// An empty cache for `scene` (whose objects must not change after).
    pub fn new(scene: &Scene) -> Self {
        FirstSample {
            key: None,
            objects: scene.objects_geometry(),
            texels: Vec::new(),
            terms: Vec::new(),
            weights: Vec::new(),
            anchors: Vec::new(),
        }
    }

    /// Whether the cache holds the hits of the scene's current view, so
    /// that the next [`FirstSample::render`] reuses them.
    pub fn is_valid_for(&self, scene: &Scene) -> bool {
        self.key == Some(key(scene))
    }

    /// Sample 0 of every pixel with `preview` (which must hold `solution`
    /// and be made for the scene's current lights). With [`Fill::Exact`]
    /// it is the image `render_samples(scene, preview, 0, 1, ..)` gives,
    /// computed from the cache, which is refilled first when the camera,
    /// image size, seed or filter changed. With [`Fill::Sparse`] its
    /// indirect light is interpolated between anchors, unless the cache
    /// holds this view: then it is exact too.
    pub fn render(&mut self, scene: &Scene, solution: Option<&Radiosity>, preview: &Preview, fill: Fill) -> Image {
        if !self.is_valid_for(scene) {
            if fill == Fill::Sparse {
                return self.render_sparse(scene, solution, preview);
            }
            self.fill(scene, solution);
        }
        let lights = light_surfaces(scene);
        let (w, h) = (scene.settings().width, scene.settings().height);
        let mut image = Image::new(w, h);
        let e = solution.map(Radiosity::indirect_irradiance);
        image.pixels.par_chunks_mut(w.max(1) as usize).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let index = y * w as usize + x;
                let terms = &self.terms[index];
                let indirect = |_: &SurfaceHit| e.and_then(|e| own_irradiance(terms, &self.weights[y], e));
                let traced = Traced::Objects { lights: &lights };
                *out = shade(scene, preview, traced, &self.texels[index], camera_drawn(scene, index), indirect);
            }
        });
        image
    }

    fn fill(&mut self, scene: &Scene, solution: Option<&Radiosity>) {
        let s = scene.settings();
        let (w, h) = (s.width as usize, s.height as usize);
        self.texels.resize(w * h, Texel::EMPTY);
        self.terms.resize(w * h, Terms::default());
        self.weights.resize_with(h, Vec::new);
        let objects = &self.objects;
        let camera = scene.camera().rays(s.width, s.height);
        let rows = self.texels.par_chunks_mut(w.max(1)).zip(self.terms.par_chunks_mut(w.max(1)));
        rows.zip(self.weights.par_iter_mut()).enumerate().for_each(|(y, ((texels, terms), weights))| {
            weights.clear();
            for (x, (texel, terms)) in texels.iter_mut().zip(terms).enumerate() {
                (*texel, _) = trace(scene, objects, &camera, x, y);
                *terms = match (&texel.hit, solution) {
                    (Some(surface), Some(solution)) => {
                        own_weights(solution, surface.p, surface.facing(texel.ray.dir), weights)
                    }
                    _ => Terms::default(),
                };
            }
        });
        self.key = Some(key(scene));
    }
}

/// Pixel (x, y)'s sample-0 camera ray and what it meets among `objects`,
/// and the pixel's generator after the camera's draws.
#[inline]
pub(super) fn trace(scene: &Scene, objects: &Geometry, camera: &CameraRays, x: usize, y: usize) -> (Texel, Sampler) {
    let s = scene.settings();
    let mut sampler = first_sampler(scene, (y * s.width as usize + x) as u64);
    let (jitter, lens) = (sampler.next2(), sampler.next2());
    let film = Vec2::new(x as f32, y as f32)
        + match s.filter {
            PixelFilter::Box => jitter,
            PixelFilter::Point => Vec2::splat(0.5),
        };
    let ray = camera.ray(film, lens);
    let mut texel = Texel { ray, hit: None, t: f32::INFINITY, albedo: Rgb::ZERO };
    if let Some(hit) = objects.intersect(&ray, f32::INFINITY) {
        let surface = objects.surface(&ray, hit);
        texel.hit = Some(surface);
        texel.t = hit.t;
        texel.albedo = scene.material_at(&surface).albedo(surface.p, surface.n) * FRAC_1_PI;
    }
    (texel, sampler)
}

/// Where a texel's camera ray was traced.
#[derive(Clone, Copy)]
pub(super) enum Traced<'a> {
    /// Among the objects only: the lights' surfaces where they are now
    /// (this geometry) are tested when the texel is shaded.
    Objects { lights: &'a Geometry },
    /// Among all the scene's surfaces ([`Scene::geometry`]), the lights'
    /// too: one query finds the same nearest hit (an object, of lower
    /// index, wins a tie, as when a light's surface must be strictly
    /// nearer).
    Everything,
}

/// What `preview.radiance` gives for a pixel's sample 0 whose camera ray
/// met `texel` where `traced` says: `sampler` is the pixel's generator
/// after the camera's draws, `indirect` the indirect irradiance at the hit
/// (asked only when no light's surface stands in front of it).
#[inline]
pub(super) fn shade(
    scene: &Scene,
    preview: &Preview,
    traced: Traced,
    texel: &Texel,
    mut sampler: Sampler,
    indirect: impl FnOnce(&SurfaceHit) -> Option<Rgb>,
) -> Rgb {
    let ray = &texel.ray;
    let medium = scene.medium();
    let light = match traced {
        Traced::Objects { lights } => lights.intersect(ray, texel.t).map(|hit| (lights.surface(ray, hit), hit.t)),
        Traced::Everything => texel.hit.filter(|s| s.emitter.is_some()).map(|s| (s, texel.t)),
    };
    let (surface, t_end) = match light {
        // A light's surface in front of the objects (it reflects nothing).
        Some((s, t)) => (surface_radiance(scene, ray, &s, &mut sampler, medium), t),
        None => match &texel.hit {
            Some(s) => {
                let mut l = surface_radiance(scene, ray, s, &mut sampler, medium);
                if let Some(e) = indirect(s) {
                    l += texel.albedo * e;
                }
                (l, texel.t)
            }
            None => (scene.settings().background, scene.settings().max_distance),
        },
    };
    let l = through_medium(scene, ray, surface, t_end, &mut sampler, |medium, length, sampler| {
        preview.glow(scene, medium, ray, length, sampler)
    });
    if l.is_finite() { l } else { Rgb::ZERO }
}

/// A texel's irradiance from its own lookup weights (in its row's `list`),
/// None where no patch is near.
#[inline]
fn own_irradiance(terms: &Terms, list: &[(u32, f32)], e: &[Rgb]) -> Option<Rgb> {
    (terms.len > 0).then(|| {
        let ws = &list[terms.start as usize..(terms.start + terms.len) as usize];
        ws.iter().fold(Rgb::ZERO, |sum, &(i, w)| sum + e[i as usize] * w) * terms.scale
    })
}

/// Appends the lookup's terms at `p` to `list`.
fn own_weights(solution: &Radiosity, p: Vec3, n: Vec3, list: &mut Vec<(u32, f32)>) -> Terms {
    let start = list.len() as u32;
    match solution.lookup().weights(solution.patches(), p, n, list) {
        Some(scale) => Terms { start, len: list.len() as u32 - start, scale },
        None => Terms { start, len: 0, scale: 0.0 },
    }
}

/// Sample 0's generator of a pixel, as the renderer makes it.
fn first_sampler(scene: &Scene, pixel: u64) -> Sampler {
    Sampler::for_pixel(scene.settings().seed, pixel, 0)
}

/// Sample 0's generator of a pixel after the camera's draws (film and
/// lens), where the renderer hands it to the integrator.
pub(super) fn camera_drawn(scene: &Scene, pixel: usize) -> Sampler {
    let mut sampler = first_sampler(scene, pixel as u64);
    sampler.next2();
    sampler.next2();
    sampler
}

fn key(scene: &Scene) -> Key {
    let s = scene.settings();
    (*scene.camera(), s.width, s.height, s.seed, s.filter)
}

/// The surfaces of the scene's area lights where they are now.
pub(super) fn light_surfaces(scene: &Scene) -> Geometry {
    let mut g = GeometryBuilder::default();
    for s in scene.surfaces().filter(|s| s.emitter.is_some()) {
        g.add(&s.shape, s.material, s.emitter);
    }
    g.build()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SceneFile;
    use crate::integrator::{AnalyticOptions, RadiosityOptions, RaymarchOptions};
    use crate::render::{RenderObserver, render_samples};
    use glam::vec3;

    const CORNELL: &str = include_str!("../../../../scenes/cornell_box.toml");

    fn check(scene: &mut Scene) {
        (scene.settings_mut().width, scene.settings_mut().height) = (48, 27);
        let options = RadiosityOptions::default();
        let mut solution = Radiosity::compile(scene, &options).unwrap();
        let mut cache = FirstSample::new(scene);
        let start = scene.lights().to_vec();
        fn preview_of<'a>(scene: &Scene, solution: Option<&'a Radiosity>) -> Preview<'a> {
            Preview::new(scene, solution, AnalyticOptions::default(), RaymarchOptions::default())
        }
        for (k, at) in [vec3(2.78, 5.487, 2.795), vec3(1.2, 5.0, 1.5), vec3(4.2, 5.3, 4.0)].into_iter().enumerate() {
            let moved: Vec<_> = start.iter().map(|l| l.moved_to(at)).collect();
            scene.set_lights(&moved);
            solution.update(scene, options.bounces);
            let preview = preview_of(scene, Some(&solution));
            assert_eq!(cache.is_valid_for(scene), k > 0, "the camera stood still");
            let cached = cache.render(scene, Some(&solution), &preview, Fill::Exact);
            let direct = render_samples(scene, &preview, 0, 1, &RenderObserver::none());
            assert_eq!(cached, direct, "light at {at}");
            assert!(cached.mean().max_element() > 0.0);
        }
        let mut camera = *scene.camera();
        camera.position.x += 0.1;
        scene.set_camera(camera);
        assert!(!cache.is_valid_for(scene));
        let preview = preview_of(scene, Some(&solution));
        let cached = cache.render(scene, Some(&solution), &preview, Fill::Exact);
        assert_eq!(cached, render_samples(scene, &preview, 0, 1, &RenderObserver::none()));
    }

    #[test]
    fn the_cached_first_sample_is_the_preview_bit_for_bit_as_the_light_moves() {
        check(&mut SceneFile::from_toml_str(CORNELL, None).unwrap().scene);
    }

    #[test]
    fn in_a_medium_too() {
        let text = format!("{CORNELL}\n[medium]\nsigma_a = 0.01\nsigma_s = 0.03\n");
        check(&mut SceneFile::from_toml_str(&text, None).unwrap().scene);
    }
}
