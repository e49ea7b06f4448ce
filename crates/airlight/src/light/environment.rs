//! Environment maps: a sky whose radiance varies with direction, read from
//! an equirectangular (latitude-longitude) image and importance-sampled
//! by its texels' power.
//!
//! The image covers the sphere of directions: its rows run from straight
//! up (+y, the top row) to straight down, its columns once around, the
//! centre column looking along −z and columns to its right toward +x. A
//! direction d = (sin θ sin φ, cos θ, −sin θ cos φ) is at u = ½ + φ/2π,
//! v = θ/π. Each texel's radiance is constant over its patch of the
//! sphere (no filtering), which is what the sampling density is made
//! from: texel (i, j) is drawn with chance in proportion to its luminance
//! times the sine of its row's polar angle (about its patch's solid
//! angle), row first and column within it, and a direction uniformly in
//! solid angle within its patch; the density is the chance over the
//! patch's solid angle (after Pharr, Jakob and Humphreys, "Physically
//! Based Rendering", 4th ed., section 12.5, there with bilinear texels).

use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// An equirectangular environment map with its sampling tables.
#[derive(Clone, PartialEq)]
pub struct EnvironmentMap {
    width: u32,
    height: u32,
    /// Linear radiance, row by row from the top.
    texels: Vec<Rgb>,
    /// Per row: the cumulative weights of its texels, the last 1.
    columns: Vec<f32>,
    /// The cumulative weights of the rows, the last 1.
    rows: Vec<f32>,
    /// Per texel: its chance of being drawn (row's × column's within it).
    chance: Vec<f32>,
    /// A hash of the texels, for the debug text.
    checksum: u64,
}

impl std::fmt::Debug for EnvironmentMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvironmentMap")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("checksum", &format_args!("{:016x}", self.checksum))
            .finish()
    }
}

/// The bytes an environment map of `width × height` texels takes.
pub fn environment_bytes(width: u32, height: u32) -> u64 {
    // Texels (12 bytes), a column table and a chance per texel (8).
    (width as u64 * height as u64).saturating_mul(20).saturating_add(height as u64 * 4)
}

impl EnvironmentMap {
    /// A map of `width × height` linear radiances, row by row from the
    /// top; None if the sizes do not match, one is zero, or a radiance is
    /// negative or not finite.
    pub fn new(width: u32, height: u32, texels: Vec<Rgb>) -> Option<EnvironmentMap> {
        if width == 0 || height == 0 || texels.len() as u64 != width as u64 * height as u64 {
            return None;
        }
        if texels.iter().any(|t| !(t.is_finite() && t.min_element() >= 0.0)) {
            return None;
        }
        let (w, h) = (width as usize, height as usize);
        let luminance = |c: Rgb| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        let mut columns = vec![0.0f32; w * h];
        let mut row_weights = vec![0.0f64; h];
        for j in 0..h {
            let sin = (PI * (j as f32 + 0.5) / h as f32).sin() as f64;
            let row = &texels[j * w..(j + 1) * w];
            let weights: Vec<f64> = row.iter().map(|c| luminance(*c) as f64 * sin).collect();
            let total: f64 = weights.iter().sum();
            row_weights[j] = total;
            let mut sum = 0.0;
            for (i, wgt) in weights.iter().enumerate() {
                sum += if total > 0.0 { wgt / total } else { 1.0 / w as f64 };
                columns[j * w + i] = if i + 1 == w { 1.0 } else { sum as f32 };
            }
        }
        let total: f64 = row_weights.iter().sum();
        let mut rows = vec![0.0f32; h];
        let mut sum = 0.0;
        for j in 0..h {
            sum += if total > 0.0 { row_weights[j] / total } else { 1.0 / h as f64 };
            rows[j] = if j + 1 == h { 1.0 } else { sum as f32 };
        }
        let step = |table: &[f32], k: usize| table[k] - if k == 0 { 0.0 } else { table[k - 1] };
        let mut chance = vec![0.0f32; w * h];
        for j in 0..h {
            let row_chance = step(&rows, j);
            for i in 0..w {
                chance[j * w + i] = row_chance * step(&columns[j * w..(j + 1) * w], i);
            }
        }
        let words = texels.iter().flat_map(|t| t.to_array().map(f32::to_bits));
        let checksum = crate::geometry::checksum(words);
        Some(EnvironmentMap { width, height, texels, columns, rows, chance, checksum })
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The texel a unit direction falls in.
    fn texel_of(&self, d: Vec3) -> (usize, usize) {
        let theta = d.y.clamp(-1.0, 1.0).acos();
        let phi = d.x.atan2(-d.z);
        let u = 0.5 + phi / (2.0 * PI);
        let v = theta / PI;
        let i = ((u * self.width as f32) as usize).min(self.width as usize - 1);
        let j = ((v * self.height as f32) as usize).min(self.height as usize - 1);
        (i, j)
    }

    /// The radiance arriving from the unit direction `d` (`d` pointing
    /// away from the scene, toward the sky).
    pub fn radiance(&self, d: Vec3) -> Rgb {
        let (i, j) = self.texel_of(d);
        self.texels[j * self.width as usize + i]
    }

    /// A direction drawn with `u` by the texels' power, its radiance and
    /// its solid-angle density. The density is constant over each texel's
    /// patch: θ within the row is drawn in proportion to sin θ there.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Rgb, f32)> {
        let (w, h) = (self.width as usize, self.height as usize);
        let j = self.rows.partition_point(|&c| c <= u.x).min(h - 1);
        let below = if j == 0 { 0.0 } else { self.rows[j - 1] };
        let row_chance = self.rows[j] - below;
        if row_chance <= 0.0 {
            return None;
        }
        let ux = ((u.x - below) / row_chance).clamp(0.0, 1.0);
        let row = &self.columns[j * w..(j + 1) * w];
        let i = row.partition_point(|&c| c <= u.y).min(w - 1);
        let left = if i == 0 { 0.0 } else { row[i - 1] };
        let col_chance = row[i] - left;
        if col_chance <= 0.0 {
            return None;
        }
        let uy = ((u.y - left) / col_chance).clamp(0.0, 1.0);
        // Uniform in solid angle within the patch: cos θ uniform between
        // the row's edges, φ uniform across the column.
        let (t0, t1) = (PI * j as f32 / h as f32, PI * (j + 1) as f32 / h as f32);
        let cos = t0.cos() + (t1.cos() - t0.cos()) * ux;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * ((i as f32 + uy) / w as f32 - 0.5);
        let d = Vec3::new(sin * phi.sin(), cos, -sin * phi.cos());
        // The density is the chance over the patch's solid angle.
        let patch = (2.0 * PI / w as f32) * (t0.cos() - t1.cos());
        let pdf = self.chance[j * w + i] / patch;
        (pdf > 0.0 && pdf.is_finite()).then(|| (d, self.texels[j * w + i], pdf))
    }

    /// The solid-angle density with which [`EnvironmentMap::sample`] draws
    /// `d`: the texel's chance over its patch's solid angle.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let (i, j) = self.texel_of(d);
        let (w, h) = (self.width as usize, self.height as usize);
        let (t0, t1) = (PI * j as f32 / h as f32, PI * (j + 1) as f32 / h as f32);
        let patch = (2.0 * PI / w as f32) * (t0.cos() - t1.cos());
        self.chance[j * w + i] / patch
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Sampler, uniform_sphere};

    /// A map with a bright patch on a dim sky.
    fn map() -> EnvironmentMap {
        let (w, h) = (32, 16);
        let texels = (0..w * h)
            .map(|k| {
                let (i, j) = (k % w, k / w);
                if (10..13).contains(&i) && (4..6).contains(&j) { Rgb::new(40.0, 30.0, 20.0) } else { Rgb::splat(0.2) }
            })
            .collect();
        EnvironmentMap::new(w as u32, h as u32, texels).unwrap()
    }

    #[test]
    fn sampling_and_uniform_sampling_estimate_the_same_irradiance_the_map_with_less_noise() {
        // The irradiance on an upward facing surface, ∫ L cos⁺ dω, by the
        // map's own samples and by uniform directions: the same within
        // noise, and the map's samples with a fraction of the variance.
        let m = map();
        let n = 200_000;
        let (mut s1, mut s2) = (Sampler::for_pixel(1, 2, 3), Sampler::for_pixel(4, 5, 6));
        let (mut sum_map, mut sq_map, mut sum_uni, mut sq_uni) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for _ in 0..n {
            let x = match m.sample(s1.next2()) {
                Some((d, l, pdf)) => (l.x * d.y.max(0.0) / pdf) as f64,
                None => 0.0,
            };
            sum_map += x;
            sq_map += x * x;
            let d = uniform_sphere(s2.next2());
            let y = (m.radiance(d).x * d.y.max(0.0) * 4.0 * PI) as f64;
            sum_uni += y;
            sq_uni += y * y;
        }
        let (mean_map, mean_uni) = (sum_map / n as f64, sum_uni / n as f64);
        let var_map = sq_map / n as f64 - mean_map * mean_map;
        let var_uni = sq_uni / n as f64 - mean_uni * mean_uni;
        let tolerance = 4.0 * (var_uni / n as f64).sqrt();
        assert!((mean_map - mean_uni).abs() < tolerance, "map {mean_map} against uniform {mean_uni}");
        assert!(var_map < 0.2 * var_uni, "variance {var_map} against {var_uni}");
    }

    #[test]
    fn the_density_of_a_sample_is_the_density_of_its_direction_and_integrates_to_one() {
        let m = map();
        let mut s = Sampler::for_pixel(7, 8, 9);
        for _ in 0..10_000 {
            if let Some((d, l, pdf)) = m.sample(s.next2()) {
                assert!((m.pdf(d) - pdf).abs() <= 1e-3 * pdf, "{d}: {pdf} vs {}", m.pdf(d));
                assert_eq!(m.radiance(d), l);
            }
        }
        // ∫ pdf dω = 1 by uniform directions.
        let n = 400_000;
        let sum: f64 = (0..n).map(|_| m.pdf(uniform_sphere(s.next2())) as f64).sum();
        let integral = sum / n as f64 * 4.0 * std::f64::consts::PI;
        assert!((integral - 1.0).abs() < 0.02, "{integral}");
    }

    #[test]
    fn directions_land_where_the_convention_puts_them() {
        // Up is the top row, −z the centre column, +x to its right.
        let (w, h) = (4, 2);
        let texels = (0..8).map(|k| Rgb::splat(k as f32)).collect();
        let m = EnvironmentMap::new(w, h, texels).unwrap();
        assert_eq!(m.texel_of(Vec3::new(0.0, 0.5, -1.0).normalize()), (2, 0));
        assert_eq!(m.texel_of(Vec3::new(1.0, -0.5, 0.3).normalize()), (3, 1));
        assert_eq!(m.texel_of(Vec3::new(-1.0, 0.5, -0.1).normalize()), (1, 0));
    }
}
