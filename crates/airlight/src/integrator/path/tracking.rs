//! Free-flight sampling in media: exactly, by inverting the closed-form
//! optical depth, where the medium has one (homogeneous and height fog);
//! else against a majorant, by delta tracking (Woodcock et al. 1965) for
//! distances and ratio tracking (Novák, Selle and Jarosz 2014) for
//! transmittance. Both are written as pbrt-v4's majorant iteration, so that
//! RGB coefficients are handled by sampling one "hero" channel and
//! weighting all three by the ratios of their path pdfs (spectral MIS); an
//! exact flight is the case σ_maj = σt(p), where no collision is null.

use crate::Rgb;
use crate::geometry::Ray;
use crate::medium::{Density, DensityProfile, Medium};
use crate::sampling::Sampler;

/// Walks [0, t_max] of `ray` from collision to collision as [`track`]
/// does, drawing each flight exactly from the medium's closed-form optical
/// depth when `closed_form` is set and the medium has one, else tracking
/// against a majorant.
pub fn free_flight(
    medium: &Medium,
    ray: &Ray,
    t_max: f32,
    hero: usize,
    closed_form: bool,
    sampler: &mut Sampler,
    at: impl FnMut(Collision, &mut Sampler) -> bool,
) -> Rgb {
    match medium.profile(ray.origin, ray.dir).filter(|_| closed_form) {
        Some(profile) => exact_flights(medium, &profile, t_max, hero, sampler, at),
        None => track(medium, ray, t_max, hero, sampler, at),
    }
}

/// [`track`] with the majorant equal to σt(p) everywhere: each flight ends
/// where the hero channel's optical depth σt·X(t) reaches an exponential
/// variate E, t = X⁻¹(X(t_prev) + E/σt) (medium/profile.rs), so every
/// collision is real. The majorant transmittance since the previous
/// collision is e^{−σt ΔX} from the density integrals, not from the f32
/// distances. Where ρ overflows f32 (far below a height fog's base) the
/// reported coefficients are scaled down together: callers only take their
/// ratios.
fn exact_flights(
    medium: &Medium,
    profile: &DensityProfile,
    t_max: f32,
    hero: usize,
    sampler: &mut Sampler,
    mut at: impl FnMut(Collision, &mut Sampler) -> bool,
) -> Rgb {
    let sigma_t = medium.sigma_t();
    let x_max = profile.integral(0.0, t_max as f64);
    if sigma_t[hero] <= 0.0 {
        return medium.transmittance_of(x_max);
    }
    let cap = f32::MAX as f64 / (2.0 * sigma_t.max_element() as f64).max(1.0);
    let mut x = 0.0f64;
    loop {
        let step = -((1.0 - sampler.next()) as f64).ln() / sigma_t[hero] as f64;
        if x + step >= x_max {
            return medium.transmittance_of(x_max - x);
        }
        x += step;
        let t = (profile.distance_to(x) as f32).min(t_max);
        let density = profile.density(t as f64).min(cap) as f32;
        let collision = Collision {
            t,
            sigma_a: medium.sigma_a * density,
            sigma_s: medium.sigma_s * density,
            sigma_maj: sigma_t * density,
            t_maj: medium.transmittance_of(step),
        };
        if !at(collision, sampler) {
            return Rgb::ONE;
        }
    }
}

/// A bound σ_maj ≥ σt(p) over the segment [t0, t1] of `ray`, per channel.
/// Exact for a homogeneous medium; for the height fog, whose density is
/// monotone along any line, the larger of the densities at the two ends;
/// for a grid, its largest value; for noise, its bound over the segment.
pub fn majorant(medium: &Medium, ray: &Ray, t0: f32, t1: f32) -> Rgb {
    match &medium.density {
        Density::Homogeneous => medium.sigma_t(),
        Density::Height { .. } => {
            let rho = medium.density_at(ray.at(t0)).max(medium.density_at(ray.at(t1)));
            medium.sigma_t() * rho
        }
        Density::Grid(grid) => medium.sigma_t() * grid.max_value(),
        Density::Noise(noise) => {
            let mut most = 0.0f32;
            noise.majorant_segments(ray.origin, ray.dir, t0, t1, |_, _, bound| {
                most = most.max(bound);
                true
            });
            medium.sigma_t() * most
        }
    }
}

/// Calls `f(t0, t1, σ_maj)` for consecutive stretches of [0, t_max] of
/// `ray` with a majorant each, until `f` returns false: one stretch for
/// media that fill space; for a grid, one per majorant cell the ray
/// crosses inside its box, and none outside (vacuum); for noise, its box
/// cut into pieces (noise.rs).
fn majorant_segments(medium: &Medium, ray: &Ray, t_max: f32, mut f: impl FnMut(f32, f32, Rgb) -> bool) {
    match &medium.density {
        Density::Grid(grid) => {
            let sigma_t = medium.sigma_t();
            grid.majorant_segments(ray.origin, ray.dir, 0.0, t_max, |t0, t1, bound| f(t0, t1, sigma_t * bound));
        }
        Density::Noise(noise) => {
            let sigma_t = medium.sigma_t();
            noise.majorant_segments(ray.origin, ray.dir, 0.0, t_max, |t0, t1, bound| f(t0, t1, sigma_t * bound));
        }
        _ => {
            f(0.0, t_max, majorant(medium, ray, 0.0, t_max));
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
/// the last collision to t_max (all ones if stopped early). Across
/// stretches with different majorants (a grid's majorant cells) a flight
/// that passes a stretch's end starts afresh at the next one, which the
/// exponential's lack of memory makes exact, and the majorant
/// transmittances of the stretches passed multiply.
pub fn track(
    medium: &Medium,
    ray: &Ray,
    t_max: f32,
    hero: usize,
    sampler: &mut Sampler,
    mut at: impl FnMut(Collision, &mut Sampler) -> bool,
) -> Rgb {
    let exp = |x: Rgb| Rgb::new((-x.x).exp(), (-x.y).exp(), (-x.z).exp());
    // Majorant transmittance since the last collision.
    let mut since = Rgb::ONE;
    let mut stopped = false;
    majorant_segments(medium, ray, t_max, |t0, t1, sigma_maj| {
        if sigma_maj[hero] <= 0.0 {
            since *= exp(sigma_maj * (t1 - t0));
            return true;
        }
        let mut t = t0;
        loop {
            let step = -(1.0 - sampler.next()).ln() / sigma_maj[hero];
            if t + step >= t1 {
                since *= exp(sigma_maj * (t1 - t));
                return true;
            }
            t += step;
            let density = medium.density_at(ray.at(t));
            let collision = Collision {
                t,
                sigma_a: medium.sigma_a * density,
                sigma_s: medium.sigma_s * density,
                sigma_maj,
                t_maj: since * exp(sigma_maj * step),
            };
            since = Rgb::ONE;
            if !at(collision, sampler) {
                stopped = true;
                return false;
            }
        }
    });
    if stopped { Rgb::ONE } else { since }
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
