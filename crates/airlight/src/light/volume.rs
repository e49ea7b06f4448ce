//! Volume lights: a region of air that glows, as the seed's light cube.
//!
//! Units: a volume light of `intensity` I (W/sr) emits like a point light of
//! intensity I spread uniformly over its volume V: every volume element dV
//! emits isotropically with intensity (I/V)·dV, so the emission coefficient is
//! ε = I/V (W·sr⁻¹·m⁻³, radiance gained per unit length through it). Far away
//! it is a point light of intensity I; the irradiance it gives at x is
//! E(x) = ∫_V (I/V)·cos θ·V(x, y)/|x − y|² dy.
//!
//! It is a region, not a surface: it casts no shadow, reflects nothing, and
//! the camera sees it only by the light its surroundings scatter.

use glam::{Vec2, Vec3};

/// The region a volume light fills.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightVolume {
    /// An axis-aligned box.
    Box { min: Vec3, max: Vec3 },
    /// A ball.
    Sphere { center: Vec3, radius: f32 },
}

impl LightVolume {
    /// The volume V.
    pub fn volume(&self) -> f32 {
        match *self {
            LightVolume::Box { min, max } => (max - min).element_product(),
            LightVolume::Sphere { radius, .. } => 4.0 / 3.0 * std::f32::consts::PI * radius.powi(3),
        }
    }

    /// A point uniformly distributed in the region (pdf 1/V) from `u`
    /// uniform in [0, 1)³. A ball's radius is R·∛u₀ (the volume within r
    /// grows as r³) and its direction uniform on the sphere.
    pub fn sample_point(&self, u: Vec3) -> Vec3 {
        match *self {
            LightVolume::Box { min, max } => min + (max - min) * u,
            LightVolume::Sphere { center, radius } => {
                center + crate::sampling::uniform_sphere(Vec2::new(u.y, u.z)) * (radius * u.x.cbrt())
            }
        }
    }

    /// The region's bounding box.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match *self {
            LightVolume::Box { min, max } => (min, max),
            LightVolume::Sphere { center, radius } => (center - radius, center + radius),
        }
    }

    /// The region's centre.
    pub fn center(&self) -> Vec3 {
        let (lo, hi) = self.bounds();
        0.5 * (lo + hi)
    }
}

/// A third uniform number made from two, for the callers of
/// [`Light::sample`](super::Light::sample) that draw two: a hash (SplitMix64's
/// finaliser) of both bit patterns. When u is uniformly random, so is the
/// result, and it is as good as independent of u for Monte Carlo purposes.
pub fn third_dimension(u: Vec2) -> f32 {
    let mut z = ((u.x.to_bits() as u64) << 32 | u.y.to_bits() as u64) ^ 0x2545_f491_4f6c_dd1d;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 40) as f32 * (1.0 / (1u32 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::super::Light;
    use super::*;
    use crate::Rgb;
    use glam::DVec3;
    use std::f64::consts::PI;

    /// ∫ over the light of (weight · max(0, n·wi)) by `sample3` on a k³ grid
    /// of midpoints (pass n = 0 for the scalar fluence ∫ weight).
    fn integrate(light: &Light, p: Vec3, n: Vec3, k: usize) -> f64 {
        let mut sum = 0.0;
        for i in 0..k {
            for j in 0..k {
                for l in 0..k {
                    let u = (Vec3::new(i as f32, j as f32, l as f32) + 0.5) / k as f32;
                    if let Some(s) = light.sample3(p, u) {
                        let cos = if n == Vec3::ZERO { 1.0 } else { s.wi.dot(n).max(0.0) };
                        sum += (s.weight.x * cos) as f64;
                    }
                }
            }
        }
        sum / (k * k * k) as f64
    }

    #[test]
    fn ball_irradiance_is_that_of_a_point_at_its_centre() {
        // Gauss: outside a uniform ball, the inverse-square field (and so the
        // irradiance on a surface facing the centre) is that of its whole
        // intensity at the centre, I/D², whatever the radius.
        for (radius, dist) in [(0.5f32, 2.0f32), (1.0, 1.3), (0.2, 5.0)] {
            let light = Light::volume_sphere(Vec3::new(0.0, dist, 0.0), radius, Rgb::splat(3.0));
            let est = integrate(&light, Vec3::ZERO, Vec3::Y, 48);
            let exact = 3.0 / (dist as f64 * dist as f64);
            assert!((est / exact - 1.0).abs() < 0.003, "r {radius} D {dist}: {est} vs {exact}");
        }
    }

    #[test]
    fn ball_fluence_matches_the_shell_integral() {
        // ∫_ball ε/|x − y|² dy with ε = I/V: over the shell of radius s about
        // the centre at distance D, ∫ dA/|x − y|² = (2π s/D) ln((D + s)/(D − s)),
        // integrated over s in [0, R] by Simpson's rule.
        let (radius, dist, intensity) = (0.8f64, 1.5f64, 2.0f64);
        let light = Light::volume_sphere(Vec3::new(dist as f32, 0.0, 0.0), radius as f32, Rgb::splat(2.0));
        let shell = |s: f64| 2.0 * PI * s / dist * ((dist + s) / (dist - s)).ln();
        let m = 2000;
        let h = radius / m as f64;
        let simpson: f64 = (0..=m)
            .map(|k| {
                (if k == 0 || k == m {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                }) * shell(k as f64 * h)
            })
            .sum::<f64>()
            * h
            / 3.0;
        let exact = intensity / (4.0 / 3.0 * PI * radius.powi(3)) * simpson;
        let est = integrate(&light, Vec3::ZERO, Vec3::ZERO, 64);
        assert!((est / exact - 1.0).abs() < 0.003, "{est} vs {exact}");
    }

    #[test]
    fn power_through_a_surrounding_sphere_is_four_pi_intensity() {
        // Gauss again, for a box: the irradiance over any closed surface
        // around the light integrates to its power, 4π·I. The surface: a
        // sphere of radius 3 about a point off the box's centre, on a
        // 48 × 96 grid in (cos θ, φ).
        let light = Light::volume_box(Vec3::new(-0.5, 0.2, -0.3), Vec3::new(0.7, 0.6, 0.9), Rgb::splat(5.0));
        let c = DVec3::new(0.3, -0.2, 0.1);
        let (nt, np) = (48, 96);
        let mut flux = 0.0;
        for i in 0..nt {
            for j in 0..np {
                let z = -1.0 + 2.0 * (i as f64 + 0.5) / nt as f64;
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                let r = (1.0 - z * z).sqrt();
                let n = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                let e = integrate(&light, (c + n * 3.0).as_vec3(), -n.as_vec3(), 12);
                // dA = R² dz dφ; light arrives inward, against n.
                flux += e * 9.0 * (2.0 / nt as f64) * (2.0 * PI / np as f64);
            }
        }
        let exact = 4.0 * PI * 5.0;
        assert!((flux / exact - 1.0).abs() < 0.005, "{flux} vs {exact}");
    }

    #[test]
    fn two_number_sampling_is_uniform_over_the_volume() {
        // `sample` with two numbers hashes a third: the points it picks must
        // fill the box uniformly (each octant an eighth, mean at the centre).
        let light = Light::volume_box(Vec3::ZERO, Vec3::new(2.0, 1.0, 4.0), Rgb::ONE);
        let mut s = crate::sampling::Sampler::for_pixel(4, 4, 4);
        let mut octants = [0u32; 8];
        let n = 80_000;
        for _ in 0..n {
            let p = Vec3::new(-1.0, -1.0, -1.0);
            let sample = light.sample(p, s.next2()).unwrap();
            let y = p + sample.wi * sample.distance;
            let o = (y.x > 1.0) as usize | ((y.y > 0.5) as usize) << 1 | ((y.z > 2.0) as usize) << 2;
            octants[o] += 1;
            assert!((sample.weight.x - 1.0 / (sample.distance * sample.distance)).abs() < 1e-3 * sample.weight.x);
        }
        for c in octants {
            assert!((c as f64 / n as f64 - 0.125).abs() < 0.005, "{octants:?}");
        }
    }
}
