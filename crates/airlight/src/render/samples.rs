//! A tile's samples: each drawn from its own random stream, its camera ray
//! made, and traced with the others of its block of pixels in one batch
//! (so that the integrator can trace their rays as packets), then added
//! into its pixel's sums.

use crate::Rgb;
use crate::film::PixelFilter;
use crate::film::{AddSample, PixelSum};
use crate::integrator::Integrator;
use crate::sampling::Sampler;
use crate::scene::{RenderSettings, Scene};
use glam::Vec2;
use std::ops::Range;

/// Side of the square blocks of pixels whose samples are traced together
/// (see [`Integrator::radiance_batch`]).
pub const BLOCK: u32 = 8;

/// The pixels of a [`BLOCK`]×[`BLOCK`] block in Z order (Morton order: x
/// and y bits interleaved), so that every 4 consecutive pixels form a 2×2
/// square and every 16 a 4×4 one: the order in which packets of camera
/// rays share the most work (`Geometry::intersect_packet`).
pub const BLOCK_ORDER: [(u32, u32); (BLOCK * BLOCK) as usize] = {
    let mut order = [(0, 0); (BLOCK * BLOCK) as usize];
    let mut i = 0;
    while i < order.len() {
        let i32_ = i as u32;
        let x = (i32_ & 1) | ((i32_ >> 1) & 2) | ((i32_ >> 2) & 4);
        let y = ((i32_ >> 1) & 1) | ((i32_ >> 2) & 2) | ((i32_ >> 3) & 4);
        order[i] = (x, y);
        i += 1;
    }
    order
};

/// Adds the samples `samples_of(x, y)` of each pixel (x, y) of the tile
/// whose top-left pixel is (x0, y0), drawn with `seed`, into `tile`, its
/// rows of pixel sums; returns how many samples that was. The samples of
/// each [`BLOCK`]×[`BLOCK`] block of pixels go to the integrator together,
/// [`BLOCK_ORDER`]'s count times [`Integrator::batch_blocks`] at a time:
/// sample number by sample number, each number with the pixels in
/// [`BLOCK_ORDER`] whose range holds it. (Where the pixels' counts differ,
/// as under adaptive sampling, a batch so takes the next numbers of the
/// pixels that still have samples, rather than shrinking to them: a
/// pixel's own rays are the most alike.) After each block, the batch is
/// traced if one more sample of a whole block would not fit in it. Each
/// pixel's sum is [`pixel_sum`]'s, bit for bit: the same samples, and the
/// sums are exact, so the order they are added in does not matter.
pub(super) fn tile_sums(
    scene: &Scene,
    integrator: &dyn Integrator,
    (x0, y0): (u32, u32),
    tile: &mut [&mut [impl AddSample]],
    seed: u64,
    samples_of: impl Fn(u32, u32) -> Range<u64>,
) -> u64 {
    let s = scene.settings();
    let (x1, y1) = (x0 + tile.first().map_or(0, |row| row.len() as u32), y0 + tile.len() as u32);
    let film = scene.camera().rays(s.film.width, s.film.height);
    let n = BLOCK_ORDER.len() * integrator.batch_blocks().max(1);
    let mut block = Vec::with_capacity(n);
    let mut batch = Batch::with_capacity(n);
    let mut rays = Vec::with_capacity(n);
    let mut radiance = vec![Rgb::ZERO; n];
    let mut done = 0;
    // The batch's camera rays made together (`CameraRays::rays_into`), traced, added to the tile.
    let mut trace = |batch: &mut Batch| {
        rays.clear();
        film.rays_into(&batch.films, &batch.lenses, &mut rays);
        let radiance = &mut radiance[..batch.pixels.len()];
        integrator.radiance_batch(scene, &rays, &mut batch.samplers, radiance);
        for (&(x, y), r) in batch.pixels.iter().zip(radiance.iter()) {
            tile[(y - y0) as usize][(x - x0) as usize].add(*r);
        }
        done += batch.pixels.len() as u64;
        batch.clear();
    };
    for by in (y0..y1).step_by(BLOCK as usize) {
        for bx in (x0..x1).step_by(BLOCK as usize) {
            block.clear();
            block.extend(
                BLOCK_ORDER
                    .iter()
                    .map(|&(dx, dy)| (bx + dx, by + dy))
                    .filter(|&(x, y)| x < x1 && y < y1)
                    .map(|(x, y)| (x, y, samples_of(x, y))),
            );
            let first = block.iter().map(|(.., r)| r.start).min().unwrap_or(0);
            let end = block.iter().map(|(.., r)| r.end).max().unwrap_or(0);
            for i in first..end {
                for (x, y, _) in block.iter().filter(|(.., r)| r.contains(&i)) {
                    let sample = PixelSample::new(s, seed, integrator.stratified(), *x, *y, i);
                    batch.films.push(sample.film);
                    batch.lenses.push(sample.lens);
                    batch.samplers.push(sample.sampler);
                    batch.pixels.push((*x, *y));
                    if batch.pixels.len() == n {
                        trace(&mut batch);
                    }
                }
            }
            // Traced now if one more block's sample would not fit.
            if batch.pixels.len() + BLOCK_ORDER.len() > n {
                trace(&mut batch);
            }
        }
    }
    if !batch.pixels.is_empty() {
        trace(&mut batch);
    }
    done
}

/// Samples waiting to be traced together: each one's pixel, film and lens
/// points (its camera ray, made when the batch is traced) and sampler.
struct Batch {
    pixels: Vec<(u32, u32)>,
    films: Vec<Vec2>,
    lenses: Vec<Vec2>,
    samplers: Vec<Sampler>,
}

impl Batch {
    fn with_capacity(n: usize) -> Self {
        Batch {
            pixels: Vec::with_capacity(n),
            films: Vec::with_capacity(n),
            lenses: Vec::with_capacity(n),
            samplers: Vec::with_capacity(n),
        }
    }

    fn clear(&mut self) {
        self.pixels.clear();
        self.films.clear();
        self.lenses.clear();
        self.samplers.clear();
    }
}

/// The samples `samples` of pixel (x, y), summed.
///
/// Each sample draws from its own stream, keyed by (seed, pixel, sample
/// number), so it is the same whichever machine, thread or pass renders it,
/// and its camera ray is the same whatever the integrator draws after it:
/// images of one scene by two integrators share their anti-aliasing and
/// lens samples, and differ only by what the integrators compute.
pub fn pixel_sum(scene: &Scene, integrator: &dyn Integrator, x: u32, y: u32, samples: Range<u64>) -> PixelSum {
    let s = scene.settings();
    let mut sum = PixelSum::default();
    for i in samples {
        let mut sample = PixelSample::new(s, s.seed, integrator.stratified(), x, y, i);
        let ray = sample.ray(scene);
        sum.add(integrator.radiance(scene, &ray, &mut sample.sampler));
    }
    sum
}

/// Sample `i` of pixel (x, y): its random stream, keyed by (seed, pixel,
/// sample number), and the film and lens points of its camera ray, drawn
/// from that stream first (from the pixel's stratified sequence when
/// `stratified`, see [`Integrator::stratified`]). The one place a pixel
/// sample is made: tiles, AOVs and the viewer's preview all draw theirs
/// here, so that they trace the same rays with the same numbers.
pub struct PixelSample {
    /// The stream the integrator goes on drawing from.
    pub sampler: Sampler,
    /// The point on the film, in pixels from the image's top-left corner.
    pub film: Vec2,
    /// The point on the lens, in [0, 1)².
    pub lens: Vec2,
}

impl PixelSample {
    pub fn new(settings: &RenderSettings, seed: u64, stratified: bool, x: u32, y: u32, i: u64) -> PixelSample {
        let mut sampler = Sampler::for_pixel(seed, y as u64 * settings.film.width as u64 + x as u64, i);
        let (jitter, lens) = if stratified {
            let u = sampler.stratified4(0);
            (Vec2::new(u[0], u[1]), Vec2::new(u[2], u[3]))
        } else {
            (sampler.next2(), sampler.next2())
        };
        let film = Vec2::new(x as f32, y as f32)
            + match settings.film.filter {
                PixelFilter::Box => jitter,
                PixelFilter::Point => Vec2::splat(0.5),
            };
        PixelSample { sampler, film, lens }
    }

    /// The sample's camera ray in `scene`.
    pub fn ray(&self, scene: &Scene) -> crate::geometry::Ray {
        let s = scene.settings();
        scene.camera().rays(s.film.width, s.film.height).ray(self.film, self.lens)
    }
}
