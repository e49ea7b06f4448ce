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
//! A moving camera would refill the cache every frame: its frames take
//! [`Fill::Sparse`] instead, which interpolates the indirect light between
//! anchors and keeps no texels (`sparse.rs`).

use super::Preview;
use super::sparse::{Anchor, between_anchors};
use crate::Rgb;
use crate::film::Image;
use crate::film::PixelFilter;
use crate::geometry::{Geometry, GeometryBuilder, Hit, Ray, SurfaceHit};
use crate::integrator::{DeferredShadows, through_medium};
use crate::radiosity::Radiosity;
use crate::render::PixelSample;
use crate::sampling::Sampler;
use crate::scene::Scene;
use crate::scratch::with_scratch;
use crate::{Camera, CameraRays};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::cell::RefCell;
use std::f32::consts::FRAC_1_PI;

/// One pixel's camera ray and what it meets among the objects.
#[derive(Clone)]
pub(super) struct Texel {
    /// Sample 0's generator after the camera's draws: where the
    /// integrator's start.
    pub sampler: Sampler,
    pub ray: Ray,
    pub hit: Option<SurfaceHit>,
    /// The hit's distance, or how far the preview follows a ray that hits nothing.
    pub t: f32,
    /// The diffuse albedo at the hit, times 1/π.
    pub albedo: Rgb,
    /// Lookup weights: `weights[row][start..start + len]`, times `scale`
    /// (for [`Indirect::Own`]).
    start: u32,
    len: u32,
    scale: f32,
    pub indirect: Indirect,
}

impl Texel {
    /// A placeholder, to be overwritten.
    pub fn empty() -> Texel {
        let (sampler, ray) = (Sampler::for_pixel(0, 0, 0), Ray::new(Vec3::ZERO, Vec3::Z));
        let (start, len, scale, albedo) = (0, 0, 0.0, Rgb::ZERO);
        Texel { sampler, ray, hit: None, t: f32::INFINITY, albedo, start, len, scale, indirect: Indirect::Own }
    }

    /// Makes this the texel of a camera ray `ray` that meets no object
    /// (yet), keeping its sampler. Field by field: a whole new texel was
    /// built on the stack and copied, and the copy's loads waited on the
    /// stores just before them.
    fn set_missed(&mut self, ray: Ray) {
        (self.ray, self.hit, self.t, self.albedo) = (ray, None, f32::INFINITY, Rgb::ZERO);
        (self.start, self.len, self.scale, self.indirect) = (0, 0, 0.0, Indirect::Own);
    }
}

/// Where a texel's indirect irradiance comes from.
#[derive(Clone, Copy)]
pub(super) enum Indirect {
    /// Its own lookup's weights.
    Own,
    /// Known already: a sparse render's anchor's, looked up in the
    /// anchors' pass (`sparse.rs`); None where no patch is near.
    Given(Option<Rgb>),
    /// A sparse render's texel between anchors: the mean of its anchors'
    /// irradiance (left and right on an anchor row; above and below on an
    /// anchor column; the four diagonal ones elsewhere) when all of them
    /// lie on its surface near its hit; else a lookup of its own when it is
    /// shaded. (Decided then, in the pass that reads the texels anyway: a
    /// pass of its own over them costs as much as the lookups it spares.)
    Anchors,
}

/// How the first sample finds the radiosity lookup's weights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// Each pixel's own: the first sample exactly as the renderer makes it.
    Exact,
    /// Each pixel's own at even columns of even rows (the anchors); a
    /// pixel between takes the mean of its neighbouring anchors'
    /// irradiance where all of them hit its surface close by, and looks up
    /// its own elsewhere. The interpolated quantity varies over the kernel's
    /// radius (a patch and a half), not over a pixel; direct light, shadows
    /// and edges stay per pixel. A sparse render keeps no texels.
    Sparse,
}

/// What [`Camera`], size, seed and filter the cache was made for.
type Key = (Camera, u32, u32, u64, PixelFilter);

/// Sample 0 of every pixel of the preview, reusing camera-ray hits and
/// lookup weights while the view stays the same (see the module docs).
pub struct FirstSample {
    /// What the texels were made for (None while they hold none: a moving
    /// camera's frames keep none).
    pub(super) key: Option<Key>,
    /// The scene's objects without the lights' surfaces.
    pub(super) objects: Geometry,
    texels: Vec<Texel>,
    /// Per image row, the lookup weights its texels index. Kept, with the
    /// texels, from frame to frame.
    weights: Vec<Vec<(u32, f32)>>,
    /// A moving camera's frame's anchors (see `sparse.rs`).
    pub(super) anchors: Vec<Anchor>,
}

impl FirstSample {
    /// An empty cache for `scene` (whose objects must not change after).
    pub fn new(scene: &Scene) -> Self {
        FirstSample {
            key: None,
            objects: scene.objects_geometry(),
            texels: Vec::new(),
            weights: Vec::new(),
            anchors: Vec::new(),
        }
    }

    /// Whether the next [`FirstSample::render`] reuses cached hits, with
    /// either fill (the cache holds an exact fill's; a sparse render keeps
    /// none).
    pub fn is_valid(&self, scene: &Scene) -> bool {
        self.key == Some(key(scene))
    }

    /// Sample 0 of every pixel with `preview` (which must hold `solution`
    /// and be made for the scene's current lights). With [`Fill::Exact`]
    /// it is the image `render_samples(scene, preview, 0, 1, ..)` gives,
    /// from the cache, which is refilled first when the camera, image size,
    /// seed or filter changed. With [`Fill::Sparse`] and no cache for this
    /// view, its indirect light is interpolated between anchors, and each
    /// row's texels are made, shaded and dropped (a kept exact fill is
    /// used as it is).
    pub fn render(&mut self, scene: &Scene, solution: Option<&Radiosity>, preview: &Preview, fill: Fill) -> Image {
        if fill == Fill::Sparse && !self.is_valid(scene) {
            return self.render_sparse(scene, solution, preview);
        }
        if !self.is_valid(scene) {
            self.fill(scene, solution);
        }
        let lights = light_surfaces(scene);
        let (w, h) = (scene.settings().film.width, scene.settings().film.height);
        let mut image = Image::new(w, h);
        image.pixels.par_chunks_mut(w.max(1) as usize).enumerate().for_each(|(y, row)| {
            let texels = &self.texels[y * row.len()..(y + 1) * row.len()];
            with_scratch(&ROWS, |scratch| {
                let RowScratch { shading, light_hits, .. } = scratch;
                light_hits.find(&lights, texels);
                let rows = Rows { scene, solution, preview, lights: &lights, weights: &self.weights[y], anchors: &[] };
                rows.shade(Span::whole(y), texels, &light_hits.hits, row, shading)
            });
        });
        image
    }

    /// Refills the cache for the scene's view: every pixel's texel with
    /// its own lookup weights.
    fn fill(&mut self, scene: &Scene, solution: Option<&Radiosity>) {
        self.key = None;
        let s = scene.settings();
        let (w, h) = (s.film.width as usize, s.film.height as usize);
        self.texels.resize(w * h, Texel::empty());
        self.weights.resize_with(h, Vec::new);
        let objects = &self.objects;
        let camera = scene.camera().rays(s.film.width, s.film.height);
        self.texels.par_chunks_mut(w.max(1)).zip(self.weights.par_iter_mut()).enumerate().for_each(
            |(y, (texels, weights))| {
                with_scratch(&ROWS, |scratch| {
                    trace_texels(scene, objects, &camera, Span::whole(y), &mut scratch.tracing, texels);
                });
                weights.clear();
                if let Some(solution) = solution {
                    for texel in texels.iter_mut() {
                        if let Some(surface) = &texel.hit {
                            let n = surface.facing(texel.ray.dir);
                            (texel.start, texel.len, texel.scale) = own_weights(solution, surface.p, n, weights);
                        }
                    }
                }
            },
        );
        self.key = Some(key(scene));
    }
}

/// Which pixels of an image row a row of texels is: texel i is pixel
/// (`first` + i·`step`, `y`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Span {
    pub y: usize,
    pub first: usize,
    pub step: usize,
}

impl Span {
    /// Every pixel of row `y`.
    pub fn whole(y: usize) -> Span {
        Span { y, first: 0, step: 1 }
    }

    /// The span's columns in an image `w` pixels wide.
    pub fn columns(self, w: usize) -> std::iter::StepBy<std::ops::Range<usize>> {
        (self.first.min(w)..w).step_by(self.step)
    }
}

/// The texels of `span` (into `out`, one per column): camera rays made
/// together and traced as a packet, with their hits' surfaces and albedos
/// (lookup weights and indirect sources are the caller's to set).
pub(super) fn trace_texels(
    scene: &Scene,
    objects: &Geometry,
    camera: &CameraRays,
    span: Span,
    scratch: &mut Tracing,
    out: &mut [Texel],
) {
    let s = scene.settings();
    let (w, y) = (s.film.width as usize, span.y);
    let Tracing { films, lenses, rays, hits } = scratch;
    // The preview's camera numbers are not stratified: two independent
    // pairs, drawn from the generator the integrator then goes on with.
    films.clear();
    lenses.clear();
    for (texel, x) in out.iter_mut().zip(span.columns(w)) {
        let sample = PixelSample::new(s, s.seed, false, x as u32, y as u32, 0);
        texel.sampler = sample.sampler;
        films.push(sample.film);
        lenses.push(sample.lens);
    }
    rays.clear();
    camera.rays_into(films, lenses, rays);
    hits.clear();
    hits.resize(rays.len(), None);
    objects.intersect_packet(rays, f32::INFINITY, hits);
    for ((texel, &ray), &hit) in out.iter_mut().zip(rays.iter()).zip(hits.iter()) {
        texel.set_missed(ray);
        if let Some(hit) = hit {
            let surface = objects.surface(&ray, hit);
            texel.hit = Some(surface);
            texel.t = hit.t;
            texel.albedo = scene.material_at(&surface).albedo(surface.p, surface.n) * FRAC_1_PI;
        }
    }
}

/// What [`trace_texels`] works in.
#[derive(Default)]
pub(super) struct Tracing {
    films: Vec<Vec2>,
    lenses: Vec<Vec2>,
    rays: Vec<Ray>,
    hits: Vec<Option<Hit>>,
}

/// A rendering thread's buffers, kept from row to row.
#[derive(Default)]
pub(super) struct RowScratch {
    pub tracing: Tracing,
    pub light_hits: LightHits,
    pub shading: Shading,
    /// A sparse render's row of texels.
    pub texels: Vec<Texel>,
}

thread_local! {
    pub(super) static ROWS: RefCell<RowScratch> = RefCell::new(RowScratch::default());
}

/// What shading a row reads: the scene, its radiosity solution, the
/// preview, the lights' surfaces where they are now, an exact fill's
/// lookup weights for the row (which its texels index) and a sparse
/// frame's anchors (none for an exact fill).
pub(super) struct Rows<'a> {
    pub scene: &'a Scene,
    pub solution: Option<&'a Radiosity>,
    pub preview: &'a Preview<'a>,
    pub lights: &'a Geometry,
    pub weights: &'a [(u32, f32)],
    pub anchors: &'a [Anchor],
}

impl Rows<'_> {
    /// What `preview.radiance` gives for the sample 0 of `span`'s pixels,
    /// into their places in the image's `row`, from their `texels` and
    /// where their camera rays meet the lights' surfaces before the
    /// objects (`light_hits`, [`LightHits`]): each pixel's light terms
    /// gathered and their shadow rays traced together, then each pixel
    /// finished (indirect light, medium) with its own sampler, which draws
    /// what the integrator's would.
    pub fn shade(
        &self,
        span: Span,
        texels: &[Texel],
        light_hits: &[Option<Hit>],
        row: &mut [Rgb],
        scratch: &mut Shading,
    ) {
        let Rows { scene, solution, preview, lights, weights, anchors } = *self;
        let (w, h, y) = (row.len(), scene.settings().film.height as usize, span.y);
        let Shading { samplers, shadows, radiance } = scratch;
        samplers.clear();
        shadows.clear();
        radiance.clear();
        // (Copied all at once: one at a time, each went through the stack.)
        samplers.extend(texels.iter().map(|texel| texel.sampler.clone()));
        for ((texel, light_hit), sampler) in texels.iter().zip(light_hits).zip(samplers.iter_mut()) {
            let (ray, k) = (&texel.ray, radiance.len());
            radiance.push(match (light_hit, &texel.hit) {
                // A light's surface in front of the objects (black, or a glowing
                // surface's material).
                (Some(hit), _) => shadows.surface(scene, ray, &lights.surface(ray, *hit), sampler, k),
                (None, Some(s)) => shadows.surface(scene, ray, s, sampler, k),
                (None, None) => scene.escaped_radiance(ray.dir),
            });
        }
        shadows.resolve(scene, scene.medium(), radiance);
        for (k, (x, (texel, light_hit))) in span.columns(w).zip(texels.iter().zip(light_hits)).enumerate() {
            let ray = &texel.ray;
            // A local copy: added to in memory, its parts were stored one
            // by one and read back together, which waits on the stores.
            let mut out = radiance[k];
            let t_end = match (light_hit, &texel.hit) {
                (Some(hit), _) => hit.t,
                (None, Some(s)) => {
                    if let Some(solution) = solution {
                        let e = match texel.indirect {
                            Indirect::Own => own_irradiance(texel, weights, solution.indirect_irradiance()),
                            Indirect::Given(e) => e,
                            Indirect::Anchors => between_anchors(anchors, solution, s, ray, (x, y), (w, h)),
                        };
                        if let Some(e) = e {
                            out += texel.albedo * e;
                        }
                    }
                    texel.t
                }
                (None, None) => scene.settings().max_distance,
            };
            let l = through_medium(scene, ray, out, t_end, &mut samplers[k], |medium, length, sampler| {
                preview.glow(scene, medium, ray, length, sampler)
            });
            row[x] = if l.is_finite() { l } else { Rgb::ZERO };
        }
    }
}

/// What [`Rows::shade`] works in.
#[derive(Default)]
pub(super) struct Shading {
    /// Each pixel's generator, between its light terms and its medium.
    samplers: Vec<Sampler>,
    shadows: DeferredShadows,
    /// Each texel's radiance so far.
    radiance: Vec<Rgb>,
}

/// Where a row's camera rays meet the lights' surfaces before their
/// objects, traced together.
#[derive(Default)]
pub(super) struct LightHits {
    rays: Vec<Ray>,
    tmax: Vec<f32>,
    /// Per texel, its camera ray's hit on a light's surface in front of
    /// its object.
    pub hits: Vec<Option<Hit>>,
}

impl LightHits {
    /// Finds the hits of `texels`' camera rays.
    pub fn find(&mut self, lights: &Geometry, texels: &[Texel]) {
        let LightHits { rays, tmax, hits } = self;
        rays.clear();
        tmax.clear();
        for texel in texels {
            rays.push(texel.ray);
            tmax.push(texel.t);
        }
        hits.clear();
        hits.resize(rays.len(), None);
        lights.intersect_each(rays, tmax, hits);
    }
}

/// A texel's irradiance from its own lookup weights (in its row's `list`),
/// None where no patch is near.
#[inline]
fn own_irradiance(texel: &Texel, list: &[(u32, f32)], e: &[Rgb]) -> Option<Rgb> {
    (texel.len > 0).then(|| {
        let ws = &list[texel.start as usize..(texel.start + texel.len) as usize];
        ws.iter().fold(Rgb::ZERO, |sum, &(i, w)| sum + e[i as usize] * w) * texel.scale
    })
}

/// Appends the lookup's terms at `p` to `list`: (start, length, scale),
/// length 0 where no patch is near.
fn own_weights(solution: &Radiosity, p: Vec3, n: Vec3, list: &mut Vec<(u32, f32)>) -> (u32, u32, f32) {
    let start = list.len() as u32;
    match solution.lookup().weights(solution.patches(), p, n, list) {
        Some(scale) => (start, list.len() as u32 - start, scale),
        None => (start, 0, 0.0),
    }
}

fn key(scene: &Scene) -> Key {
    let s = scene.settings();
    (*scene.camera(), s.film.width, s.film.height, s.seed, s.film.filter)
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
        (scene.settings_mut().film.width, scene.settings_mut().film.height) = (48, 27);
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
            assert_eq!(cache.is_valid(scene), k > 0, "the camera stood still");
            let cached = cache.render(scene, Some(&solution), &preview, Fill::Exact);
            let direct = render_samples(scene, &preview, 0, 1, &RenderObserver::none());
            assert_eq!(cached, direct, "light at {at}");
            assert!(cached.mean().max_element() > 0.0);
        }
        let mut camera = *scene.camera();
        camera.position.x += 0.1;
        scene.set_camera(camera);
        assert!(!cache.is_valid(scene));
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
