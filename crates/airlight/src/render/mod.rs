//! Rendering an image: tiles over threads (rayon), each sample with its own
//! random stream, every sample added into exact per-pixel sums (a tile's
//! own `PixelTotal`s while it renders, or an [`Accumulator`]'s
//! [`PixelSum`]s),
//! so the image is the same, bit for bit, whatever the thread count and
//! however the samples were grouped (one render, progressive passes,
//! shards).

use crate::film::{Accumulator, Image, PixelSum, PixelTotal};
use crate::integrator::{Integrator, IntegratorError};
use crate::scene::Scene;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

pub mod adaptive;
pub mod aov;
mod job;
mod run;
mod samples;

pub use job::{MAX_THREADS, RenderJob, RenderMode, RenderRequest};
pub use run::{PassesEnd, Rendered};
use samples::tile_sums;
pub use samples::{BLOCK, BLOCK_ORDER, PixelSample, pixel_sum};

const TILE: u32 = 16;

/// Hooks a caller may give a render: progress reports and a stop flag.
#[derive(Default, Clone, Copy)]
pub struct RenderObserver<'a> {
    /// Called with the number of pixel samples just finished (from any
    /// thread).
    pub progress: Option<&'a (dyn Fn(u64) + Sync)>,
    /// When set, tiles not yet started are skipped: their pixels get no
    /// samples.
    pub cancel: Option<&'a AtomicBool>,
}

impl RenderObserver<'_> {
    pub fn none() -> Self {
        RenderObserver::default()
    }

    fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

/// Renders the scene's `spp` samples of every pixel with `integrator`: each
/// pixel the mean of its samples (box filtered, unless the scene asks for
/// point sampling). With `adaptive` set in the scene's settings, the same
/// number of samples in all, spread over the pixels by their noise
/// ([`adaptive`]).
pub fn render(scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> Image {
    if scene.settings().adaptive {
        return adaptive::render_adaptive(scene, integrator, observer);
    }
    render_samples(scene, integrator, 0, scene.settings().spp, observer)
}

/// Renders samples `first .. first + count` of every pixel (sample numbers
/// count across passes): each pixel the mean of those samples, bit for bit
/// [`accumulate`]'s image.
///
/// Each tile's sums live only while the tile renders, in a buffer of the
/// tile's size, and leave as the tile's means. They are `PixelTotal`s,
/// without the sums of squares that only a variance needs (on a large
/// mesh at 8 samples a pixel the image took 0.91× the time so). The
/// image-sized accumulator (112 bytes a pixel, against the image's 12) is
/// never made: at 1024² and one sample per pixel, faulting in its fresh
/// pages and reading it back made the image take 1.33× the time; at
/// 3840×2160 it was 929 MB of the 1020 MB the render held.
pub fn render_samples(
    scene: &Scene,
    integrator: &dyn Integrator,
    first: u64,
    count: u32,
    observer: &RenderObserver,
) -> Image {
    let samples = first..first + count as u64;
    render_pixel_samples(scene, integrator, scene.settings().seed, |_, _| samples.clone(), observer)
}

/// Renders samples `samples_of(x, y)` of each pixel (x, y), drawn with
/// `seed`: each pixel the mean of its samples (black if it has none).
/// [`render_samples`] gives every pixel the same range; adaptive sampling
/// gives each its own count.
pub(crate) fn render_pixel_samples(
    scene: &Scene,
    integrator: &dyn Integrator,
    seed: u64,
    samples_of: impl Fn(u32, u32) -> Range<u64> + Sync,
    observer: &RenderObserver,
) -> Image {
    let s = scene.settings();
    let mut image = Image::new(s.film.width, s.film.height);
    for_each_tile(&mut image.pixels, s.film.width, 0, observer, |origin, means| {
        let tile_width = means.first().map_or(0, |row| row.len());
        let mut sums = vec![PixelTotal::default(); tile_width * means.len()];
        let mut sum_rows: TileRows<PixelTotal> = sums.chunks_mut(tile_width.max(1)).collect();
        let done = tile_sums(scene, integrator, origin, &mut sum_rows, seed, &samples_of);
        for (row, sums) in means.iter_mut().zip(&sum_rows) {
            for (mean, sum) in row.iter_mut().zip(sums.iter()) {
                *mean = sum.mean();
            }
        }
        done
    });
    image
}

/// Adds samples `samples` of every pixel in the rows `rows` (pixel and
/// sample numbers those of the full image) into a new accumulator that
/// holds those rows.
pub fn accumulate(
    scene: &Scene,
    integrator: &dyn Integrator,
    samples: Range<u64>,
    rows: Range<u32>,
    observer: &RenderObserver,
) -> Accumulator {
    let mut acc = Accumulator::band(scene.settings().film.width, scene.settings().film.height, rows);
    accumulate_into(scene, integrator, samples, &mut acc, observer);
    acc
}

/// Adds samples `samples` of every pixel that `acc` holds into it, as
/// [`accumulate`] would into a new one and a merge after (the sums are
/// exact, so the bits are the same). A cancelled render leaves some of the
/// pixels with the samples and the others without. Panics if `acc` is not
/// of the scene's image size.
pub fn accumulate_into(
    scene: &Scene,
    integrator: &dyn Integrator,
    samples: Range<u64>,
    acc: &mut Accumulator,
    observer: &RenderObserver,
) {
    let (width, height) = acc.size();
    assert_eq!(
        (width, height),
        (scene.settings().film.width, scene.settings().film.height),
        "an accumulator of the scene's image"
    );
    accumulate_pixel_samples(scene, integrator, scene.settings().seed, |_, _| samples.clone(), acc, observer);
}

/// Adds samples `samples_of(x, y)` of each pixel (x, y) that `acc` holds,
/// drawn with `seed`, into it (see [`accumulate_into`]).
pub(crate) fn accumulate_pixel_samples(
    scene: &Scene,
    integrator: &dyn Integrator,
    seed: u64,
    samples_of: impl Fn(u32, u32) -> Range<u64> + Sync,
    acc: &mut Accumulator,
    observer: &RenderObserver,
) {
    let (width, first_row) = (acc.size().0, acc.rows().start);
    // Each tile gets its rows of the accumulator's pixels (disjoint slices)
    // and adds its samples there: no copy, no second image-sized buffer.
    for_each_tile(acc.pixels_mut(), width, first_row, observer, |origin, tile| {
        tile_sums(scene, integrator, origin, tile, seed, &samples_of)
    });
}

/// Runs `work(origin, rows)` on every tile of `pixels` ([`tiles`]) over the
/// threads, each tile once; tiles not started when the observer's cancel
/// flag is set are skipped. Each finished tile is reported to the observer
/// with the number of samples its `work` returns.
fn for_each_tile<T: Send>(
    pixels: &mut [T],
    width: u32,
    first_row: u32,
    observer: &RenderObserver,
    work: impl Fn((u32, u32), &mut TileRows<T>) -> u64 + Sync,
) {
    // Each tile its own piece of work to steal (`with_max_len(1)`): rayon
    // otherwise hands a thread runs of tiles that it works through alone,
    // and where tiles' costs differ (adaptive sampling's counts) one thread
    // ended with a run of costly tiles while the other waited.
    tiles(pixels, width, first_row).into_par_iter().with_max_len(1).for_each(|(origin, mut tile)| {
        if observer.cancelled() {
            return;
        }
        let samples = work(origin, &mut tile);
        if let Some(progress) = observer.progress {
            progress(samples);
        }
    });
}

/// Cuts a band of rows of pixels, `width` to a row and the first one the
/// image's row `first_row`, into [`TILE`]×[`TILE`] tiles (smaller at the
/// right and bottom edges): each its top-left pixel in the image and its
/// rows, disjoint slices of `pixels`.
fn tiles<T>(pixels: &mut [T], width: u32, first_row: u32) -> Vec<((u32, u32), TileRows<'_, T>)> {
    let mut tiles = Vec::new();
    // (`max(1)`: an image 0 pixels wide has no pixels and no tiles.)
    for (ty, band) in pixels.chunks_mut((TILE * width).max(1) as usize).enumerate() {
        let mut band_tiles: Vec<TileRows<T>> = (0..width.div_ceil(TILE)).map(|_| Vec::new()).collect();
        for row in band.chunks_mut(width.max(1) as usize) {
            for (tile, part) in band_tiles.iter_mut().zip(row.chunks_mut(TILE as usize)) {
                tile.push(part);
            }
        }
        let origin = |tx: usize| (tx as u32 * TILE, first_row + ty as u32 * TILE);
        tiles.extend(band_tiles.into_iter().enumerate().map(|(tx, tile)| (origin(tx), tile)));
    }
    tiles
}

/// A tile's rows of pixels (by default its pixel sums), top row first.
type TileRows<'a, T = PixelSum> = Vec<&'a mut [T]>;

/// Moves `scene` to `time` in [0, 1] of its light animation and tells
/// `integrator`: the one step every command takes between frames (radiosity
/// relights instead of recompiling).
pub fn set_time(scene: &mut Scene, integrator: &mut dyn Integrator, time: f32) -> Result<(), IntegratorError> {
    scene.at_time(time);
    integrator.lights_changed(scene)
}

/// The time in [0, 1] of frame `frame` of `frames`: k/(N − 1), so the first
/// and last frames show the animation's ends.
pub fn frame_time(frame: u32, frames: u32) -> f32 {
    if frames > 1 { frame as f32 / (frames - 1) as f32 } else { 0.0 }
}

/// Progressive rendering: the scene's `spp` samples in passes of 1, 1, 2,
/// 4, 8, ... samples per pixel (the last one cut to what is left), each
/// added to the accumulator, so that after every pass the image is the mean
/// of all samples so far. Pass sizes double so that the pixel's stratified
/// sequence is always cut at a power of two, where it is best spread, and
/// the number of passes (and rewrites of the image) grows only as log₂ spp.
/// The finished image is bit for bit the one [`render`] gives (the
/// accumulator's sums do not depend on grouping).
pub struct Progressive {
    spp: u32,
    done: u32,
    accumulator: Accumulator,
}

impl Progressive {
    pub fn new(scene: &Scene) -> Self {
        let s = scene.settings();
        Progressive { spp: s.spp, done: 0, accumulator: Accumulator::new(s.film.width, s.film.height) }
    }

    /// Continues from an accumulator that holds the first `done` samples of
    /// every pixel of the scene's image.
    pub fn resume(scene: &Scene, accumulator: Accumulator, done: u32) -> Self {
        Progressive { spp: scene.settings().spp, done, accumulator }
    }

    /// Samples per pixel rendered so far.
    pub fn samples(&self) -> u32 {
        self.done
    }

    /// Whether all of the scene's samples are in.
    pub fn finished(&self) -> bool {
        self.done >= self.spp
    }

    /// How many samples the next pass renders (0 when finished).
    pub fn next_pass_size(&self) -> u32 {
        self.done.max(1).min(self.spp.saturating_sub(self.done))
    }

    /// Renders the next pass and adds it in. Returns false, adding nothing,
    /// when the observer's cancel flag stopped the pass part way, when
    /// everything is already done, or when the accumulator it resumed from
    /// is not the whole of the scene's image.
    pub fn pass(&mut self, scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> bool {
        let count = self.next_pass_size();
        if count == 0 {
            return false;
        }
        let s = scene.settings();
        if self.accumulator.size() != (s.film.width, s.film.height) || self.accumulator.rows() != (0..s.film.height) {
            return false;
        }
        let first = self.done as u64;
        let samples = first..first + count as u64;
        if observer.cancel.is_none() {
            // Nothing can stop the pass part way: straight into the sums,
            // without a second accumulator to fault in and merge.
            accumulate_into(scene, integrator, samples, &mut self.accumulator, observer);
        } else {
            let pass = accumulate(scene, integrator, samples, 0..s.film.height, observer);
            if observer.cancelled() || self.accumulator.merge(&pass).is_err() {
                return false;
            }
        }
        self.done += count;
        true
    }

    /// The samples so far.
    pub fn accumulator(&self) -> &Accumulator {
        &self.accumulator
    }

    /// The mean of the samples so far (black before the first pass).
    pub fn image(&self) -> Image {
        self.accumulator.image()
    }

    /// The estimated variance of each pixel's mean, per channel (infinite
    /// before two samples).
    pub fn variance(&self) -> Image {
        self.accumulator.variance()
    }

    /// The estimated relative error of the image (see
    /// [`Accumulator::estimated_relative_error`]).
    pub fn estimated_relative_error(&self) -> f64 {
        self.accumulator.estimated_relative_error()
    }
}
