//! Random numbers and the warps that turn them into directions and points.
//!
//! Every pixel draws from its own generator, seeded from (scene seed, pixel,
//! pass) by a hash, so an image does not depend on which thread rendered what.

pub mod sobol;

use glam::{Vec2, Vec3};
use rand::RngExt;
use rand_pcg::Pcg32;
use std::f32::consts::PI;

/// A per-pixel stream of uniform numbers in [0, 1). A clone goes on with
/// the same numbers (the viewer keeps a pixel's stream after its camera's
/// draws, to shade from there frame after frame).
#[derive(Clone)]
pub struct Sampler {
    rng: Pcg32,
    /// The sample's number within its pixel, across passes.
    sample: u64,
    /// A key of (seed, pixel) for the pixel's scrambled Sobol' points.
    pixel_key: u64,
}

/// SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mix.
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Sampler {
    /// The generator of one sample (`sample`: its number across all passes)
    /// of one pixel of a render with this seed.
    pub fn for_pixel(seed: u64, pixel: u64, sample: u64) -> Self {
        let pixel_key = mix64(mix64(seed) ^ pixel);
        let key = mix64(pixel_key ^ sample.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        // Both keys are hashes already, so they start the generator as they
        // are (hashing them again into a seed, as `seed_from_u64` does, cost
        // a tenth of the viewer's frame): each pixel has its own stream, as
        // in pbrt's samplers, and each sample starts at a random place on
        // it, so that two samples of a pixel overlap within a thousand draws
        // with a chance of about 2000/2^64 per pair.
        Self { rng: Pcg32::new(key, pixel_key), sample, pixel_key }
    }

    /// Four stratified numbers in [0, 1): this sample's point of the pixel's
    /// Owen-scrambled Sobol' sequence in `group` (sobol.rs). The pixel's
    /// samples 0, 1, 2, ... are the points 0, 1, 2, ... of one sequence, so
    /// any 2^k consecutive samples from 0 are stratified in each coordinate,
    /// across passes too; each group has its own scramble, so groups are
    /// independent of each other. Group 0 is the camera's (film and lens).
    pub fn stratified4(&self, group: u32) -> [f32; 4] {
        let seed = (mix64(self.pixel_key ^ (group as u64 + 1).wrapping_mul(0xd1b5_4a32_d192_ed03)) >> 32) as u32;
        sobol::scrambled_sobol4(self.sample as u32, seed)
    }

    /// A uniform number in [0, 1). (Not an Iterator: the stream never ends.)
    #[inline]
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> f32 {
        self.rng.random::<f32>()
    }

    #[inline]
    pub fn next2(&mut self) -> Vec2 {
        Vec2::new(self.next(), self.next())
    }

    /// A random 64-bit key, for [`keyed2`].
    #[inline]
    pub fn next_key(&mut self) -> u64 {
        self.rng.random::<u64>()
    }
}

/// Two uniform numbers in [0, 1) for item `index` under `key`: a
/// counter-based draw, so that what item i gets does not depend on which
/// other items were drawn (lights culled at one point and not another).
#[inline]
pub fn keyed2(key: u64, index: u64) -> Vec2 {
    let bits = mix64(key ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15).wrapping_add(0x632b_e59b_d9b4_e019));
    // The top 24 bits of each half make floats exact in [0, 1).
    let scale = 1.0 / (1u32 << 24) as f32;
    Vec2::new((bits >> 40) as f32 * scale, ((bits >> 8) & 0xff_ffff) as f32 * scale)
}

/// An orthonormal basis (t, b, n) around a unit vector n, by the branchless
/// construction of Duff et al., "Building an Orthonormal Basis, Revisited"
/// (JCGT 2017).
#[inline]
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// Expresses local (x, y, z) in the frame whose z axis is `n`.
#[inline]
pub fn to_world(local: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = basis(n);
    t * local.x + b * local.y + n * local.z
}

/// A point on the unit disk, by Shirley and Chiu's concentric map (1997).
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = u * 2.0 - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) =
        if o.x.abs() > o.y.abs() { (o.x, PI / 4.0 * (o.y / o.x)) } else { (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y)) };
    Vec2::new(r * theta.cos(), r * theta.sin())
}

/// A cosine-weighted direction about +z (Malley's method); pdf = cos θ/π.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    Vec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}

/// A direction uniformly inside the cone of half angle θmax around +z, given
/// cos θmax; pdf = 1 / (2π (1 − cos θmax)).
pub fn uniform_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let cos_theta = (1.0 - u.x) + u.x * cos_theta_max;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// A direction at an angle α from the unit vector `axis` drawn uniformly in
/// [0, π/2], its azimuth uniform: the pdf, [`angle_uniform_pdf`], is
/// 1/(π² sin α) per steradian, growing as 1/α toward the axis. The light
/// that a point light at distance d scatters toward a ray through a medium
/// grows as 1/h where the ray passes it at distance h ≈ d·α, so its
/// estimate over directions drawn so stays bounded; over directions drawn
/// by a phase function or BRDF its second moment diverges.
pub fn angle_uniform(u: Vec2, axis: Vec3) -> Vec3 {
    let (sin_alpha, cos_alpha) = (0.5 * PI * u.x).sin_cos();
    let phi = 2.0 * PI * u.y;
    to_world(Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha), axis)
}

/// The solid-angle pdf of `wi` drawn by [`angle_uniform`] about `axis`
/// (both unit): 1/(π² sin α) on the axis's hemisphere, 0 beyond. sin α
/// from the cross product, which keeps its precision near the axis, where
/// 1 − cos² α would round to 0.
pub fn angle_uniform_pdf(axis: Vec3, wi: Vec3) -> f32 {
    if axis.dot(wi) <= 0.0 {
        return 0.0;
    }
    1.0 / (PI * PI * axis.cross(wi).length())
}

/// A direction uniformly on the unit sphere; pdf = 1/(4π).
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pearson's correlation of paired values.
    fn correlation(pairs: &[(f32, f32)]) -> f64 {
        let n = pairs.len() as f64;
        let (mx, my) = pairs.iter().fold((0.0, 0.0), |(a, b), &(x, y)| (a + x as f64 / n, b + y as f64 / n));
        let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
        for &(x, y) in pairs {
            let (dx, dy) = (x as f64 - mx, y as f64 - my);
            (sxy, sxx, syy) = (sxy + dx * dy, sxx + dx * dx, syy + dy * dy);
        }
        sxy / (sxx * syy).sqrt()
    }

    #[test]
    fn pixel_generators_are_uniform_and_independent_of_each_other() {
        // 64 pixels × 64 samples: the first numbers of all 4096 generators
        // fill 16 bins evenly (χ² with 15 degrees of freedom, whose 99.99th
        // percentile is 44.3), and are uncorrelated with those of the next
        // pixel, of the next sample, and with each generator's own second
        // number (|r| < 4/√n, four standard errors).
        let first = |pixel: u64, sample: u64| Sampler::for_pixel(9, pixel, sample).next();
        let mut bins = [0u32; 16];
        let (mut by_pixel, mut by_sample, mut in_stream) = (Vec::new(), Vec::new(), Vec::new());
        for pixel in 0..64 {
            for sample in 0..64 {
                let mut s = Sampler::for_pixel(9, pixel, sample);
                let (u, v) = (s.next(), s.next());
                bins[(u * 16.0) as usize] += 1;
                by_pixel.push((u, first(pixel + 1, sample)));
                by_sample.push((u, first(pixel, sample + 1)));
                in_stream.push((u, v));
            }
        }
        let expected = 4096.0 / 16.0;
        let chi2: f64 = bins.iter().map(|&b| (b as f64 - expected).powi(2) / expected).sum();
        assert!(chi2 < 44.3, "χ² {chi2:.1} over 15 degrees of freedom: {bins:?}");
        let bound = 4.0 / 4096f64.sqrt();
        for (what, pairs) in [("next pixel", by_pixel), ("next sample", by_sample), ("own second number", in_stream)] {
            let r = correlation(&pairs);
            assert!(r.abs() < bound, "correlation with the {what}: {r:.4}");
        }
    }

    #[test]
    fn basis_is_orthonormal() {
        let mut s = Sampler::for_pixel(1, 2, 3);
        for _ in 0..1000 {
            let n = uniform_sphere(s.next2());
            let (t, b) = basis(n);
            for (x, y) in [(t, b), (t, n), (b, n)] {
                assert!(x.dot(y).abs() < 1e-5);
            }
            for v in [t, b] {
                assert!((v.length() - 1.0).abs() < 1e-5);
            }
            assert!((t.cross(b) - n).length() < 1e-4, "right-handed");
        }
    }

    #[test]
    fn angle_uniform_pdf_integrates_to_one_and_matches_its_samples() {
        // ∫ pdf dω over the sphere by a midpoint sum on a grid in (cos θ, φ)
        // about another axis than the distribution's, so that the grid
        // does not follow the pdf's own form: 1 to the sum's accuracy.
        let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (n_cos, n_phi) = (2000, 400);
        let mut integral = 0.0f64;
        for i in 0..n_cos {
            let z = -1.0 + (i as f64 + 0.5) * 2.0 / n_cos as f64;
            let r = (1.0 - z * z).sqrt();
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) * 2.0 * std::f64::consts::PI / n_phi as f64;
                let wi = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                integral += angle_uniform_pdf(axis, wi) as f64;
            }
        }
        integral *= 4.0 * std::f64::consts::PI / (n_cos * n_phi) as f64;
        assert!((integral - 1.0).abs() < 0.01, "{integral}");
        // Samples: unit, on the axis's side, and E[g/pdf] = ∫ g dω for
        // g = max(0, cos α)² (∫ = 2π/3), which checks the pdf against the
        // warp where it is large and where it is small.
        let mut s = Sampler::for_pixel(5, 0, 0);
        let n = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let wi = angle_uniform(s.next2(), axis);
            assert!((wi.length() - 1.0).abs() < 1e-5 && wi.dot(axis) >= -1e-6);
            let pdf = angle_uniform_pdf(axis, wi);
            if pdf > 0.0 && pdf.is_finite() {
                sum += (wi.dot(axis).max(0.0) as f64).powi(2) / pdf as f64;
            }
        }
        let estimate = sum / n as f64;
        let expected = 2.0 * std::f64::consts::PI / 3.0;
        assert!((estimate - expected).abs() < 0.01 * expected, "{estimate} against {expected}");
    }

    #[test]
    fn cone_samples_stay_in_cone_and_cover_it_uniformly() {
        // The fraction of samples with cos θ above the cone's mid-cosine must
        // be the solid-angle fraction, 1/2 (cos θ is uniform in the cone).
        let cos_max = 0.8f32;
        let mid = 0.5 * (1.0 + cos_max);
        let mut s = Sampler::for_pixel(7, 0, 0);
        let n = 100_000;
        let mut above = 0;
        for _ in 0..n {
            let d = uniform_cone(s.next2(), cos_max);
            assert!(d.z >= cos_max - 1e-6);
            assert!((d.length() - 1.0).abs() < 1e-5);
            above += (d.z > mid) as usize;
        }
        let frac = above as f64 / n as f64;
        assert!((frac - 0.5).abs() < 0.005, "{frac}");
    }
}
