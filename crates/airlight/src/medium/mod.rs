//! Participating media: homogeneous fog and exponential height fog, with
//! transmittance in closed form for both.

mod phase;

pub use phase::{henyey_greenstein, isotropic, sample_henyey_greenstein_cos};

use crate::Rgb;
use glam::Vec3;

/// A medium filling all of space (docs/scene-format.md: `[medium]`). Coefficients are per
/// unit length, per RGB channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
    /// Henyey–Greenstein asymmetry, pbrt's sign: g > 0 scatters forward.
    pub g: f32,
    pub density: Density,
}

/// How the coefficients vary in space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Density {
    /// Constant: the coefficients as given.
    Homogeneous,
    /// Exponential height fog: the coefficients times exp(−falloff·(y − base)).
    Height { base: f32, falloff: f32 },
}

impl Medium {
    pub fn homogeneous(sigma_a: Rgb, sigma_s: Rgb, g: f32) -> Self {
        Medium { sigma_a, sigma_s, g, density: Density::Homogeneous }
    }

    pub fn height(sigma_a: Rgb, sigma_s: Rgb, g: f32, base: f32, falloff: f32) -> Self {
        Medium { sigma_a, sigma_s, g, density: Density::Height { base, falloff } }
    }

    /// Extinction coefficient σt = σa + σs where the density is 1.
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }

    /// Whether light passes untouched (σt = 0 in every channel).
    pub fn is_vacuum(&self) -> bool {
        self.sigma_t() == Rgb::ZERO
    }

    /// The density multiplier at `p`.
    #[inline]
    pub fn density_at(&self, p: Vec3) -> f32 {
        match self.density {
            Density::Homogeneous => 1.0,
            Density::Height { base, falloff } => (-falloff * (p.y - base)).exp(),
        }
    }

    /// ∫ density over the segment o + t·d, t in [t0, t1], d unit; t1 may be
    /// infinite. In closed form for the height fog: with y(t) = o.y + t·d.y
    /// and a = falloff·d.y,
    /// ∫ e^{−falloff (y(t) − base)} dt = ρ(t0)·(1 − e^{−a (t1 − t0)})/a,
    /// evaluated with expm1 (and its limit t1 − t0 as a → 0) in f64.
    pub fn density_integral(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> f64 {
        let length = t1 as f64 - t0 as f64;
        if length.is_nan() || length <= 0.0 {
            return 0.0;
        }
        match self.density {
            Density::Homogeneous => length,
            Density::Height { base, falloff } => {
                let k = falloff as f64;
                let rho0 = (-k * (o.y as f64 + t0 as f64 * d.y as f64 - base as f64)).exp();
                let a = k * d.y as f64;
                if length.is_infinite() {
                    return if a > 0.0 {
                        rho0 / a
                    } else if rho0 == 0.0 {
                        0.0
                    } else {
                        f64::INFINITY
                    };
                }
                let x = a * length;
                if x.abs() < 1e-8 { rho0 * length * (1.0 - 0.5 * x) } else { rho0 * -(-x).exp_m1() / a }
            }
        }
    }

    /// Optical depth σt·∫density over the segment, per channel.
    pub fn optical_depth(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Rgb {
        let sigma_t = self.sigma_t();
        if sigma_t == Rgb::ZERO {
            return Rgb::ZERO;
        }
        let integral = self.density_integral(o, d, t0, t1);
        // σt = 0 channels stay 0 even over infinite lengths.
        Rgb::new(scaled(sigma_t.x, integral), scaled(sigma_t.y, integral), scaled(sigma_t.z, integral))
    }

    /// Transmittance exp(−optical depth) over the segment, per channel.
    pub fn transmittance(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Rgb {
        let tau = self.optical_depth(o, d, t0, t1);
        Rgb::new((-tau.x).exp(), (-tau.y).exp(), (-tau.z).exp())
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
