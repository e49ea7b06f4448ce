//! What reaches a point from the scene's lights: samples of each light
//! (or of each emitter, an emitting mesh's triangles as one), their
//! densities, and whether anything blocks them. Every light-sampling loop
//! of the integrators goes through here.

use super::Scene;
use crate::Rgb;
use crate::geometry::{Segment, offset_origin};
use crate::light::{Light, LightSample};
use glam::{Vec2, Vec3};

impl Scene {
    /// The distance a shadow ray toward a light sample should span: the
    /// sample's distance, or for a sun, across the scene's bounding sphere.
    pub fn light_distance(&self, distance: f32) -> f32 {
        if distance.is_finite() { distance } else { 2.0 * self.bounds_radius }
    }

    /// Light from light `index` arriving at `p`, drawn with the uniform
    /// numbers `u` (see [`Light::sample`]: a volume light makes a third
    /// from these two); None when the light sends none there. Blockers are
    /// not tested: see [`Scene::unoccluded`]. Every light-sampling loop
    /// goes through here, [`Scene::sample_light3`] or
    /// [`Scene::sample_emitter`].
    #[inline]
    pub fn sample_light(&self, index: usize, p: Vec3, u: Vec2) -> Option<LightSample> {
        if let Some(sample) = self.mapped_sky_sample(index, u) {
            return sample;
        }
        let sample = self.lights[index].sample(p, u)?;
        Some(self.textured_sample(index, p, sample)).filter(|s| s.weight != Rgb::ZERO)
    }

    /// A sample of the sky light `index` drawn by its environment map's
    /// power: Some(the sample, or None) when `index` is that light.
    #[inline]
    fn mapped_sky_sample(&self, index: usize, u: Vec2) -> Option<Option<LightSample>> {
        let (sky, map) = self.sky_map.as_ref().filter(|(i, _)| *i as usize == index)?;
        let Light::Sky { radiance: scale } = self.lights[*sky as usize] else { return Some(None) };
        Some(map.sample(u).map(|(wi, l, pdf)| LightSample {
            wi,
            distance: f32::INFINITY,
            weight: scale * l / pdf,
            pdf,
        }))
    }

    /// The radiance sky light `index` sends from the direction `dir`
    /// (pointing toward the sky): its radiance, times its environment
    /// map's there if it has one.
    #[inline]
    pub fn sky_radiance(&self, index: usize, dir: Vec3) -> Rgb {
        let scale = self.lights[index].emitted(Vec3::ZERO, Vec3::ZERO);
        match &self.sky_map {
            Some((sky, map)) if *sky as usize == index => scale * map.radiance(dir.normalize()),
            _ => scale,
        }
    }

    /// The solid-angle density with which sampling sky light `index`
    /// draws `dir`.
    #[inline]
    pub fn sky_pdf(&self, index: usize, dir: Vec3) -> f32 {
        match &self.sky_map {
            Some((sky, map)) if *sky as usize == index => map.pdf(dir.normalize()),
            _ => self.lights[index].pdf(Vec3::ZERO, dir, f32::INFINITY),
        }
    }

    /// A sample of light `index` from `p` with its weight taken from the
    /// light's emission at the sampled point, where that varies over the
    /// light ([`crate::scene::TexturedEmission`]).
    #[inline]
    fn textured_sample(&self, index: usize, p: Vec3, sample: LightSample) -> LightSample {
        match &self.light_emission[index] {
            Some(e) if sample.pdf > 0.0 => {
                let radiance = e.radiance_at(&self.lights[index], p + sample.wi * sample.distance);
                LightSample { weight: radiance / sample.pdf, ..sample }
            }
            _ => sample,
        }
    }

    /// The radiance leaving light `index`'s surface at `p` (outward normal
    /// `n`) toward −`dir`: [`Light::emitted`], or its emission at `p` where
    /// that varies over the light.
    #[inline]
    pub fn emitted(&self, index: usize, p: Vec3, n: Vec3, dir: Vec3) -> Rgb {
        let light = &self.lights[index];
        let le = light.emitted(n, dir);
        match &self.light_emission[index] {
            Some(e) if le != Rgb::ZERO => e.radiance_at(light, p),
            _ => le,
        }
    }

    /// [`Scene::sample_light`] with three uniform numbers, all of which a
    /// volume light uses (others the first two).
    #[inline]
    pub fn sample_light3(&self, index: usize, p: Vec3, u: Vec3) -> Option<LightSample> {
        let sample = self.lights[index].sample3(p, u)?;
        Some(self.textured_sample(index, p, sample)).filter(|s| s.weight != Rgb::ZERO)
    }

    /// Whether nothing blocks `sample` (a light sample seen from `p`). On a
    /// surface, give its normal: the shadow ray starts lifted off it.
    #[inline]
    pub fn unoccluded(&self, p: Vec3, normal: Option<Vec3>, sample: &LightSample) -> bool {
        let origin = match normal {
            Some(n) => offset_origin(p, n, sample.wi),
            None => p,
        };
        self.light_visible(p, origin, sample.wi, sample.distance)
    }

    /// Whether the light sample at `p + wi·distance` (a sun's when distance
    /// is infinite) is visible from `origin`, which is `p` or `p` lifted off
    /// its surface. The shadow ray aims from `origin` at the sample point
    /// itself and stops just short of it. Keeping the direction wi from the
    /// lifted origin would not do: that ray runs beside the sample point, and
    /// where it meets the light's own surface at a slant (a floor point
    /// seeing a ceiling light at 50° or more from the vertical) it meets it
    /// before any span measured along wi ends, and calls the light a blocker
    /// of itself (the Cornell box's one-bounce walls read 5.5% dark so).
    #[inline]
    pub fn light_visible(&self, p: Vec3, origin: Vec3, wi: Vec3, distance: f32) -> bool {
        self.light_segment(p, origin, wi, distance).is_some_and(|s| !self.geometry.occluded(s.origin, s.dir, s.tmax))
    }

    /// The shadow ray that [`Scene::light_visible`] traces, or None where
    /// it traces none and answers "not visible" (the sample point is the
    /// origin itself): for callers that trace many at once
    /// ([`Geometry::occluded_packet`](crate::geometry::Geometry::occluded_packet)).
    #[inline]
    pub fn light_segment(&self, p: Vec3, origin: Vec3, wi: Vec3, distance: f32) -> Option<Segment> {
        if !distance.is_finite() {
            return Some(Segment { origin, dir: wi, tmax: 2.0 * self.bounds_radius * SHADOW_SHORT });
        }
        let (dir, tmax) = toward_sample(p, origin, wi, distance);
        (tmax > 0.0).then_some(Segment { origin, dir, tmax })
    }

    /// Calls `f(index, light)` for every emitter that may reach `p`, in
    /// index order: each light, but a run of triangle lights of the same
    /// radiance (an emitting mesh) as one emitter, visited once at its
    /// first light, of which [`Scene::sample_emitter`] then draws one
    /// triangle; a shading point so traces one shadow ray per mesh rather
    /// than one per triangle. With culling, lights whose range ends before
    /// `p` are skipped without being looked at.
    pub fn for_each_emitter_at(&self, p: Vec3, mut f: impl FnMut(usize, &Light)) {
        if !self.culls_lights() {
            for &i in self.emitters.firsts() {
                f(i as usize, &self.lights[i as usize]);
            }
            return;
        }
        thread_local! {
            static FOUND: std::cell::RefCell<Vec<u32>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        // The culling holds the emitters' first lights only.
        let visit = |found: &mut Vec<u32>| {
            self.light_culling.lights_at(p, found);
            for &i in found.iter() {
                f(i as usize, &self.lights[i as usize]);
            }
        };
        // A reused buffer, or a fresh one if a caller nests these loops.
        crate::scratch::with_scratch(&FOUND, visit);
    }

    /// Whether [`Scene::for_each_emitter_at`] skips lights out of range;
    /// without, it visits [`Scene::emitter_firsts`] at every point.
    pub fn culls_lights(&self) -> bool {
        self.settings.cull_lights && self.light_culling.has_ranges()
    }

    /// Whether the emitter that starts at light `first` is that light
    /// alone (not an emitting mesh's triangles).
    pub fn emitter_is_alone(&self, first: usize) -> bool {
        self.emitters.is_alone(first)
    }

    /// The emitters' first lights, in index order: each light, but of a
    /// run of triangle lights of the same radiance (an emitting mesh) only
    /// the first ([`Scene::for_each_emitter_at`] without culling).
    pub fn emitter_firsts(&self) -> &[u32] {
        self.emitters.firsts()
    }

    /// Draws a light of the emitter that starts at light `first` with
    /// `u.x`: for an emitting mesh a triangle, with a chance in proportion
    /// to its area; else the light itself, with chance 1. Returns the
    /// light's index, the chance, and `u` with `u.x` stretched back over
    /// [0, 1) within the light's share, to sample the light with.
    pub fn draw_emitter(&self, first: usize, u: Vec2) -> (usize, f32, Vec2) {
        self.emitters.draw(first, u)
    }

    /// Light from the emitter that starts at light `first` (see
    /// [`Scene::for_each_emitter_at`]) arriving at `p`: for an emitting
    /// mesh, a triangle drawn in proportion to its area and a point of it,
    /// so a point uniform by area over the mesh, with the density of both
    /// choices; for any other light, [`Scene::sample_light`].
    #[inline]
    pub fn sample_emitter(&self, first: usize, p: Vec3, u: Vec2) -> Option<LightSample> {
        if let Some(sample) = self.mapped_sky_sample(first, u) {
            return sample;
        }
        let (index, sample) = self.emitters.sample(&self.lights, first, p, u)?;
        Some(self.textured_sample(index, p, sample)).filter(|s| s.weight != Rgb::ZERO)
    }

    /// The chance with which [`Scene::sample_emitter`] draws light `index`
    /// within its emitter (1 for a light alone): the solid-angle density of
    /// its samples is [`Light::pdf`] times this.
    #[inline]
    pub fn emitter_chance(&self, index: usize) -> f32 {
        self.emitters.chance(index)
    }
}

/// How much of the way to a light sample a shadow ray spans.
const SHADOW_SHORT: f32 = 1.0 - 1e-4;

/// The direction and span of the shadow ray from `origin` to the light
/// sample at `p + wi·distance` (finite), stopping just short of it; a
/// span of 0 (or NaN) where there is no way to go. Without branches, for
/// callers that find many at once in lanes (`integrator/light_lanes.rs`).
#[inline(always)]
pub(crate) fn toward_sample(p: Vec3, origin: Vec3, wi: Vec3, distance: f32) -> (Vec3, f32) {
    let to = p + wi * distance - origin;
    let length = to.length();
    (to / length, length * SHADOW_SHORT)
}
