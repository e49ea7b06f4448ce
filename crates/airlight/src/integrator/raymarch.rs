//! Ray marching of a participating medium, as in Wyman and Ramsey,
//! "Interactive Volumetric Shadows in Participating Media with
//! Single-Scattering" (2008): trace to the nearest surface, then
//! sample the medium between eye and surface, a shadow ray from each sample.

use super::{Integrator, RadianceParts, RaymarchOptions, no_extra, single_scattering_parts};
use crate::Rgb;
use crate::geometry::Ray;
use crate::medium::Medium;
use crate::sampling::{Sampler, keyed2};
use crate::scene::Scene;
use glam::DVec3;

/// The ray-marching integrator.
///
/// The ray's span [0, t_end] (t_end: the hit distance, or max_distance when
/// nothing is hit or the hit lies beyond it), or the part of it where the
/// medium can have density (a grid's box), is cut into `steps` segments of
/// length Δ. Segment i, from a = iΔ past that part's start, contributes
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
    pub options: RaymarchOptions,
}

impl Raymarch {
    pub fn new(options: RaymarchOptions) -> Self {
        Raymarch { options }
    }
}

impl Integrator for Raymarch {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        self.parts(scene, ray, sampler).total()
    }

    fn radiance_parts(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Option<RadianceParts> {
        Some(self.parts(scene, ray, sampler))
    }
}

impl Raymarch {
    fn parts(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> RadianceParts {
        single_scattering_parts(scene, ray, sampler, no_extra, |medium, length, sampler| {
            march(scene, medium, ray, length, self.options, sampler)
        })
    }
}

/// [`in_scattered`] with the march's own offset: a random fraction of a
/// step per pixel sample with jitter, the middle of each step without.
pub fn march(
    scene: &Scene,
    medium: &Medium,
    ray: &Ray,
    length: f32,
    options: RaymarchOptions,
    sampler: &mut Sampler,
) -> Rgb {
    let offset = if options.jitter { sampler.next() } else { 0.5 };
    in_scattered(scene, medium, ray, length, options.steps, offset, sampler)
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
    // The steps go where the medium may have density (a grid's box); before
    // it the medium is vacuum.
    let Some((start, end)) = medium.extent(ray.origin, ray.dir, 0.0, t_end) else { return Rgb::ZERO };
    let dt = (end - start) / steps as f32;
    let wo = -ray.dir;
    // Sums in f64: over thousands of steps f32 rounding would otherwise set
    // an error floor near 1e-5 that hides the method's own convergence.
    let mut to_eye = DVec3::ONE;
    if start > 0.0 {
        to_eye = medium.transmittance(ray.origin, ray.dir, 0.0, start).as_dvec3();
    }
    let mut total = DVec3::ZERO;
    // A step's optical depth is often the last one's, to the bit (in a
    // homogeneous medium it differs only by the rounding of the step's
    // ends): its exponentials are then the last ones'.
    let (mut last_tau, mut decay, mut weight) = (Rgb::NAN, DVec3::ONE, Rgb::ZERO);
    for i in 0..steps {
        let a = start + i as f32 * dt;
        let t = a + offset * dt;
        let p = ray.at(t);
        let tau = medium.optical_depth(ray.origin, ray.dir, a, a + dt);
        if tau != last_tau {
            decay = DVec3::new((-tau.x as f64).exp(), (-tau.y as f64).exp(), (-tau.z as f64).exp());
            weight = segment_weight(tau, decay, dt);
            last_tau = tau;
        }
        let mut light_in = Rgb::ZERO;
        let key = sampler.next_key();
        scene.for_each_emitter_at(p, |index, _| {
            let u = keyed2(key, index as u64);
            let Some(sample) = scene.sample_emitter(index, p, u) else { return };
            if !scene.unoccluded(p, None, &sample) {
                return;
            }
            let phase = medium.phase(wo, sample.wi);
            let distance = scene.light_distance(sample.distance);
            light_in += sample.weight * phase * medium.transmittance(p, sample.wi, 0.0, distance);
        });
        total += to_eye * (medium.sigma_s * medium.density_at(p) * weight * light_in).as_dvec3();
        to_eye *= decay;
    }
    total.as_vec3()
}

/// ∫0^Δ e^{−τ s/Δ} ds = Δ(1 − e^{−τ})/τ per channel, → Δ as τ → 0, from
/// `decay` = e^{−τ} in f64, which the march needs anyway for the
/// transmittance to the eye. In f64 the difference 1 − e^{−τ} loses
/// log10(1/τ) of its 16 digits, at most 5 for τ ≥ 10⁻⁵, and keeps far more
/// than f32's 7; below 10⁻⁵ the series' first two terms are exact to f32.
/// (libm's `expm1f`, three calls a step, was a quarter of the demo scene's
/// time.)
#[inline]
pub fn segment_weight(tau: Rgb, decay: DVec3, dt: f32) -> Rgb {
    let w = |x: f32, e: f64| {
        if x < 1e-5 { dt * (1.0 - 0.5 * x) } else { (dt as f64 * (1.0 - e) / x as f64) as f32 }
    };
    Rgb::new(w(tau.x, decay.x), w(tau.y, decay.y), w(tau.z, decay.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against Δ(1 − e^{−τ})/τ in f64 through `expm1` (exact to f64 for
    /// every τ): within an f32 rounding, on both sides of the series'
    /// threshold and from optically thin to thick.
    #[test]
    fn segment_weight_is_the_integral_of_the_step_transmittance() {
        let dt = 0.37f32;
        for x in [0.0f32, 1e-9, 3e-7, 9.99e-6, 1e-5, 1.01e-5, 1e-4, 3e-3, 0.1, 0.7, 1.0, 4.0, 30.0, 200.0] {
            let tau = Rgb::new(x, 2.0 * x, 0.5 * x);
            let decay = DVec3::new((-tau.x as f64).exp(), (-tau.y as f64).exp(), (-tau.z as f64).exp());
            let got = segment_weight(tau, decay, dt);
            for c in 0..3 {
                let t = tau[c] as f64;
                let exact = if t == 0.0 { dt as f64 } else { dt as f64 * -(-t).exp_m1() / t };
                let error = (got[c] as f64 - exact).abs() / exact;
                assert!(error < 1.2e-7, "τ = {t:e}: {} against {exact}, relative error {error:e}", got[c]);
            }
        }
    }
}
