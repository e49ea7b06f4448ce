//! The preview's first sample, cached across frames while the camera stands
//! still: when only lights move, what each pixel's camera ray meets, and the
//! radiosity lookup's weights there, stay the same. Keeping them leaves a
//! frame one light sample with its shadow ray and a short weighted sum of
//! patch irradiances per pixel.
//!
//! Area lights are surfaces the camera can see, and they move: the cache
//! holds hits against the scene's objects only, and each frame tests the
//! camera rays against the lights' surfaces where they are now.

use super::Preview;
use crate::Camera;
use crate::Rgb;
use crate::camera::CameraRays;
use crate::film::Image;
use crate::geometry::{Geometry, GeometryBuilder, Hit, Ray, SurfaceHit};
use crate::integrator::{ShadowScratch, surface_radiance_batch, through_medium};
use crate::radiosity::Radiosity;
use crate::render::{BLOCK, BLOCK_ORDER};
use crate::sampling::Sampler;
use crate::scene::{PixelFilter, Scene};
use glam::Vec2;
use rayon::prelude::*;
use std::f32::consts::FRAC_1_PI;

/// One pixel's camera ray and what it meets among the objects.
#[derive(Clone, Copy)]
struct Texel {
    ray: Ray,
    hit: Option<SurfaceHit>,
    /// The hit's distance, or how far the preview follows a ray that hits nothing.
    t: f32,
    /// The diffuse albedo at the hit, times 1/π.
    albedo: Rgb,
    /// Lookup weights: `weights[band][start..start + len]`, times `scale`.
    start: u32,
    len: u32,
    scale: f32,
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
    /// Per band of [`BLOCK`] image rows, the lookup weights its texels
    /// index. Kept, with the texels, from frame to frame: a moving camera
    /// refills them every frame, into the memory the last frame used.
    weights: Vec<Vec<(u32, f32)>>,
}

/// A band's pixels are taken [`BLOCK`]×[`BLOCK`] at a time, in
/// [`BLOCK_ORDER`], so that camera rays and shadow rays go in packets of
/// neighbours (`Geometry::intersect_packet`, `occluded_packet`).
struct Block {
    /// Pixel (x, y) and its index in the band's texels.
    pixels: Vec<(usize, usize, usize)>,
    rays: Vec<Ray>,
    samplers: Vec<Sampler>,
    hits: Vec<Option<Hit>>,
    surfaces: Vec<Option<SurfaceHit>>,
    radiance: Vec<Rgb>,
    scratch: ShadowScratch,
}

impl Block {
    fn new() -> Block {
        let n = BLOCK_ORDER.len();
        Block {
            pixels: Vec::with_capacity(n),
            rays: Vec::with_capacity(n),
            samplers: Vec::with_capacity(n),
            hits: Vec::with_capacity(n),
            surfaces: Vec::with_capacity(n),
            radiance: Vec::with_capacity(n),
            scratch: ShadowScratch::default(),
        }
    }

    /// The pixels of the block at column `x0` of the band at row `y0` of a
    /// `w`-wide band of `rows` rows.
    fn select(&mut self, x0: usize, y0: usize, w: usize, rows: usize) {
        self.pixels.clear();
        for &(dx, dy) in &BLOCK_ORDER {
            let (x, dy) = (x0 + dx as usize, dy as usize);
            if x < w && dy < rows {
                self.pixels.push((x, y0 + dy, dy * w + x));
            }
        }
    }
}

impl FirstSample {
    /// An empty cache for `scene` (whose objects must not change after).
    pub fn new(scene: &Scene) -> Self {
        FirstSample { key: None, objects: scene.objects_geometry(), texels: Vec::new(), weights: Vec::new() }
    }

    /// Whether the next [`FirstSample::render`] reuses the cached hits.
    pub fn is_valid_for(&self, scene: &Scene) -> bool {
        self.key == Some(key(scene))
    }

    /// Sample 0 of every pixel with `preview` (which must hold `solution`
    /// and be made for the scene's current lights): the image
    /// `render_samples(scene, preview, 0, 1, ..)` gives, computed from the
    /// cache, which is refilled first when the camera, image size, seed or
    /// filter changed. A refill shades each block of pixels as it fills it
    /// (the moving camera's frame: one pass, each sampler seeded once).
    pub fn render(&mut self, scene: &Scene, solution: Option<&Radiosity>, preview: &Preview) -> Image {
        let lights = light_surfaces(scene);
        let (w, h) = (scene.settings().width, scene.settings().height);
        let mut image = Image::new(w, h);
        let (w, band) = (w.max(1) as usize, BLOCK as usize);
        let shading = Shading { scene, solution, preview, lights: &lights };
        if self.is_valid_for(scene) {
            let (texels, weights) = (&self.texels, &self.weights);
            let bands = texels.par_chunks(band * w).zip(weights.par_iter());
            bands.zip(image.pixels.par_chunks_mut(band * w)).enumerate().for_each(|(b, ((texels, weights), out))| {
                let mut block = Block::new();
                for x0 in (0..w).step_by(band) {
                    block.select(x0, b * band, w, texels.len() / w);
                    block.samplers.clear();
                    for &(x, y, _) in &block.pixels {
                        let mut sampler = first_sampler(scene, (y * w + x) as u64);
                        // The camera's draws, made by the renderer before the integrator's.
                        sampler.next2();
                        sampler.next2();
                        block.samplers.push(sampler);
                    }
                    shading.shade(&mut block, texels, weights, out);
                }
            });
            return image;
        }
        if self.texels.len() != w * h as usize {
            let ray = Ray::new(glam::Vec3::ZERO, glam::Vec3::Z);
            let empty = Texel { ray, hit: None, t: 0.0, albedo: Rgb::ZERO, start: 0, len: 0, scale: 0.0 };
            self.texels = vec![empty; w * h as usize];
        }
        self.weights.resize_with((h as usize).div_ceil(band), Vec::new);
        let objects = &self.objects;
        let camera = scene.camera().rays(w as u32, h);
        let bands = self.texels.par_chunks_mut(band * w).zip(self.weights.par_iter_mut());
        bands.zip(image.pixels.par_chunks_mut(band * w)).enumerate().for_each(|(b, ((texels, weights), out))| {
            weights.clear();
            let mut block = Block::new();
            for x0 in (0..w).step_by(band) {
                block.select(x0, b * band, w, texels.len() / w);
                block.rays.clear();
                block.samplers.clear();
                for &(x, y, _) in &block.pixels {
                    let mut sampler = first_sampler(scene, (y * w + x) as u64);
                    block.rays.push(camera_ray(scene, &camera, (x, y), &mut sampler));
                    block.samplers.push(sampler);
                }
                block.hits.clear();
                block.hits.resize(block.rays.len(), None);
                objects.intersect_packet(&block.rays, f32::INFINITY, &mut block.hits);
                for (k, &(_, _, i)) in block.pixels.iter().enumerate() {
                    texels[i] = texel(scene, objects, solution, block.rays[k], block.hits[k], weights);
                }
                shading.shade(&mut block, texels, weights, out);
            }
        });
        self.key = Some(key(scene));
        image
    }
}

/// The camera ray of pixel (x, y), drawn from `sampler` as the renderer
/// draws it.
fn camera_ray(scene: &Scene, camera: &CameraRays, (x, y): (usize, usize), sampler: &mut Sampler) -> Ray {
    let (jitter, lens) = (sampler.next2(), sampler.next2());
    let film = Vec2::new(x as f32, y as f32)
        + match scene.settings().filter {
            PixelFilter::Box => jitter,
            PixelFilter::Point => Vec2::splat(0.5),
        };
    camera.ray(film, lens)
}

/// The texel of `ray`, whose hit among `objects` is `hit`, with the lookup
/// weights there appended to its band's `weights`.
fn texel(
    scene: &Scene,
    objects: &Geometry,
    solution: Option<&Radiosity>,
    ray: Ray,
    hit: Option<Hit>,
    weights: &mut Vec<(u32, f32)>,
) -> Texel {
    let mut texel = Texel { ray, hit: None, t: f32::INFINITY, albedo: Rgb::ZERO, start: 0, len: 0, scale: 0.0 };
    if let Some(hit) = hit {
        let surface = objects.surface(&ray, hit);
        texel.hit = Some(surface);
        texel.t = hit.t;
        texel.albedo = scene.material_at(&surface).albedo(surface.p, surface.n) * FRAC_1_PI;
        if let Some(solution) = solution {
            let n = if surface.n.dot(ray.dir) <= 0.0 { surface.n } else { -surface.n };
            texel.start = weights.len() as u32;
            let lookup = solution.lookup();
            if let Some(scale) = lookup.weights(solution.patches(), surface.p, n, weights) {
                texel.len = weights.len() as u32 - texel.start;
                texel.scale = scale;
            }
        }
    }
    texel
}

/// What shades a frame: the scene with its current lights, their surfaces,
/// the solution relit for them and the preview made for them.
struct Shading<'a> {
    scene: &'a Scene,
    solution: Option<&'a Radiosity>,
    preview: &'a Preview<'a>,
    lights: &'a Geometry,
}

impl Shading<'_> {
    /// Writes into `out` what `preview.radiance` gives for the samples of
    /// `block`'s pixels, whose texels are in `texels` (with their band's
    /// lookup `weights`) and whose samplers have made the camera's draws.
    fn shade(&self, block: &mut Block, texels: &[Texel], weights: &[(u32, f32)], out: &mut [Rgb]) {
        let Shading { scene, solution, preview, lights } = *self;
        let Block { pixels, rays, samplers, surfaces, radiance, scratch, .. } = block;
        let medium = scene.medium();
        // The surface each ray's light leaves: a light's in front of the
        // objects (it reflects nothing), or the object's; and how far.
        rays.clear();
        surfaces.clear();
        let mut ends = [(0.0f32, false); BLOCK_ORDER.len()];
        for (k, &(_, _, i)) in pixels.iter().enumerate() {
            let texel = &texels[i];
            let ray = &texel.ray;
            rays.push(*ray);
            let (surface, end) = match lights.intersect(ray, texel.t) {
                Some(hit) => (Some(lights.surface(ray, hit)), (hit.t, false)),
                None if texel.hit.is_some() => (texel.hit, (texel.t, true)),
                None => (None, (scene.settings().max_distance, false)),
            };
            surfaces.push(surface);
            ends[k] = end;
        }
        radiance.clear();
        radiance.resize(pixels.len(), scene.settings().background);
        surface_radiance_batch(scene, rays, surfaces, samplers, medium, scratch, radiance);
        for (k, &(_, _, i)) in pixels.iter().enumerate() {
            let texel = &texels[i];
            let (mut l, (t_end, on_object)) = (radiance[k], ends[k]);
            // The indirect light, on an object (not on a light's surface).
            if let Some(solution) = solution
                && on_object
                && texel.len > 0
            {
                let e = solution.indirect_irradiance();
                let ws = &weights[texel.start as usize..(texel.start + texel.len) as usize];
                let e = ws.iter().fold(Rgb::ZERO, |sum, &(i, w)| sum + e[i as usize] * w) * texel.scale;
                l += texel.albedo * e;
            }
            let ray = &rays[k];
            let l = through_medium(scene, ray, l, t_end, &mut samplers[k], |medium, length, sampler| {
                preview.glow(scene, medium, ray, length, sampler)
            });
            out[i] = if l.is_finite() { l } else { Rgb::ZERO };
        }
    }
}

/// Sample 0's generator of a pixel, as the renderer makes it.
fn first_sampler(scene: &Scene, pixel: u64) -> Sampler {
    Sampler::for_pixel(scene.settings().seed, pixel, 0)
}

fn key(scene: &Scene) -> Key {
    let s = scene.settings();
    (*scene.camera(), s.width, s.height, s.seed, s.filter)
}

/// The surfaces of the scene's area lights where they are now.
fn light_surfaces(scene: &Scene) -> Geometry {
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

    fn check(text: &str) {
        check_at(&mut SceneFile::from_toml_str(text, None).unwrap().scene, 48, 27);
        // Partial blocks at the right and bottom edges.
        check_at(&mut SceneFile::from_toml_str(text, None).unwrap().scene, 45, 21);
    }

    fn check_at(scene: &mut Scene, width: u32, height: u32) {
        (scene.settings_mut().width, scene.settings_mut().height) = (width, height);
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
            let cached = cache.render(scene, Some(&solution), &preview);
            let direct = render_samples(scene, &preview, 0, 1, &RenderObserver::none());
            assert_eq!(cached, direct, "light at {at}");
            assert!(cached.mean().max_element() > 0.0);
        }
        let mut camera = *scene.camera();
        camera.position.x += 0.1;
        scene.set_camera(camera);
        assert!(!cache.is_valid_for(scene));
        let preview = preview_of(scene, Some(&solution));
        let cached = cache.render(scene, Some(&solution), &preview);
        assert_eq!(cached, render_samples(scene, &preview, 0, 1, &RenderObserver::none()));
    }

    #[test]
    fn the_cached_first_sample_is_the_preview_bit_for_bit_as_the_light_moves() {
        check(CORNELL);
    }

    #[test]
    fn in_a_medium_too() {
        let text = format!("{CORNELL}\n[medium]\nsigma_a = 0.01\nsigma_s = 0.03\n");
        check(&text);
    }
}
