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
//! of `spp` samples a pixel:
//! 1. A pilot of [`pilot_samples`] a pixel, drawn with a seed of its own,
//!    estimates each pixel's σ; each estimate is raised to the largest in
//!    its 3×3 neighbourhood, so that a pixel whose pilot happened to miss
//!    an edge that its neighbours saw is not starved.
//! 2. The rest of the budget, a quarter spread evenly (a floor that keeps
//!    every pixel converging whatever the pilot saw) and three quarters in
//!    proportion to σ, each pixel at most [`CAP`] times the rest's mean.
//!    Each pixel then takes its count of samples from the render's own
//!    seed, samples 0, 1, 2, … as a uniform render would.
//!
//! The image is the mean of stage 2 alone. A pixel's count depends only on
//! the pilot, whose numbers are independent of stage 2's (another seed), so
//! each pixel's mean is an unbiased estimate whatever its count; averaging
//! the pilot in too would not be (a pilot that saw a bright sample asks for
//! more samples, which then dilute it). The pilot costs its share of the
//! budget (a sixteenth, or 2 samples a pixel below 32) without entering
//! the image.

use super::{RenderObserver, accumulate_pixel_samples, render_pixel_samples};
use crate::film::{Accumulator, Image};
use crate::integrator::Integrator;
use crate::sampling::mix64;
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

/// The pilot's seed, derived from the render's: its numbers independent of
/// stage 2's.
fn pilot_seed(seed: u64) -> u64 {
    mix64(seed ^ 0x7069_6c6f_745f_7365)
}

/// Renders the scene with its `spp` samples a pixel on average, spread by
/// the pixels' noise (module notes). Below [`MIN_SPP`] a uniform render.
pub fn render_adaptive(scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> Image {
    let s = scene.settings();
    if s.spp < MIN_SPP {
        return super::render_samples(scene, integrator, 0, s.spp, observer);
    }
    let counts = plan(scene, integrator, observer);
    let width = s.width as usize;
    render_pixel_samples(scene, integrator, s.seed, |x, y| 0..counts[y as usize * width + x as usize] as u64, observer)
}

/// Stage 1: the pilot, and from it each pixel's count of samples in stage
/// 2 (row by row).
pub fn plan(scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> Vec<u32> {
    let s = scene.settings();
    let pilot = pilot_samples(s.spp);
    let mut sums = Accumulator::new(s.width, s.height);
    accumulate_pixel_samples(scene, integrator, pilot_seed(s.seed), |_, _| 0..pilot as u64, &mut sums, observer);
    let sigma: Vec<f64> = sums
        .pixels()
        .iter()
        .map(|p| {
            // The standard deviation of one sample, over the channels.
            let per_sample = p.variance_of_mean().element_sum() / 3.0 * p.count as f64;
            if per_sample.is_finite() { per_sample.sqrt() } else { UNMEASURED }
        })
        .collect();
    let sigma = neighbourhood_max(&sigma, s.width as usize, s.height as usize);
    allocate(&sigma, s.spp - pilot)
}

/// Each value raised to the largest in its 3×3 neighbourhood (within the
/// image) of a `width`×`height` grid stored row by row.
pub fn neighbourhood_max(values: &[f64], width: usize, height: usize) -> Vec<f64> {
    let at = |x: usize, y: usize| values[y * width + x];
    let mut out = Vec::with_capacity(values.len());
    for y in 0..height {
        for x in 0..width {
            let mut m = f64::MIN;
            for yy in y.saturating_sub(1)..(y + 2).min(height) {
                for xx in x.saturating_sub(1)..(x + 2).min(width) {
                    m = m.max(at(xx, yy));
                }
            }
            out.push(m);
        }
    }
    out
}

/// Sample counts for pixels of noise `sigma` (standard deviations, ≥ 0)
/// that sum to exactly `per_pixel` times their number: a quarter of that
/// evenly (at least 1 each), the rest in proportion to sigma, no count
/// above [`CAP`] × `per_pixel` (what a capped pixel cannot take goes to the
/// others, in proportion again). Where every sigma is 0, even counts.
pub fn allocate(sigma: &[f64], per_pixel: u32) -> Vec<u32> {
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
    // Whole samples by rounding the running total, so that the counts sum
    // to the budget exactly.
    let mut running = 0.0f64;
    let mut given = 0u64;
    sigma
        .iter()
        .zip(&capped)
        .map(|(&s, &c)| {
            let share = if c {
                headroom
            } else if free > 0.0 {
                to_spread * s / free
            } else {
                to_spread / uncapped
            };
            running += share;
            let total = running.round() as u64;
            let extra = total - given;
            given = total;
            floor + extra as u32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_follow_the_noise_and_keep_the_budget() {
        // Four pixels: silent, quiet, twice as noisy, noisier still.
        let sigma = [0.0, 1.0, 2.0, 5.0];
        let counts = allocate(&sigma, 100);
        assert_eq!(counts.iter().sum::<u32>(), 400);
        // A quarter of the budget evenly (25 each), the other 300 in
        // proportion to sigma (1 : 2 : 5 of 8).
        assert_eq!(counts, vec![25, 25 + 38, 25 + 75, 25 + 187]);
    }

    #[test]
    fn a_firefly_is_capped_and_the_rest_shared() {
        // One pixel a million times noisier than 99 others.
        let mut sigma = vec![1.0; 100];
        sigma[7] = 1e6;
        let counts = allocate(&sigma, 64);
        assert_eq!(counts.iter().sum::<u32>(), 6400);
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
        assert_eq!(allocate(&[0.0; 5], 12), vec![12; 5]);
        // An unmeasurable pixel (its pilot broke) counts as the noisiest.
        let counts = allocate(&[1.0, UNMEASURED, 1.0, UNMEASURED], 40);
        assert_eq!(counts.iter().sum::<u32>(), 160);
        assert!(counts[1] > counts[0] && counts[0] == counts[2] && counts[1] == counts[3], "{counts:?}");
    }

    #[test]
    fn neighbourhood_max_spreads_a_peak_over_its_3x3() {
        let mut v = vec![0.0; 5 * 4];
        v[6] = 2.0; // (1, 1)
        v[19] = 1.0; // (4, 3), a corner
        let m = neighbourhood_max(&v, 5, 4);
        for y in 0..4 {
            for x in 0..5 {
                let want = if x <= 2 && y <= 2 {
                    2.0
                } else if x >= 3 && y >= 2 {
                    1.0
                } else {
                    0.0
                };
                assert_eq!(m[y * 5 + x], want, "({x}, {y})");
            }
        }
    }
}
