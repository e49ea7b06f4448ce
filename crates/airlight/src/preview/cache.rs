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
use crate::film::Image;
use crate::geometry::{Geometry, GeometryBuilder, Ray, SurfaceHit};
use crate::integrator::{surface_radiance, through_medium};
use crate::radiosity::Radiosity;
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
    /// Lookup weights: `weights[row][start..start + len]`, times `scale`.
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
    /// Per image row, the lookup weights its texels index. Kept, with the
    /// texels, from frame to frame: a moving camera refills them every
    /// frame, into the memory the last frame used.
    weights: Vec<Vec<(u32, f32)>>,
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
    /// filter changed.
    pub fn render(&mut self, scene: &Scene, solution: Option<&Radiosity>, preview: &Preview) -> Image {
        if !self.is_valid_for(scene) {
            self.fill(scene, solution);
        }
        let lights = light_surfaces(scene);
        let (w, h) = (scene.settings().width, scene.settings().height);
        let mut image = Image::new(w, h);
        image.pixels.par_chunks_mut(w.max(1) as usize).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                *out = self.shade(scene, solution, preview, &lights, y, y * w as usize + x);
            }
        });
        image
    }

    fn fill(&mut self, scene: &Scene, solution: Option<&Radiosity>) {
        let s = scene.settings();
        let (w, h) = (s.width as usize, s.height as usize);
        if self.texels.len() != w * h {
            let ray = Ray::new(glam::Vec3::ZERO, glam::Vec3::Z);
            let empty = Texel { ray, hit: None, t: 0.0, albedo: Rgb::ZERO, start: 0, len: 0, scale: 0.0 };
            self.texels = vec![empty; w * h];
        }
        self.weights.resize_with(h, Vec::new);
        let objects = &self.objects;
        let camera = scene.camera().rays(s.width, s.height);
        self.texels.par_chunks_mut(w.max(1)).zip(self.weights.par_iter_mut()).enumerate().for_each(
            |(y, (texels, weights))| {
                weights.clear();
                for (x, texel) in texels.iter_mut().enumerate() {
                    let mut sampler = first_sampler(scene, (y * w + x) as u64);
                    let (jitter, lens) = (sampler.next2(), sampler.next2());
                    let film = Vec2::new(x as f32, y as f32)
                        + match s.filter {
                            PixelFilter::Box => jitter,
                            PixelFilter::Point => Vec2::splat(0.5),
                        };
                    let ray = camera.ray(film, lens);
                    let t = f32::INFINITY;
                    *texel = Texel { ray, hit: None, t, albedo: Rgb::ZERO, start: 0, len: 0, scale: 0.0 };
                    if let Some(hit) = objects.intersect(&ray, t) {
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
                }
            },
        );
        self.key = Some(key(scene));
    }

    /// What `preview.radiance` gives for pixel `index`'s sample 0.
    fn shade(
        &self,
        scene: &Scene,
        solution: Option<&Radiosity>,
        preview: &Preview,
        lights: &Geometry,
        row: usize,
        index: usize,
    ) -> Rgb {
        let texel = &self.texels[index];
        let ray = &texel.ray;
        let mut sampler = first_sampler(scene, index as u64);
        // The camera's draws, made by the renderer before the integrator's.
        sampler.next2();
        sampler.next2();
        let medium = scene.medium();
        let (surface, t_end) = match lights.intersect(ray, texel.t) {
            // A light's surface in front of the objects (it reflects nothing).
            Some(hit) => (surface_radiance(scene, ray, &lights.surface(ray, hit), &mut sampler, medium), hit.t),
            None => match &texel.hit {
                Some(s) => {
                    let mut l = surface_radiance(scene, ray, s, &mut sampler, medium);
                    if let Some(solution) = solution {
                        let e = if texel.len > 0 {
                            let e = solution.indirect_irradiance();
                            let ws = &self.weights[row][texel.start as usize..(texel.start + texel.len) as usize];
                            Some(ws.iter().fold(Rgb::ZERO, |sum, &(i, w)| sum + e[i as usize] * w) * texel.scale)
                        } else {
                            None
                        };
                        if let Some(e) = e {
                            l += texel.albedo * e;
                        }
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
        check(&mut SceneFile::from_toml_str(CORNELL, None).unwrap().scene);
    }

    #[test]
    fn in_a_medium_too() {
        let text = format!("{CORNELL}\n[medium]\nsigma_a = 0.01\nsigma_s = 0.03\n");
        check(&mut SceneFile::from_toml_str(&text, None).unwrap().scene);
    }
}
