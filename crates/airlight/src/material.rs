//! Surface materials. All reflect on both sides (DESIGN.md: two-sided).

use crate::Rgb;
use glam::Vec3;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian: BRDF = albedo/π.
    Diffuse { albedo: Rgb },
    /// A solid checkerboard of two Lambertian albedos, squares `scale` wide.
    Checker { albedo: Rgb, albedo2: Rgb, scale: f32 },
    /// Diffuse plus a normalised Phong lobe (Lafortune and Willems 1994):
    /// f = albedo/π + specular·(n+2)/(2π)·max(0, r·wi)^n, r the mirror of wo.
    /// The (n+2)/(2π) makes the lobe's directional albedo at normal
    /// incidence equal `specular`, as in the seed's setUpPhongIllumination.
    Phong { albedo: Rgb, specular: Rgb, exponent: f32 },
}

impl Material {
    pub fn diffuse(albedo: Rgb) -> Self {
        Material::Diffuse { albedo }
    }
    pub fn checker(albedo: Rgb, albedo2: Rgb, scale: f32) -> Self {
        Material::Checker { albedo, albedo2, scale }
    }
    pub fn phong(albedo: Rgb, specular: Rgb, exponent: f32) -> Self {
        Material::Phong { albedo, specular, exponent }
    }
    /// The black surface of an area light.
    pub const BLACK: Material = Material::Diffuse { albedo: Rgb::ZERO };

    /// The diffuse albedo at point `p` with outward normal `n`.
    pub fn albedo(&self, p: Vec3, n: Vec3) -> Rgb {
        match *self {
            Material::Diffuse { albedo } | Material::Phong { albedo, .. } => albedo,
            Material::Checker { albedo, albedo2, scale } => {
                // Step half a square inward so that points on a face that lies
                // on a cell boundary (a floor at y = 0) all fall in one cell.
                let q = (p - n * (0.5 * scale)) / scale;
                let parity = q.x.floor() as i64 + q.y.floor() as i64 + q.z.floor() as i64;
                if parity.rem_euclid(2) == 0 { albedo } else { albedo2 }
            }
        }
    }

    /// The BRDF for outgoing `wo` and incident `wi` (both pointing away from
    /// the surface) at `p`, with geometric normal `n` facing either way.
    pub fn brdf(&self, p: Vec3, n: Vec3, wo: Vec3, wi: Vec3) -> Rgb {
        let diffuse = self.albedo(p, n) / PI;
        match *self {
            Material::Phong { specular, exponent, .. } => {
                // Both directions on one side of the surface, for the lobe.
                let n = if n.dot(wo) < 0.0 { -n } else { n };
                if n.dot(wi) <= 0.0 {
                    return diffuse;
                }
                let mirror = 2.0 * n.dot(wo) * n - wo;
                let cos = mirror.dot(wi).max(0.0);
                diffuse + specular * ((exponent + 2.0) / (2.0 * PI) * cos.powf(exponent))
            }
            _ => diffuse,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Sampler, to_world, uniform_sphere};

    /// Directional albedo ∫ f·cos dω by Monte Carlo over the hemisphere.
    fn directional_albedo(m: &Material, wo: Vec3, n: usize) -> Rgb {
        let mut s = Sampler::for_pixel(3, 1, 4);
        let mut sum = Rgb::ZERO;
        for _ in 0..n {
            let mut wi = uniform_sphere(s.next2());
            wi.z = wi.z.abs();
            sum += m.brdf(Vec3::ZERO, Vec3::Z, wo, wi) * wi.z * (2.0 * PI);
        }
        sum / n as f32
    }

    #[test]
    fn lambertian_reflects_its_albedo() {
        let a = directional_albedo(&Material::diffuse(Rgb::splat(0.6)), Vec3::Z, 200_000);
        assert!((a.x - 0.6).abs() < 0.005, "{a}");
    }

    #[test]
    fn phong_lobe_at_normal_incidence_reflects_its_specular_weight() {
        // With the (n+2)/2π normalisation, ∫ cos^n(α) cos θ dω = 2π/(n+2) at
        // normal incidence, where α = θ; so the lobe's albedo is `specular`.
        let m = Material::phong(Rgb::ZERO, Rgb::splat(0.5), 20.0);
        let a = directional_albedo(&m, Vec3::Z, 400_000);
        assert!((a.x - 0.5).abs() < 0.01, "{a}");
        // And it is symmetric in wo and wi (reciprocity).
        let wo = to_world(Vec3::new(0.3, 0.1, 0.9).normalize(), Vec3::Z);
        let wi = Vec3::new(-0.2, 0.25, 0.8).normalize();
        let f1 = m.brdf(Vec3::ZERO, Vec3::Z, wo, wi);
        let f2 = m.brdf(Vec3::ZERO, Vec3::Z, wi, wo);
        assert!((f1 - f2).length() < 1e-5);
    }

    #[test]
    fn checker_alternates_and_is_stable_on_cell_boundaries() {
        let m = Material::checker(Rgb::ONE, Rgb::ZERO, 1.0);
        let up = Vec3::Y;
        let a = m.albedo(Vec3::new(0.5, 0.0, 0.5), up);
        let b = m.albedo(Vec3::new(0.5, 1e-7, 0.5), up);
        let c = m.albedo(Vec3::new(0.5, -1e-7, 0.5), up);
        assert_eq!(a, b);
        assert_eq!(a, c);
        assert_ne!(a, m.albedo(Vec3::new(1.5, 0.0, 0.5), up));
        assert_eq!(a, m.albedo(Vec3::new(1.5, 0.0, 1.5), up));
    }
}
