//! Participating media: homogeneous fog and exponential height fog, with
//! transmittance in closed form for both, and a density grid (from a
//! `.vol` file) and fractal noise fog, whose transmittance is integrated
//! along the ray and whose free flights are tracked against a majorant.

mod grid;
pub mod noise;
mod phase;
mod profile;

pub use grid::{DensityGrid, MAJORANT_RESOLUTION};
pub use noise::NoiseFog;
pub use phase::{henyey_greenstein, isotropic, sample_henyey_greenstein_cos};
pub use profile::DensityProfile;

use crate::Rgb;
use glam::Vec3;
use std::sync::Arc;

/// A medium filling all of space (docs/scene-format.md: `[medium]`). Coefficients are per
/// unit length, per RGB channel, where the density is 1. Cheap to clone:
/// a grid's voxels are shared.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
    /// Henyey–Greenstein asymmetry, pbrt's sign: g > 0 scatters forward.
    pub g: f32,
    pub density: Density,
}

/// How the coefficients vary in space.
#[derive(Clone, Debug, PartialEq)]
pub enum Density {
    /// Constant: the coefficients as given.
    Homogeneous,
    /// Exponential height fog: the coefficients times exp(−falloff·(y − base)).
    Height { base: f32, falloff: f32 },
    /// The coefficients times a grid's trilinear density; vacuum outside
    /// its box (grid.rs).
    Grid(Arc<DensityGrid>),
    /// The coefficients times fractal noise (noise.rs).
    Noise(Arc<NoiseFog>),
}

impl Medium {
    pub fn homogeneous(sigma_a: Rgb, sigma_s: Rgb, g: f32) -> Self {
        Medium { sigma_a, sigma_s, g, density: Density::Homogeneous }
    }

    pub fn height(sigma_a: Rgb, sigma_s: Rgb, g: f32, base: f32, falloff: f32) -> Self {
        Medium { sigma_a, sigma_s, g, density: Density::Height { base, falloff } }
    }

    pub fn grid(sigma_a: Rgb, sigma_s: Rgb, g: f32, grid: DensityGrid) -> Self {
        Medium { sigma_a, sigma_s, g, density: Density::Grid(Arc::new(grid)) }
    }

    pub fn noise(sigma_a: Rgb, sigma_s: Rgb, g: f32, noise: NoiseFog) -> Self {
        Medium { sigma_a, sigma_s, g, density: Density::Noise(Arc::new(noise)) }
    }

    /// Extinction coefficient σt = σa + σs where the density is 1.
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }

    /// Whether light passes untouched (σt = 0 in every channel).
    /// The largest density of a medium that tracking crosses with null
    /// collisions (a grid, noise without a height falloff); None for the
    /// media whose flights are drawn exactly (homogeneous and height fog),
    /// where no density makes the work per path grow.
    pub fn tracked_peak_density(&self) -> Option<f32> {
        match &self.density {
            Density::Grid(grid) => Some(grid.max_value()),
            Density::Noise(noise) if noise.height.is_none() => Some(noise.noise_bound()),
            _ => None,
        }
    }

    pub fn is_vacuum(&self) -> bool {
        self.sigma_t() == Rgb::ZERO
    }

    /// The density multiplier at `p`.
    #[inline]
    pub fn density_at(&self, p: Vec3) -> f32 {
        match &self.density {
            Density::Homogeneous => 1.0,
            Density::Height { base, falloff } => (-falloff * (p.y - base)).exp(),
            Density::Grid(grid) => grid.density(p),
            Density::Noise(noise) => noise.density(p),
        }
    }

    /// The density along the line o + t·d (d unit) as ρ(t) = e^{ln ρ0 − a t}
    /// (profile.rs), for media where it has that closed form (homogeneous
    /// and height fog). A grid has none (None): it is sampled by tracking
    /// against a majorant.
    pub fn profile(&self, o: Vec3, d: Vec3) -> Option<DensityProfile> {
        match self.density {
            Density::Homogeneous => Some(DensityProfile { ln_rho0: 0.0, a: 0.0 }),
            Density::Height { base, falloff } => {
                let k = falloff as f64;
                Some(DensityProfile { ln_rho0: -k * (o.y as f64 - base as f64), a: k * d.y as f64 })
            }
            Density::Grid(_) | Density::Noise(_) => None,
        }
    }

    /// The part of [t0, t1] of the line o + t·d where the density may be
    /// non-zero: a grid's box; all of it for media that fill space.
    pub fn extent(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Option<(f32, f32)> {
        match &self.density {
            Density::Grid(grid) => grid.clip(o, d, t0, t1),
            Density::Noise(noise) => noise.clip(o, d, t0, t1),
            _ => (t1 > t0).then_some((t0, t1)),
        }
    }

    /// Whether the density along every line has the closed form of
    /// [`Medium::profile`], so that free flights can be drawn and
    /// transmittance taken exactly.
    pub fn has_closed_form(&self) -> bool {
        self.profile(Vec3::ZERO, Vec3::Y).is_some()
    }

    /// ∫ density over the segment o + t·d, t in [t0, t1], d unit; t1 may be
    /// infinite. In closed form for the height fog: with y(t) = o.y + t·d.y
    /// and a = falloff·d.y,
    /// ∫ e^{−falloff (y(t) − base)} dt = ρ(t0)·(1 − e^{−a (t1 − t0)})/a,
    /// evaluated in f64 from the segment's denser end ([`DensityProfile::integral`]).
    /// For a grid, exact for its trilinear density ([`DensityGrid::integral`]);
    /// for noise, a quadrature ([`NoiseFog::integral`]).
    pub fn density_integral(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> f64 {
        match &self.density {
            Density::Grid(grid) => grid.integral(o, d, t0, t1),
            Density::Noise(noise) => noise.integral(o, d, t0, t1),
            _ => self.profile(o, d).map_or(0.0, |profile| profile.integral(t0 as f64, t1 as f64)),
        }
    }

    /// Optical depth σt·∫density over the segment, per channel.
    pub fn optical_depth(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Rgb {
        if self.is_vacuum() {
            return Rgb::ZERO;
        }
        self.optical_depth_of(self.density_integral(o, d, t0, t1))
    }

    /// σt·X per channel for a density integral X; σt = 0 channels stay 0
    /// even for an infinite X.
    pub fn optical_depth_of(&self, integral: f64) -> Rgb {
        let sigma_t = self.sigma_t();
        Rgb::new(scaled(sigma_t.x, integral), scaled(sigma_t.y, integral), scaled(sigma_t.z, integral))
    }

    /// Transmittance exp(−optical depth) over the segment, per channel.
    pub fn transmittance(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Rgb {
        let tau = self.optical_depth(o, d, t0, t1);
        Rgb::new((-tau.x).exp(), (-tau.y).exp(), (-tau.z).exp())
    }

    /// exp(−σt·X) per channel for a density integral X (1 where σt = 0).
    pub fn transmittance_of(&self, integral: f64) -> Rgb {
        let tau = self.optical_depth_of(integral);
        Rgb::new((-tau.x).exp(), (-tau.y).exp(), (-tau.z).exp())
    }

    /// σs(t)·T(0, t) per channel along o + t·d: the density in t of a
    /// free flight from o that scatters first at t (σt·ρ(t)·T(0, t) is the
    /// density of the first collision, σs/σt of which scatter). In f64 as
    /// σs·e^{ln ρ(t) − σt X(t)}, so that where ρ overflows and T underflows
    /// the product stays finite (capped at f32::MAX deep below a height fog's
    /// base, where ρ alone overflows f32). Zero where the medium has no closed form.
    pub fn free_flight_scattering(&self, o: Vec3, d: Vec3, t: f32) -> Rgb {
        if let Density::Homogeneous = self.density {
            // ρ = 1: nothing to overflow, so f32 suffices.
            let sigma_t = self.sigma_t();
            let channel = |sigma_s: f32, sigma_t: f32| sigma_s * (-sigma_t * t).exp();
            return Rgb::new(
                channel(self.sigma_s.x, sigma_t.x),
                channel(self.sigma_s.y, sigma_t.y),
                channel(self.sigma_s.z, sigma_t.z),
            );
        }
        let Some(profile) = self.profile(o, d) else { return Rgb::ZERO };
        let ln_rho = profile.ln_rho0 - profile.a * t as f64;
        let x = profile.integral(0.0, t as f64);
        let channel = |sigma_s: f32, sigma_t: f32| {
            // Capped at f32::MAX: callers divide it by sums that hold it.
            if sigma_s == 0.0 {
                0.0
            } else {
                (sigma_s as f64 * (ln_rho - sigma_t as f64 * x).exp()).min(f32::MAX as f64) as f32
            }
        };
        let sigma_t = self.sigma_t();
        Rgb::new(
            channel(self.sigma_s.x, sigma_t.x),
            channel(self.sigma_s.y, sigma_t.y),
            channel(self.sigma_s.z, sigma_t.z),
        )
    }

    /// The phase function for directions `wo`, `wi` pointing away from the
    /// scattering point.
    #[inline]
    pub fn phase(&self, wo: Vec3, wi: Vec3) -> f32 {
        henyey_greenstein(wo.dot(wi), self.g)
    }
}

fn scaled(sigma: f32, integral: f64) -> f32 {
    if sigma == 0.0 { 0.0 } else { (sigma as f64 * integral) as f32 }
}

#[cfg(test)]
mod tests;
