//! Ray marching of a participating medium, after the seed
//! (raymarching-participating-media.txt): trace to the nearest surface, then
//! sample the medium between eye and surface, a shadow ray from each sample.

use super::{Integrator, surface_radiance};
use crate::Rgb;
use crate::geometry::Ray;
use crate::medium::Medium;
use crate::sampling::{Sampler, keyed2};
use crate::scene::Scene;
use glam::DVec3;

/// The ray-marching integrator.
///
/// The ray's span [0, t_end] (t_end: the hit distance, or max_distance when
/// nothing is hit or the hit lies beyond it) is cut into `steps` segments of length Δ. Segment i, from
/// a = iΔ, contributes
///
///   T(0, a) · σs(t_i) · S(t_i) · Δ (1 − e^{−τ_i}) / τ_i,
///
/// where τ_i is the segment's optical depth, S(t_i) = Σ_lights phase · L_i ·
/// T(light → t_i) · V is the in-scattered light at the sample t_i = a + ξΔ,
/// and Δ(1 − e^{−τ})/τ = ∫ over the segment of e^{−σ̄t s} ds is the segment's
/// exact weight for constant S: thick media stay right, and as τ → 0 it
/// tends to Δ. ξ = 1/2 (midpoint) without jitter, uniform per pixel sample
/// with jitter. With midpoints the error is O(Δ²): the sample sits at the
/// middle of each segment, so the linear term of S's variation cancels and
/// what remains per segment is O(Δ³), over N = T/Δ segments.
pub struct Raymarch {
    pub steps: u32,
    pub jitter: bool,
}

impl Integrator for Raymarch {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        // A medium that neither absorbs nor scatters is vacuum.
        let medium = scene.medium.as_ref().filter(|m| !m.is_vacuum());
        let hit = scene.geometry.intersect(ray, f32::INFINITY);
        // The surface first, so that with a vacuum the samples drawn, and so
        // the image, are exactly those of `direct`.
        let (surface, t_end) = match hit {
            Some(hit) => {
                let s = scene.geometry.surface(ray, hit);
                (surface_radiance(scene, ray, &s, sampler, medium), hit.t)
            }
            None => (scene.settings.background, scene.settings.max_distance),
        };
        let Some(medium) = medium else {
            return surface;
        };
        let offset = if self.jitter { sampler.next() } else { 0.5 };
        let through = medium.transmittance(ray.origin, ray.dir, 0.0, t_end);
        // Marching stops at max_distance even when a surface lies beyond it
        // (a floor seen near the horizon), so steps stay short.
        let march_end = t_end.min(scene.settings.max_distance);
        surface * through + in_scattered(scene, medium, ray, march_end, self.steps, offset, sampler)
    }
}

/// Single-scattered radiance along `ray` over [0, t_end], marched with
/// `steps` samples at fraction `offset` of each step (see [`Raymarch`]).
pub fn in_scattered(
    scene: &Scene,
    medium: &Medium,
    ray: &Ray,
    t_end: f32,
    steps: u32,
    offset: f32,
    sampler: &mut Sampler,
) -> Rgb {
    if medium.sigma_s == Rgb::ZERO || t_end <= 0.0 {
        return Rgb::ZERO;
    }
    let dt = t_end / steps as f32;
    let wo = -ray.dir;
    // Sums in f64: over thousands of steps f32 rounding would otherwise set
    // an error floor near 1e-5 that hides the method's own convergence.
    let mut to_eye = DVec3::ONE;
    let mut total = DVec3::ZERO;
    for i in 0..steps {
        let a = i as f32 * dt;
        let t = a + offset * dt;
        let p = ray.at(t);
        let tau = medium.optical_depth(ray.origin, ray.dir, a, a + dt);
        let weight = segment_weight(tau, dt);
        let mut light_in = Rgb::ZERO;
        let key = sampler.next_key();
        scene.for_each_light_at(p, |index, light| {
            let Some(sample) = light.sample(p, keyed2(key, index as u64)) else { return };
            let distance = scene.light_distance(sample.distance);
            if !scene.light_visible(p, p, sample.wi, sample.distance) {
                return;
            }
            let phase = medium.phase(wo, sample.wi);
            light_in += sample.weight * phase * medium.transmittance(p, sample.wi, 0.0, distance);
        });
        total += to_eye * (medium.sigma_s * medium.density_at(p) * weight * light_in).as_dvec3();
        to_eye *= DVec3::new((-tau.x as f64).exp(), (-tau.y as f64).exp(), (-tau.z as f64).exp());
    }
    total.as_vec3()
}

/// ∫0^Δ e^{−τ s/Δ} ds = Δ(1 − e^{−τ})/τ per channel, → Δ as τ → 0.
#[inline]
pub fn segment_weight(tau: Rgb, dt: f32) -> Rgb {
    let w = |x: f32| {
        if x < 1e-5 { dt * (1.0 - 0.5 * x) } else { dt * -(-x).exp_m1() / x }
    };
    Rgb::new(w(tau.x), w(tau.y), w(tau.z))
}
