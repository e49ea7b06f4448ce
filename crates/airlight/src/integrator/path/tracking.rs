//! Free-flight sampling in media against a majorant: delta tracking (Woodcock
//! et al. 1965) for distances and ratio tracking (Novák, Selle and Jarosz
//! 2014) for transmittance, written as in pbrt-v4's majorant iteration so
//! that RGB coefficients are handled by sampling one "hero" channel and
//! weighting all three by the ratios of their path pdfs (spectral MIS).

use crate::Rgb;
use crate::geometry::Ray;
use crate::medium::{Density, Medium};
use crate::sampling::Sampler;

/// A bound σ_maj ≥ σt(p) over the segment [t0, t1] of `ray`, per channel.
/// Exact for a homogeneous medium; for the height fog, whose density is
/// monotone along any line, the larger of the densities at the two ends.
pub fn majorant(medium: &Medium, ray: &Ray, t0: f32, t1: f32) -> Rgb {
    match medium.density {
        Density::Homogeneous => medium.sigma_t(),
        Density::Height { .. } => {
            let rho = medium.density_at(ray.at(t0)).max(medium.density_at(ray.at(t1)));
            medium.sigma_t() * rho
        }
    }
}

/// What happens at a tentative collision: the caller decides and says
/// whether tracking goes on.
pub struct Collision {
    pub t: f32,
    /// σa and σs at the collision (density included).
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
    pub sigma_maj: Rgb,
    /// Majorant transmittance since the previous collision (or the start).
    pub t_maj: Rgb,
}

/// Walks [0, t_max] of `ray` from collision to collision with the majorant,
/// drawing free flights in channel `hero`, and calls `at` at each; stops
/// early when `at` returns false. Returns the majorant transmittance from
/// the last collision to t_max (all ones if stopped early).
pub fn track(
    medium: &Medium,
    ray: &Ray,
    t_max: f32,
    hero: usize,
    sampler: &mut Sampler,
    mut at: impl FnMut(Collision, &mut Sampler) -> bool,
) -> Rgb {
    let sigma_maj = majorant(medium, ray, 0.0, t_max);
    let exp = |x: Rgb| Rgb::new((-x.x).exp(), (-x.y).exp(), (-x.z).exp());
    if sigma_maj[hero] <= 0.0 {
        return exp(sigma_maj * t_max);
    }
    let mut t = 0.0f32;
    loop {
        let step = -(1.0 - sampler.next()).ln() / sigma_maj[hero];
        if t + step >= t_max {
            return exp(sigma_maj * (t_max - t));
        }
        t += step;
        let density = medium.density_at(ray.at(t));
        let collision = Collision {
            t,
            sigma_a: medium.sigma_a * density,
            sigma_s: medium.sigma_s * density,
            sigma_maj,
            t_maj: exp(sigma_maj * step),
        };
        if !at(collision, sampler) {
            return Rgb::ONE;
        }
    }
}

/// Whether a particle passes [0, t_max] without a real collision, by delta
/// tracking in one channel: its probability is that channel's transmittance.
pub fn delta_tracking_passes(medium: &Medium, ray: &Ray, t_max: f32, channel: usize, sampler: &mut Sampler) -> bool {
    let mut passed = true;
    track(medium, ray, t_max, channel, sampler, |c, s| {
        let real = (c.sigma_a[channel] + c.sigma_s[channel]) / c.sigma_maj[channel];
        if s.next() < real {
            passed = false;
            return false;
        }
        true
    });
    passed
}

/// Ratio-tracking estimate of the transmittance of [0, t_max], one channel:
/// the product of σn/σ_maj over the tentative collisions.
pub fn ratio_tracking(medium: &Medium, ray: &Ray, t_max: f32, channel: usize, sampler: &mut Sampler) -> f32 {
    let mut estimate = 1.0f32;
    track(medium, ray, t_max, channel, sampler, |c, _| {
        let null = (c.sigma_maj[channel] - c.sigma_a[channel] - c.sigma_s[channel]).max(0.0);
        estimate *= null / c.sigma_maj[channel];
        estimate > 0.0
    });
    estimate
}
