//! Adaptive sampling: the image's samples spread over its pixels by how
//! noisy each is, rather than the same number everywhere.
//!
//! Where a few pixels hold most of an image's noise (the edges of a light
//! in view, whose value is the fraction of the pixel the light covers), the
//! same budget of samples lowers the image's total squared error most when
//! each pixel's count is in proportion to the standard deviation of its
//! samples: the error Σ σᵢ²/nᵢ under Σ nᵢ = N is least at nᵢ ∝ σᵢ (a
//! Lagrange multiplier; the classical allocation of stratified sampling,
//! Neyman 1934).
//!
//! The render has two stages of the same total budget as a uniform render
//! of `spp` samples a pixel, both drawn with the render's seed:
//! 1. A pilot, samples 0 to [`pilot_samples`] of every pixel, measures
//!    each pixel's σ.
//! 2. The rest of the budget, a quarter spread evenly (a floor that keeps
//!    every pixel converging whatever the pilot saw) and three quarters in
//!    proportion to the noise around each pixel (below), each pixel at most
//!    [`CAP`] times the rest's mean. Each pixel goes on along its own
//!    sequence from where the pilot stopped.
//!
//! So a pixel's samples are samples 0, 1, 2, … of its sequence, as in a
//! uniform render with its count, the pilot's among them, and the image is
//! their mean. That mean is unbiased only if a pixel's count does not
//! depend on its own samples (a pixel whose pilot saw a bright sample would
//! otherwise ask for more samples, which then dilute it): its noise is
//! therefore taken as the largest of its eight neighbours', never its own,
//! and its share is rounded to whole samples with a number drawn from the
//! seed and the pixel alone. Pixels' samples are independent of each other,
//! so what remains of a pixel in its count is one term among the image's
//! W·H in the sum that scales every share to the budget, and in which
//! pixels reach the cap. Taking the largest neighbour also keeps edges: a
//! pixel on an edge has neighbours along the edge.
//!
//! The counts keep the budget on average; the rounding makes the total
//! differ from W·H·`spp` by a few samples (a standard deviation of at
//! most √(W·H)/2: each pixel's rounding varies by at most ¼ sample²).
//!
//! An earlier version drew the pilot with a seed of its own and left it out
//! of the image, a sixteenth of the budget spent on measuring alone: the
//! Cornell box's squared error at 512 spp was 1.06× this one's.

use super::{RenderObserver, accumulate_pixel_samples};
use crate::Rgb;
use crate::film::{Accumulator, Image};
use crate::geometry::Ray;
use crate::integrator::Integrator;
use crate::sampling::{Sampler, mix64};
use crate::scene::Scene;

/// The most samples a pixel may take in stage 2, as a multiple of the
/// stage's mean per pixel: a pixel whose pilot caught one rare, bright
/// sample (a firefly) would otherwise take a large share of the image's
/// budget on the strength of one number.
pub const CAP: u32 = 8;

/// The pilot's samples per pixel for a budget of `spp`: a sixteenth of
/// it, and at least 2 (a variance needs two).
pub fn pilot_samples(spp: u32) -> u32 {
    (spp / 16).max(2)
}

/// The fewest samples per pixel that adaptive sampling takes: below this
/// the pilot would leave stage 2 too little to spread, and the render is
/// uniform.
pub const MIN_SPP: u32 = 8;

/// The noise given a pixel whose pilot could not measure it (a variance
/// that is not finite): above any real one (samples are f32, below 4e38),
/// and small enough that the image's sum of them stays finite.
const UNMEASURED: f64 = 1e150;

/// Renders the scene with its `spp` samples a pixel on average, spread by
/// the pixels' noise (module notes). Below [`MIN_SPP`] a uniform render.
pub fn render_adaptive(scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> Image {
    let s = scene.settings();
    if s.spp < MIN_SPP {
        return super::render_samples(scene, integrator, 0, s.spp, observer);
    }
    let mut sums = pilot(scene, integrator, observer);
    let first = pilot_samples(s.spp);
    let more = plan(&sums, s.spp - first, s.seed);
    let width = s.film.width as usize;
    // Each pixel goes on from the pilot's last sample.
    let samples_of = |x: u32, y: u32| first as u64..first as u64 + more[y as usize * width + x as usize] as u64;
    accumulate_pixel_samples(scene, integrator, s.seed, samples_of, &mut sums, observer);
    sums.image()
}

/// Stage 1: samples 0 to [`pilot_samples`] of every pixel.
pub fn pilot(scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> Accumulator {
    let s = scene.settings();
    let mut sums = Accumulator::new(s.film.width, s.film.height);
    let pilot = pilot_samples(s.spp) as u64;
    // A pixel's count follows its neighbours' pilot noise; were their
    // pilot samples to share this pixel's paths, its count would follow
    // its own samples, and its mean would be biased.
    let alone = OneByOne(integrator);
    let integrator = if integrator.shares_between_pixels() { &alone } else { integrator };
    accumulate_pixel_samples(scene, integrator, s.seed, |_, _| 0..pilot, &mut sums, observer);
    sums
}

/// An integrator whose samples are traced one by one (the trait's own
/// `radiance_batch`), so that no pixel's sample depends on another's.
struct OneByOne<'a>(&'a dyn Integrator);

impl Integrator for OneByOne<'_> {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        self.0.radiance(scene, ray, sampler)
    }

    fn stratified(&self) -> bool {
        self.0.stratified()
    }
}

/// From the pilot's sums, each pixel's count of samples in stage 2 (row by
/// row), `per_pixel` a pixel on average; `seed` the render's, for the
/// rounding.
pub fn plan(pilot: &Accumulator, per_pixel: u32, seed: u64) -> Vec<u32> {
    let (width, height) = pilot.size();
    let sigma: Vec<f64> = pilot
        .pixels()
        .iter()
        .map(|p| {
            // The standard deviation of one sample, over the channels.
            let per_sample = p.variance_of_mean().element_sum() / 3.0 * p.count as f64;
            if per_sample.is_finite() { per_sample.sqrt() } else { UNMEASURED }
        })
        .collect();
    let around = neighbours_max(&sigma, width as usize, height as usize);
    allocate(&around, per_pixel, mix64(seed ^ ROUNDING))
}

/// Mixed into the seed for the rounding's numbers.
const ROUNDING: u64 = 0x726f_756e_6469_6e67;

/// The largest value among each cell's (up to) eight neighbours, the cell
/// itself left out, in a `width`×`height` grid stored row by row; 0 for a
/// cell with none (a 1×1 grid).
pub fn neighbours_max(values: &[f64], width: usize, height: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(values.len());
    for y in 0..height {
        for x in 0..width {
            let mut largest = 0.0f64;
            for yy in y.saturating_sub(1)..(y + 2).min(height) {
                for xx in x.saturating_sub(1)..(x + 2).min(width) {
                    if (xx, yy) != (x, y) {
                        largest = largest.max(values[yy * width + xx]);
                    }
                }
            }
            out.push(largest);
        }
    }
    out
}

/// Sample counts for pixels of noise `sigma` (standard deviations, ≥ 0),
/// `per_pixel` a pixel on average: a quarter of that evenly (at least 1
/// each), the rest in proportion to sigma, no count above [`CAP`] ×
/// `per_pixel` (what a capped pixel cannot take goes to the others, in
/// proportion again). Where every sigma is 0, even counts. Each pixel's
/// share is rounded up or down at random, up with a chance equal to its
/// fraction, by a number drawn from `key` and the pixel's index alone: a
/// count depends on no other pixel's rounding, and the counts sum to the
/// budget on average.
pub fn allocate(sigma: &[f64], per_pixel: u32, key: u64) -> Vec<u32> {
    let n = sigma.len();
    let floor = (per_pixel / 4).max(1).min(per_pixel);
    let headroom = (CAP.saturating_mul(per_pixel) - floor) as f64;
    let mut to_spread = n as f64 * (per_pixel - floor) as f64;
    // Water-filling: cap the pixels whose share would pass the cap, and
    // share what is left among the others, until none passes it.
    let mut capped = vec![false; n];
    // The uncapped pixels' sum of sigma, kept from the last round.
    let free = loop {
        let free: f64 = sigma.iter().zip(&capped).filter(|&(_, &c)| !c).map(|(&s, _)| s).sum();
        if free <= 0.0 {
            break free;
        }
        let scale = to_spread / free;
        let mut newly = 0;
        for (c, &s) in capped.iter_mut().zip(sigma) {
            if !*c && s * scale > headroom {
                *c = true;
                newly += 1;
            }
        }
        if newly == 0 {
            break free;
        }
        to_spread -= newly as f64 * headroom;
    };
    let uncapped = capped.iter().filter(|&&c| !c).count() as f64;
    sigma
        .iter()
        .zip(&capped)
        .enumerate()
        .map(|(i, (&s, &c))| {
            let share = if c {
                headroom
            } else if free > 0.0 {
                to_spread * s / free
            } else {
                to_spread / uncapped
            };
            // 53 random bits: uniform in [0, 1).
            let u = (mix64(key ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)) >> 11) as f64 / (1u64 << 53) as f64;
            floor + (share + u).floor().min(headroom) as u32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_follow_the_noise() {
        // Four pixels: silent, quiet, twice as noisy, noisier still.
        let sigma = [0.0, 1.0, 2.0, 5.0];
        let counts = allocate(&sigma, 100, 1);
        // A quarter of the budget evenly (25 each), the other 300 in
        // proportion to sigma (1 : 2 : 5 of 8): 0, 37.5, 75 and 187.5,
        // the halves rounded either way.
        assert_eq!(counts[0], 25);
        assert!((62..=63).contains(&counts[1]), "{counts:?}");
        assert_eq!(counts[2], 100);
        assert!((212..=213).contains(&counts[3]), "{counts:?}");
    }

    #[test]
    fn rounding_keeps_the_budget_on_average() {
        // Shares of 16/3 and 32/3 beside a floor of 2: rounding down alone
        // would give 7 and 12, 0.5 a pixel short.
        let sigma: Vec<f64> = (0..20_000).map(|i| if i % 2 == 0 { 1.0 } else { 2.0 }).collect();
        let counts = allocate(&sigma, 10, 7);
        let mean_of = |parity| {
            let picked: Vec<f64> = counts.iter().skip(parity).step_by(2).map(|&c| c as f64).collect();
            picked.iter().sum::<f64>() / picked.len() as f64
        };
        // Each count's rounding has a variance of 2/9 sample²: the mean of
        // 10 000 lies within 0.005 (one standard error) of the share.
        assert!((mean_of(0) - (2.0 + 16.0 / 3.0)).abs() < 0.03, "{}", mean_of(0));
        assert!((mean_of(1) - (2.0 + 32.0 / 3.0)).abs() < 0.03, "{}", mean_of(1));
        let total: u32 = counts.iter().sum();
        assert!(total.abs_diff(200_000) < 300, "{total}");
        // The same key gives the same counts; another key other roundings.
        assert_eq!(counts, allocate(&sigma, 10, 7));
        assert_ne!(counts, allocate(&sigma, 10, 8));
    }

    #[test]
    fn a_firefly_is_capped_and_the_rest_shared() {
        // One pixel a million times noisier than 99 others.
        let mut sigma = vec![1.0; 100];
        sigma[7] = 1e6;
        let counts = allocate(&sigma, 64, 1);
        assert_eq!(counts[7], CAP * 64);
        // The others share what is left evenly: (6400 − 8·64) / 99 each.
        for (i, &c) in counts.iter().enumerate() {
            if i != 7 {
                assert!((59..=60).contains(&c), "pixel {i}: {c}");
            }
        }
    }

    #[test]
    fn silence_everywhere_gives_even_counts() {
        assert_eq!(allocate(&[0.0; 5], 12, 1), vec![12; 5]);
        // An unmeasurable pixel (its pilot broke) counts as the noisiest.
        let counts = allocate(&[1.0, UNMEASURED, 1.0, UNMEASURED], 40, 1);
        assert!(counts[1] > counts[0] && counts[0] == counts[2] && counts[1] == counts[3], "{counts:?}");
    }

    #[test]
    fn neighbours_max_spreads_a_peak_around_it_and_leaves_it_out() {
        let mut v = vec![0.0; 5 * 4];
        v[6] = 2.0; // (1, 1)
        v[19] = 1.0; // (4, 3), a corner
        let m = neighbours_max(&v, 5, 4);
        for y in 0..4 {
            for x in 0..5 {
                let want = if (x, y) == (1, 1) {
                    // Its own value left out, its neighbours are 0.
                    0.0
                } else if x <= 2 && y <= 2 {
                    2.0
                } else if x >= 3 && y >= 2 && (x, y) != (4, 3) {
                    1.0
                } else {
                    0.0
                };
                assert_eq!(m[y * 5 + x], want, "({x}, {y})");
            }
        }
        assert_eq!(neighbours_max(&[3.0], 1, 1), vec![0.0]);
    }
}
