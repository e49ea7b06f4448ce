//! Procedural fog: fractal value noise, inside a box or filling space,
//! optionally times an exponential height falloff. Patchy mist without a
//! file.
//!
//! With q = p / scale (per axis) the density is
//!
//!   ρ(p) = max(0, offset + F(q)) · h(p),
//!   F(q) = Σ_{i<octaves} gainⁱ·v(2ⁱ q + sᵢ) / Σ_{i<octaves} gainⁱ,
//!   h(p) = exp(−falloff·(y − base)) (1 without a falloff),
//!
//! where v is value noise: a pseudo-random value in [−1, 1] at each point
//! of the integer lattice (a hash of the point, the seed and the octave),
//! blended between the eight surrounding points by the quintic fade
//! 6t⁵ − 15t⁴ + 10t³ (Perlin, "Improving Noise", 2002), and sᵢ a per-octave
//! shift. The blend is a convex combination, so |v| ≤ 1 and |F| ≤ 1: the
//! density never exceeds max(0, offset + 1)·h, the bound tracking uses.
//! `scale` is the size of the largest features; each octave halves it
//! (lacunarity 2); `gain` weighs each octave against the one before;
//! `offset` moves the whole field up (denser, fewer gaps) or down
//! (sparser, more gaps).

use glam::{IVec3, Vec3};

/// Most octaves.
pub const MAX_OCTAVES: u32 = 12;

/// Most pieces of the quadrature of the optical depth along one segment.
pub const MAX_PIECES: usize = 256;

/// Fractal noise fog (module notes).
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseFog {
    /// Size of the largest features, per axis (world units, > 0).
    pub scale: Vec3,
    pub octaves: u32,
    pub gain: f32,
    pub offset: f32,
    pub seed: u32,
    /// Where the fog is; None: everywhere.
    pub bounds: Option<(Vec3, Vec3)>,
    /// Height falloff (base, falloff); None: none.
    pub height: Option<(f32, f32)>,
}

impl NoiseFog {
    /// The density at `p` (module notes).
    pub fn density(&self, p: Vec3) -> f32 {
        if let Some((lo, hi)) = self.bounds
            && !(p.cmpge(lo).all() && p.cmple(hi).all())
        {
            return 0.0;
        }
        let base = (self.offset + self.fractal(p / self.scale)).max(0.0);
        if base == 0.0 { 0.0 } else { base * self.height_factor(p) }
    }

    fn height_factor(&self, p: Vec3) -> f32 {
        self.height.map_or(1.0, |(base, falloff)| (-falloff * (p.y - base)).exp())
    }

    /// F(q) in [−1, 1].
    pub fn fractal(&self, q: Vec3) -> f32 {
        let (mut sum, mut norm, mut amplitude, mut frequency) = (0.0f32, 0.0f32, 1.0f32, 1.0f32);
        for octave in 0..self.octaves.max(1) {
            // A shift per octave, so that lattice points of octaves do not line up.
            let shift = Vec3::new(0.31, 0.57, 0.73) * octave as f32 * 17.0;
            sum += amplitude * value_noise(q * frequency + shift, self.seed, octave);
            norm += amplitude;
            amplitude *= self.gain;
            frequency *= 2.0;
        }
        if norm > 0.0 { sum / norm } else { 0.0 }
    }

    /// The bound max(0, offset + 1) of the density before the height factor.
    pub fn noise_bound(&self) -> f32 {
        (self.offset + 1.0).max(0.0)
    }

    /// The part of [t0, t1] of o + t·d inside the box (all of it without one).
    pub fn clip(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Option<(f32, f32)> {
        let (mut lo, mut hi) = (t0, t1);
        if let Some((min, max)) = self.bounds {
            for axis in 0..3 {
                if d[axis] == 0.0 {
                    if o[axis] < min[axis] || o[axis] > max[axis] {
                        return None;
                    }
                    continue;
                }
                let (a, b) = ((min[axis] - o[axis]) / d[axis], (max[axis] - o[axis]) / d[axis]);
                lo = lo.max(a.min(b));
                hi = hi.min(a.max(b));
            }
        }
        (lo < hi && self.noise_bound() > 0.0).then_some((lo, hi))
    }

    /// Calls `f(t0, t1, bound)` for consecutive pieces of [t0, t1] of
    /// o + t·d inside the fog with a bound of the density over each: with a
    /// height falloff, up to 16 pieces, each bounded by the larger height
    /// factor at its ends (the factor is monotone along a line); without,
    /// one. Infinite ends are cut to the box or left to the caller.
    pub fn majorant_segments(&self, o: Vec3, d: Vec3, t0: f32, t1: f32, mut f: impl FnMut(f32, f32, f32) -> bool) {
        let Some((a, b)) = self.clip(o, d, t0, t1) else { return };
        let bound = self.noise_bound();
        let pieces = if self.height.is_some() && b.is_finite() { 16 } else { 1 };
        let step = (b - a) / pieces as f32;
        for i in 0..pieces {
            let s0 = a + step * i as f32;
            let s1 = if i + 1 == pieces { b } else { s0 + step };
            let h = if self.height.is_some() {
                self.height_factor(o + d * s0).max(self.height_factor(o + d * s1))
            } else {
                1.0
            };
            if !f(s0, s1, bound * h) {
                return;
            }
        }
    }

    /// ∫ density over [t0, t1] of o + t·d (t1 may be infinite only when a
    /// box cuts it): Gauss–Legendre, two points per piece, pieces half the
    /// finest octave's feature size, at most [`MAX_PIECES`] of them (longer
    /// pieces on longer stretches).
    pub fn integral(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> f64 {
        let Some((a, b)) = self.clip(o, d, t0, t1) else { return 0.0 };
        if !b.is_finite() {
            return f64::INFINITY;
        }
        let finest = self.scale.min_element() / 2f32.powi(self.octaves.max(1) as i32 - 1);
        let pieces = (((b - a) / (0.5 * finest)).ceil() as usize).clamp(1, MAX_PIECES);
        const NODE: f64 = 0.577_350_269_189_625_8;
        let h = (b as f64 - a as f64) / pieces as f64;
        let at = |t: f64| self.density(o + d * t as f32) as f64;
        (0..pieces)
            .map(|i| {
                let mid = a as f64 + (i as f64 + 0.5) * h;
                0.5 * h * (at(mid - 0.5 * h * NODE) + at(mid + 0.5 * h * NODE))
            })
            .sum()
    }
}

/// Value noise in [−1, 1] at `q` (module notes).
fn value_noise(q: Vec3, seed: u32, octave: u32) -> f32 {
    let cell = q.floor();
    let f = q - cell;
    let c = cell.as_ivec3();
    let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let at = |dx: i32, dy: i32, dz: i32| lattice(c + IVec3::new(dx, dy, dz), seed, octave);
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(at(0, 0, 0), at(1, 0, 0), u);
    let x10 = lerp(at(0, 1, 0), at(1, 1, 0), u);
    let x01 = lerp(at(0, 0, 1), at(1, 0, 1), u);
    let x11 = lerp(at(0, 1, 1), at(1, 1, 1), u);
    lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
}

/// A pseudo-random value in [−1, 1] for a lattice point.
fn lattice(p: IVec3, seed: u32, octave: u32) -> f32 {
    let mut h = (p.x as u32 as u64)
        | ((p.y as u32 as u64) << 32)
            ^ ((p.z as u32 as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
            ^ ((seed as u64) << 17 | octave as u64).wrapping_mul(0xd1b5_4a32_d192_ed03);
    // SplitMix64's finaliser.
    h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^= h >> 31;
    (h >> 40) as f32 / (1u64 << 23) as f32 - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fog() -> NoiseFog {
        NoiseFog {
            scale: Vec3::new(2.0, 1.0, 2.0),
            octaves: 4,
            gain: 0.5,
            offset: 0.1,
            seed: 7,
            bounds: Some((Vec3::new(-3.0, 0.0, -3.0), Vec3::new(3.0, 2.0, 3.0))),
            height: Some((0.0, 0.5)),
        }
    }

    #[test]
    fn noise_stays_in_its_bound_and_is_patchy() {
        let f = fog();
        let (mut zero, mut most, mut n) = (0, 0.0f32, 0);
        for i in 0..20_000 {
            let p = Vec3::new((i % 37) as f32 * 0.16 - 2.9, (i % 11) as f32 * 0.18, (i / 407) as f32 * 0.12 - 2.9);
            let v = f.fractal(p);
            assert!((-1.0..=1.0).contains(&v), "{v}");
            let rho = f.density(p);
            let bound = f.noise_bound() * (-0.5 * p.y).exp();
            assert!(rho >= 0.0 && rho <= bound * 1.000_001, "{rho} > {bound}");
            zero += usize::from(rho == 0.0);
            most = most.max(rho);
            n += 1;
        }
        assert!(zero > n / 10 && zero < 9 * n / 10, "gaps in {zero} of {n}");
        assert!(most > 0.3, "{most}");
        // Outside the box: vacuum. Another seed: another field.
        assert_eq!(f.density(Vec3::new(0.0, 2.5, 0.0)), 0.0);
        let other = NoiseFog { seed: 8, ..fog() };
        assert_ne!(f.fractal(Vec3::splat(0.3)), other.fractal(Vec3::splat(0.3)));
    }

    #[test]
    fn majorant_pieces_bound_the_density_and_the_integral_matches_a_fine_sum() {
        let f = fog();
        let o = Vec3::new(-4.0, 1.9, -1.0);
        let d = Vec3::new(1.0, -0.2, 0.3).normalize();
        let mut covered = None;
        f.majorant_segments(o, d, 0.0, 20.0, |a, b, bound| {
            covered.get_or_insert(a);
            for k in 0..=50 {
                let t = a + (b - a) * k as f32 / 50.0;
                assert!(f.density(o + d * t) <= bound * 1.000_001);
            }
            true
        });
        assert!(covered.is_some());
        let (a, b) = f.clip(o, d, 0.0, 20.0).unwrap();
        let n = 200_000;
        let h = (b - a) as f64 / n as f64;
        let fine: f64 = (0..n).map(|i| f.density(o + d * (a as f64 + (i as f64 + 0.5) * h) as f32) as f64 * h).sum();
        let quadrature = f.integral(o, d, 0.0, 20.0);
        assert!((quadrature - fine).abs() < 0.01 * fine, "{quadrature} vs {fine}");
    }
}
