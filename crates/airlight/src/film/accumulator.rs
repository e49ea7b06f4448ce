//! The one accumulator under every render: per pixel the sum and the sum of
//! squares of its samples and their count.
//!
//! Sums are kept in fixed point (`i128`), not floating point: each sample is
//! rounded once to a multiple of 2⁻⁴⁸ (its square to a multiple of 2⁻⁶⁴)
//! and integers add exactly, in any order. So the same samples give the
//! same bits however they were grouped: one render, progressive passes,
//! sample shards rendered on other machines and merged, tiles. A floating
//! point sum would differ in its last bits with the grouping.
//!
//! Range and precision: a sum holds up to 2⁷⁹ ≈ 6·10²³ (radiance times
//! samples), a sum of squares 2⁶³ ≈ 9·10¹⁸; beyond, the sums saturate
//! instead of wrapping (only the variance of pixels with single samples
//! above 3·10⁹ is affected). The rounding of a sample, at most 1.8·10⁻¹⁵,
//! is far below f32's own resolution for the radiance of any visible pixel.

use crate::Rgb;
use crate::film::Image;
use glam::DVec3;
use rayon::prelude::*;

/// Fraction bits of a sample in [`PixelSum::sum`].
pub const SUM_FRACTION_BITS: i32 = 48;
/// Fraction bits of a squared sample in [`PixelSum::sum_squares`].
pub const SQUARE_FRACTION_BITS: i32 = 64;

/// One pixel's samples: fixed-point sums per channel and how many.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PixelSum {
    /// Σ x · 2⁴⁸, each term rounded to an integer.
    pub sum: [i128; 3],
    /// Σ x² · 2⁶⁴, each term rounded to an integer.
    pub sum_squares: [i128; 3],
    /// Samples taken, broken ones (NaN, infinite) included: they count as
    /// zero, so that one broken sample does not bias the pixel upward.
    pub count: u64,
}

/// `x · 2^bits` rounded to the nearest integer (ties away from zero);
/// saturates at the ends of `i128` (Rust's float-to-int cast does), so no
/// input overflows. `x` is an f32's value or the square of one.
///
/// Below 2⁵¹ in magnitude the rounding is |y| + ½ truncated by the
/// hardware's f64 → i64 conversion: y = x·2^bits has at most 48
/// significant bits (24 of an f32, 48 of its square), so |y| + ½ is exact
/// in f64 there (and below ½ it stays below 1), and the result is
/// `y.round()`'s. From 2⁴⁷ up, y is already an integer (its lowest bit is
/// at least the 48th below its highest), so up to 2⁶³ the hardware
/// conversion alone is exact; that covers the squares of samples up to
/// 0.7. Only larger values take `round` (a libm call) and the software
/// f64 → i128 conversion, which together were 4% of the Cornell box's time
/// when every sample took them.
#[inline]
fn to_fixed(x: f64, bits: i32) -> i128 {
    let y = x * 2f64.powi(bits);
    let magnitude = y.abs();
    if magnitude < (1u64 << 51) as f64 {
        let rounded = (magnitude + 0.5) as i64;
        return if y < 0.0 { -rounded } else { rounded } as i128;
    }
    if magnitude < 2f64.powi(63) {
        return y as i64 as i128;
    }
    y.round() as i128
}

/// `x · 2^-bits` rounded to the nearest f64. A sum that fits in an `i64`
/// takes the hardware conversion (one instruction), which rounds exactly
/// as the i128 → f64 conversion (a library call, `__floattidf`) does: to
/// nearest, ties to even.
#[inline]
fn from_fixed(x: i128, bits: i32) -> f64 {
    let whole = match i64::try_from(x) {
        Ok(small) => small as f64,
        Err(_) => wide_to_f64(x),
    };
    whole * 2f64.powi(-bits)
}

/// The software conversion, kept out of line: inlined, the compiler sees
/// that both branches of [`from_fixed`] give the same value and keeps only
/// this one.
#[cold]
#[inline(never)]
fn wide_to_f64(x: i128) -> f64 {
    x as f64
}

/// Something samples are added into: a pixel's sums.
pub(crate) trait AddSample {
    fn add(&mut self, sample: Rgb);
}

impl AddSample for PixelSum {
    #[inline]
    fn add(&mut self, sample: Rgb) {
        PixelSum::add(self, sample)
    }
}

/// A pixel's sums without the sums of squares, for a render that keeps
/// only the means (`render::render_samples`): its sums and count are a
/// [`PixelSum`]'s, bit for bit, so its mean is too, and a sample takes half
/// the work to add.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct PixelTotal {
    sum: [i128; 3],
    count: u64,
}

impl PixelTotal {
    /// The mean of the samples (black before the first), as [`PixelSum::mean`].
    pub fn mean(&self) -> Rgb {
        mean_of(&self.sum, self.count).as_vec3()
    }
}

impl AddSample for PixelTotal {
    #[inline]
    fn add(&mut self, sample: Rgb) {
        self.count += 1;
        if sample.is_finite() {
            for (c, x) in sample.to_array().into_iter().enumerate() {
                self.sum[c] = self.sum[c].saturating_add(to_fixed(x as f64, SUM_FRACTION_BITS));
            }
        }
    }
}

/// The mean of samples whose fixed-point sums are `sum`.
fn mean_of(sum: &[i128; 3], count: u64) -> DVec3 {
    if count == 0 {
        return DVec3::ZERO;
    }
    let n = count as f64;
    DVec3::from_array(sum.map(|s| from_fixed(s, SUM_FRACTION_BITS) / n))
}

impl PixelSum {
    /// Adds one sample. Non-finite samples count but add nothing.
    #[inline]
    pub fn add(&mut self, sample: Rgb) {
        self.count += 1;
        if !sample.is_finite() {
            return;
        }
        for (c, x) in sample.to_array().into_iter().enumerate() {
            // f32 → f64 is exact, and so is the square of an f32 in f64
            // (24 + 24 bits of mantissa fit in 53).
            let x = x as f64;
            self.sum[c] = self.sum[c].saturating_add(to_fixed(x, SUM_FRACTION_BITS));
            self.sum_squares[c] = self.sum_squares[c].saturating_add(to_fixed(x * x, SQUARE_FRACTION_BITS));
        }
    }

    /// The sum of a single sample.
    pub fn of_one(sample: Rgb) -> PixelSum {
        let mut sum = PixelSum::default();
        sum.add(sample);
        sum
    }

    /// Adds another pixel's samples (exact, in any order).
    #[inline]
    pub fn merge(&mut self, other: &PixelSum) {
        for c in 0..3 {
            self.sum[c] = self.sum[c].saturating_add(other.sum[c]);
            self.sum_squares[c] = self.sum_squares[c].saturating_add(other.sum_squares[c]);
        }
        self.count += other.count;
    }

    /// The mean of the samples (black before the first).
    pub fn mean(&self) -> Rgb {
        self.mean_f64().as_vec3()
    }

    fn mean_f64(&self) -> DVec3 {
        mean_of(&self.sum, self.count)
    }

    /// The estimated variance of the pixel's mean, per channel: s²/n with
    /// s² = (Σx² − (Σx)²/n)/(n − 1), the unbiased sample variance. Exact in
    /// expectation for independent samples, an upper bound for stratified
    /// ones (stratification only lowers the variance of the mean). Infinite
    /// before two samples.
    pub fn variance_of_mean(&self) -> DVec3 {
        if self.count < 2 {
            return DVec3::INFINITY;
        }
        let n = self.count as f64;
        let sum = DVec3::from_array(self.sum.map(|s| from_fixed(s, SUM_FRACTION_BITS)));
        let squares = DVec3::from_array(self.sum_squares.map(|s| from_fixed(s, SQUARE_FRACTION_BITS)));
        let sample_variance = ((squares - sum * sum / n) / (n - 1.0)).max(DVec3::ZERO);
        sample_variance / n
    }
}

// SAFETY: every field is an integer (or an array of them), for which all
// zero bits are the value 0: a zeroed `PixelSum` is `PixelSum::default()`.
unsafe impl bytemuck::Zeroable for PixelSum {}

/// The samples of a band of rows of an image (all rows by default): a
/// [`PixelSum`] per pixel, in rows of the full image's width.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulator {
    width: u32,
    height: u32,
    /// The band of rows held, `first_row .. first_row + pixels.len() / width`.
    first_row: u32,
    pixels: Vec<PixelSum>,
}

/// Bytes an [`Accumulator`] holds per pixel.
pub const ACCUMULATOR_BYTES_PER_PIXEL: usize = size_of::<PixelSum>();

impl Accumulator {
    /// An empty accumulator for a whole `width` × `height` image.
    pub fn new(width: u32, height: u32) -> Self {
        Self::band(width, height, 0..height)
    }

    /// An empty accumulator for the rows `rows` of a `width` × `height`
    /// image (clipped to the image).
    pub fn band(width: u32, height: u32, rows: std::ops::Range<u32>) -> Self {
        let first_row = rows.start.min(height);
        let end = rows.end.clamp(first_row, height);
        // Zeroed memory straight from the allocator (fresh pages for a large
        // film), not `vec![PixelSum::default(); n]`, which writes every
        // byte on this one thread first: 75 ms for a 1024² film, a fifth
        // of rendering it at one sample per pixel. The pages are now zeroed
        // as the render threads first touch them.
        let pixels = bytemuck::zeroed_vec(width as usize * (end - first_row) as usize);
        Accumulator { width, height, first_row, pixels }
    }

    /// The full image's size.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The rows held.
    pub fn rows(&self) -> std::ops::Range<u32> {
        let count = (self.pixels.len() as u32).checked_div(self.width).unwrap_or(0);
        self.first_row..self.first_row + count
    }

    /// The pixels held, row by row from the first row held.
    pub fn pixels(&self) -> &[PixelSum] {
        &self.pixels
    }

    pub fn pixels_mut(&mut self) -> &mut [PixelSum] {
        &mut self.pixels
    }

    /// The sum of pixel (x, y) of the full image, if its row is held.
    pub fn pixel(&self, x: u32, y: u32) -> Option<&PixelSum> {
        if x >= self.width || !self.rows().contains(&y) {
            return None;
        }
        self.pixels.get(((y - self.first_row) * self.width + x) as usize)
    }

    pub fn pixel_mut(&mut self, x: u32, y: u32) -> Option<&mut PixelSum> {
        if x >= self.width || !self.rows().contains(&y) {
            return None;
        }
        self.pixels.get_mut(((y - self.first_row) * self.width + x) as usize)
    }

    /// Adds `other`'s samples into the rows both hold. Fails, changing
    /// nothing, when the images' sizes differ or `other` holds rows this
    /// one does not.
    pub fn merge(&mut self, other: &Accumulator) -> Result<(), String> {
        if self.size() != other.size() {
            return Err(format!(
                "the images differ in size: {}×{} and {}×{}",
                self.width, self.height, other.width, other.height
            ));
        }
        let (mine, theirs) = (self.rows(), other.rows());
        if theirs.start < mine.start || theirs.end > mine.end {
            return Err(format!("rows {theirs:?} do not lie within rows {mine:?}"));
        }
        let offset = ((theirs.start - mine.start) * self.width) as usize;
        self.pixels[offset..].par_iter_mut().zip(&other.pixels).for_each(|(a, b)| a.merge(b));
        Ok(())
    }

    /// The smallest and largest sample count of any pixel held.
    pub fn count_range(&self) -> (u64, u64) {
        let min = self.pixels.iter().map(|p| p.count).min().unwrap_or(0);
        let max = self.pixels.iter().map(|p| p.count).max().unwrap_or(0);
        (min, max)
    }

    /// The mean of each pixel's samples; rows not held are black.
    pub fn image(&self) -> Image {
        self.map(PixelSum::mean)
    }

    /// The estimated variance of each pixel's mean, per channel (see
    /// [`PixelSum::variance_of_mean`]); rows not held are black.
    pub fn variance(&self) -> Image {
        self.map(|p| p.variance_of_mean().as_vec3())
    }

    /// `f` of every pixel held, black elsewhere; on all threads, each pixel
    /// written once.
    fn map(&self, f: impl Fn(&PixelSum) -> Rgb + Sync) -> Image {
        let start = (self.first_row * self.width) as usize;
        let pixels = (0..self.width as usize * self.height as usize)
            .into_par_iter()
            .map(|i| i.checked_sub(start).and_then(|held| self.pixels.get(held)).map_or(Rgb::ZERO, &f))
            .collect();
        Image { width: self.width, height: self.height, pixels }
    }

    /// The estimated relative error of the image: √(Σ Var(mean) / Σ mean²)
    /// over pixels and channels, what [`crate::film::compare`]'s `rel_rmse`
    /// against the converged image is expected to be. Infinite before two
    /// samples in every pixel, or for a black image.
    pub fn estimated_relative_error(&self) -> f64 {
        let (mut variance, mut signal) = (0.0, 0.0);
        for p in &self.pixels {
            variance += p.variance_of_mean().element_sum();
            signal += p.mean_f64().length_squared();
        }
        if signal > 0.0 && variance.is_finite() { (variance / signal).sqrt() } else { f64::INFINITY }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples(n: usize) -> Vec<Rgb> {
        // Values over many octaves, as a renderer's samples are.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        (0..n)
            .map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                let u = (state >> 40) as f32 / (1u64 << 24) as f32;
                let octave = ((state >> 8) % 30) as i32 - 20;
                Rgb::new(u * 2f32.powi(octave), u, 1.0 - u)
            })
            .collect()
    }

    #[test]
    fn sums_that_fit_in_64_bits_convert_as_the_128_bit_conversion_does() {
        let wide = |x: i128| std::hint::black_box(x) as f64;
        let edges = [i64::MAX as i128, i64::MIN as i128, (1i128 << 53) + 1, -(1i128 << 60) - 3, (1 << 62) + 7];
        let beyond = [i64::MAX as i128 + 1, i64::MIN as i128 - 1, (3i128 << 70) + 1, i128::MAX, i128::MIN];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let random = (0..1000).map(|_| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state as i64 as i128) >> (state % 64)
        });
        for x in edges.into_iter().chain(beyond).chain(random).chain([0, 1, -1]) {
            assert_eq!(from_fixed(x, 0).to_bits(), wide(x).to_bits(), "{x}");
            assert_eq!(from_fixed(x, SUM_FRACTION_BITS).to_bits(), (wide(x) * 2f64.powi(-48)).to_bits(), "{x}");
        }
    }

    #[test]
    fn a_new_accumulator_is_all_empty_pixel_sums() {
        let acc = Accumulator::band(7, 9, 2..5);
        assert_eq!(acc.pixels().len(), 21);
        assert!(acc.pixels().iter().all(|p| *p == PixelSum::default()));
    }

    #[test]
    fn fixed_point_rounding_is_f64_round_for_every_kind_of_f32() {
        // Random f32 bit patterns (all exponents, both signs, subnormals),
        // their squares, and the values where a shortcut could slip: ties
        // at ½ below and above 2⁵¹, the boundaries 2⁵¹ and 2⁶³ themselves,
        // the largest f32.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut values: Vec<f32> = (0..2_000_000)
            .map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                f32::from_bits((state >> 32) as u32)
            })
            .filter(|x| x.is_finite())
            .collect();
        for k in [-49, -48, -47, -16, -1, 0, 1, 2, 3, 46, 47, 48, 49, 50, 51, 52, 62, 63, 64] {
            let scale = 2f32.powi(k - SUM_FRACTION_BITS);
            for m in [0.5f32, 1.5, 2.5, 0.75, 1.0 - f32::EPSILON / 2.0, 1.0 + f32::EPSILON] {
                values.push(m * scale);
                values.push(-m * scale);
            }
        }
        values.extend([0.0, -0.0, f32::MAX, -f32::MAX, f32::MIN_POSITIVE, f32::from_bits(1)]);
        for x in values {
            let x = x as f64;
            for (value, bits) in [(x, SUM_FRACTION_BITS), (x * x, SQUARE_FRACTION_BITS), (x, 0), (x * x, 0)] {
                let expected = (value * 2f64.powi(bits)).round() as i128;
                assert_eq!(to_fixed(value, bits), expected, "{value:e} · 2^{bits}");
            }
        }
    }

    #[test]
    fn the_sum_does_not_depend_on_how_samples_are_grouped() {
        let xs = samples(1000);
        let mut whole = PixelSum::default();
        for &x in &xs {
            whole.add(x);
        }
        // Reversed, and in uneven chunks merged in another order.
        let mut reversed = PixelSum::default();
        for &x in xs.iter().rev() {
            reversed.add(x);
        }
        assert_eq!(whole, reversed);
        let mut parts: Vec<PixelSum> = xs
            .chunks(37)
            .map(|chunk| {
                let mut p = PixelSum::default();
                chunk.iter().for_each(|&x| p.add(x));
                p
            })
            .collect();
        parts.reverse();
        let mut merged = PixelSum::default();
        for p in &parts {
            merged.merge(p);
        }
        assert_eq!(whole, merged);
        assert_eq!(whole.mean().to_array().map(f32::to_bits), merged.mean().to_array().map(f32::to_bits));
    }

    #[test]
    fn mean_and_variance_match_a_direct_f64_computation() {
        let xs = samples(500);
        let mut p = PixelSum::default();
        xs.iter().for_each(|&x| p.add(x));
        let n = xs.len() as f64;
        let mean: DVec3 = xs.iter().map(|x| x.as_dvec3()).sum::<DVec3>() / n;
        let var: DVec3 = xs.iter().map(|x| (x.as_dvec3() - mean) * (x.as_dvec3() - mean)).sum::<DVec3>() / (n - 1.0);
        let got = p.mean().as_dvec3();
        assert!(((got - mean) / mean).abs().max_element() < 1e-6, "{got} vs {mean}");
        let got = p.variance_of_mean();
        assert!(((got - var / n) / (var / n)).abs().max_element() < 1e-6, "{got} vs {}", var / n);
    }

    #[test]
    fn broken_samples_count_as_zero_and_huge_ones_saturate() {
        let mut p = PixelSum::default();
        p.add(Rgb::splat(2.0));
        p.add(Rgb::new(f32::NAN, f32::INFINITY, 2.0));
        assert_eq!(p.count, 2);
        // A sample with any broken channel is dropped whole.
        assert_eq!(p.mean(), Rgb::splat(1.0));
        let mut big = PixelSum::default();
        for _ in 0..4 {
            big.add(Rgb::splat(f32::MAX));
        }
        assert_eq!(big.sum[0], i128::MAX);
        assert!(big.mean().is_finite());
        assert_eq!(PixelSum::default().mean(), Rgb::ZERO);
        assert!(PixelSum::default().variance_of_mean().x.is_infinite());
    }

    #[test]
    fn a_pixel_total_is_a_pixel_sum_without_its_squares() {
        let broken = [Rgb::new(f32::NAN, 1.0, 2.0), Rgb::splat(f32::MAX), Rgb::new(-3.0, f32::INFINITY, 0.5)];
        let (mut sum, mut total) = (PixelSum::default(), PixelTotal::default());
        assert_eq!(total.mean(), sum.mean());
        for sample in samples(700).into_iter().chain(broken) {
            PixelSum::add(&mut sum, sample);
            AddSample::add(&mut total, sample);
            assert_eq!((total.sum, total.count), (sum.sum, sum.count));
            assert_eq!(total.mean().to_array().map(f32::to_bits), sum.mean().to_array().map(f32::to_bits));
        }
    }

    #[test]
    fn bands_merge_into_the_rows_they_hold() {
        let mut whole = Accumulator::new(3, 4);
        let mut band = Accumulator::band(3, 4, 1..3);
        band.pixel_mut(2, 2).unwrap().add(Rgb::splat(4.0));
        assert!(band.pixel(0, 0).is_none());
        whole.merge(&band).unwrap();
        assert_eq!(whole.image().pixel(2, 2), Rgb::splat(4.0));
        assert_eq!(whole.count_range(), (0, 1));
        assert!(band.merge(&whole).is_err(), "a band cannot take rows it does not hold");
        assert!(whole.merge(&Accumulator::new(3, 5)).is_err());
        assert_eq!(band.image().pixel(2, 2), Rgb::splat(4.0));
        assert_eq!(band.image().pixel(0, 0), Rgb::ZERO);
    }
}
