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
