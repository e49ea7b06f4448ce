//! Rendering an image: tiles over threads (rayon), each pixel with its own
//! random stream, so the image is the same whatever the thread count.

use crate::Rgb;
use crate::film::Image;
use crate::integrator::{self, Integrator};
use crate::sampling::Sampler;
use crate::scene::{PixelFilter, Scene};
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

const TILE: u32 = 16;

/// Hooks a caller may give a render: progress reports and a stop flag.
#[derive(Default, Clone, Copy)]
pub struct RenderObserver<'a> {
    /// Called with the number of pixels just finished (from any thread).
    pub progress: Option<&'a (dyn Fn(u64) + Sync)>,
    /// When set, tiles not yet started are skipped and stay black.
    pub cancel: Option<&'a AtomicBool>,
}

impl RenderObserver<'_> {
    pub fn none() -> Self {
        RenderObserver::default()
    }
}

/// Renders `scene` with its settings. Fails only when the scene names an
/// integrator that cannot render it.
pub fn try_render(scene: &Scene, observer: &RenderObserver) -> Result<Image, String> {
    let integrator = integrator::for_scene(scene)?;
    Ok(render_with(scene, integrator.as_ref(), observer))
}

/// Renders `scene`; panics if its integrator is not available (see
/// [`try_render`] for the fallible form).
pub fn render(scene: &Scene, observer: &RenderObserver) -> Image {
    try_render(scene, observer).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `scene` with a given integrator: `spp` jittered samples per pixel,
/// box filtered.
pub fn render_with(scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> Image {
    render_samples(scene, integrator, 0, scene.settings.spp, observer)
}

/// Renders samples `first .. first + count` of every pixel (sample numbers
/// count across passes): each pixel is the mean of those samples.
pub fn render_samples(
    scene: &Scene,
    integrator: &dyn Integrator,
    first: u64,
    count: u32,
    observer: &RenderObserver,
) -> Image {
    render_moments(scene, integrator, first, count, observer).0
}

/// Like [`render_samples`], with a second image of each pixel's mean of
/// squared samples (per channel), from which [`Progressive`] estimates the
/// variance of its pixels.
pub fn render_moments(
    scene: &Scene,
    integrator: &dyn Integrator,
    first: u64,
    count: u32,
    observer: &RenderObserver,
) -> (Image, Image) {
    let s = &scene.settings;
    let (w, h) = (s.width, s.height);
    let tiles_x = w.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE)).flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty))).collect();
    let rendered: Vec<Vec<Moments>> = tiles
        .par_iter()
        .map(|&(tx, ty)| {
            let (x0, y0) = (tx * TILE, ty * TILE);
            let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
            let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            if observer.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                out.resize(((x1 - x0) * (y1 - y0)) as usize, Moments::default());
                return out;
            }
            for y in y0..y1 {
                for x in x0..x1 {
                    out.push(pixel_moments(scene, integrator, x, y, first, count));
                }
            }
            if let Some(progress) = observer.progress {
                progress(out.len() as u64);
            }
            out
        })
        .collect();
    let (mut mean, mut mean_square) = (Image::new(w, h), Image::new(w, h));
    for (&(tx, ty), tile) in tiles.iter().zip(&rendered) {
        let (x0, y0) = (tx * TILE, ty * TILE);
        let tile_w = (x0 + TILE).min(w) - x0;
        for (i, m) in tile.iter().enumerate() {
            let (x, y) = (x0 + i as u32 % tile_w, y0 + i as u32 / tile_w);
            mean.pixels[(y * w + x) as usize] = m.mean;
            mean_square.pixels[(y * w + x) as usize] = m.mean_square;
        }
    }
    (mean, mean_square)
}

/// The first two moments of a pixel's samples.
#[derive(Clone, Copy, Default)]
struct Moments {
    mean: Rgb,
    mean_square: Rgb,
}

/// The mean of `spp` samples of one pixel in pass `pass`.
///
/// Each sample draws from its own stream, keyed by (seed, pixel, sample
/// number), so its camera ray is the same whatever the integrator draws
/// after it: images of one scene by two integrators share their
/// anti-aliasing and lens samples, and differ only by what the integrators
/// compute.
pub fn render_pixel(scene: &Scene, integrator: &dyn Integrator, x: u32, y: u32, pass: u64) -> Rgb {
    let spp = scene.settings.spp;
    pixel_samples(scene, integrator, x, y, pass * spp as u64, spp)
}

/// The mean of samples `first .. first + count` of one pixel.
pub fn pixel_samples(scene: &Scene, integrator: &dyn Integrator, x: u32, y: u32, first: u64, count: u32) -> Rgb {
    pixel_moments(scene, integrator, x, y, first, count).mean
}

/// The mean and mean square of samples `first .. first + count` of one pixel.
fn pixel_moments(scene: &Scene, integrator: &dyn Integrator, x: u32, y: u32, first: u64, count: u32) -> Moments {
    let s = &scene.settings;
    let index = y as u64 * s.width as u64 + x as u64;
    let (mut sum, mut sum_square) = (Rgb::ZERO, Rgb::ZERO);
    for i in 0..count as u64 {
        let mut sampler = Sampler::for_pixel(s.seed, index, first + i);
        let (jitter, lens) = if integrator.stratified() {
            let u = sampler.stratified4(0);
            (Vec2::new(u[0], u[1]), Vec2::new(u[2], u[3]))
        } else {
            (sampler.next2(), sampler.next2())
        };
        let film = Vec2::new(x as f32, y as f32)
            + match s.filter {
                PixelFilter::Box => jitter,
                PixelFilter::Point => Vec2::splat(0.5),
            };
        let ray = scene.camera.ray(film, s.width, s.height, lens);
        let l = integrator.radiance(scene, &ray, &mut sampler);
        // One broken sample (NaN, inf) must not spoil the pixel.
        if l.is_finite() {
            sum += l;
            sum_square += l * l;
        }
    }
    let n = count.max(1) as f32;
    Moments { mean: sum / n, mean_square: sum_square / n }
}

/// Progressive rendering: the scene's `spp` samples in passes of 1, 1, 2,
/// 4, 8, ... samples per pixel (the last one cut to what is left), each
/// added to a running sum, so that after every pass the image is the mean of
/// all samples so far. Pass sizes double so that the pixel's stratified
/// sequence is always cut at a power of two, where it is best spread, and
/// the number of passes (and rewrites of the image) grows only as log₂ spp.
/// The result is a pure function of the scene, as for [`render`], but not
/// bit for bit the same image: sums are grouped differently.
///
/// It also keeps each pixel's sum of squared samples, for the variance of
/// its mean, s²/n with s² the unbiased sample variance: exact for
/// independent samples, an upper bound in expectation for stratified ones
/// (stratification only lowers the variance of the mean).
pub struct Progressive {
    width: u32,
    height: u32,
    spp: u32,
    done: u32,
    sum: Vec<glam::DVec3>,
    sum_square: Vec<glam::DVec3>,
}

impl Progressive {
    pub fn new(scene: &Scene) -> Self {
        let s = &scene.settings;
        let pixels = s.width as usize * s.height as usize;
        Progressive {
            width: s.width,
            height: s.height,
            spp: s.spp,
            done: 0,
            sum: vec![glam::DVec3::ZERO; pixels],
            sum_square: vec![glam::DVec3::ZERO; pixels],
        }
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
        self.done.max(1).min(self.spp - self.done)
    }

    /// Renders the next pass and adds it in. Returns false, adding nothing,
    /// when the observer's cancel flag stopped the pass part way (or when
    /// everything is already done).
    pub fn pass(&mut self, scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> bool {
        let count = self.next_pass_size();
        if count == 0 {
            return false;
        }
        let (mean, mean_square) = render_moments(scene, integrator, self.done as u64, count, observer);
        if observer.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return false;
        }
        let n = count as f64;
        for ((acc, acc_square), (p, q)) in
            self.sum.iter_mut().zip(&mut self.sum_square).zip(mean.pixels.iter().zip(&mean_square.pixels))
        {
            *acc += p.as_dvec3() * n;
            *acc_square += q.as_dvec3() * n;
        }
        self.done += count;
        true
    }

    /// The mean of the samples so far (black before the first pass).
    pub fn image(&self) -> Image {
        let n = self.done.max(1) as f64;
        let pixels = self.sum.iter().map(|s| (*s / n).as_vec3()).collect();
        Image { width: self.width, height: self.height, pixels }
    }

    /// The estimated variance of each pixel's mean, per channel: s²/n, with
    /// s² = (Σx² − (Σx)²/n)/(n − 1). Infinite before two samples.
    pub fn variance(&self) -> Image {
        let pixels = self.sum.iter().zip(&self.sum_square).map(|(s, q)| self.variance_of_mean(*s, *q).as_vec3());
        Image { width: self.width, height: self.height, pixels: pixels.collect() }
    }

    fn variance_of_mean(&self, sum: glam::DVec3, sum_square: glam::DVec3) -> glam::DVec3 {
        if self.done < 2 {
            return glam::DVec3::INFINITY;
        }
        let n = self.done as f64;
        let sample_variance = ((sum_square - sum * sum / n) / (n - 1.0)).max(glam::DVec3::ZERO);
        sample_variance / n
    }

    /// The estimated relative error of the image: √(Σ Var(mean) / Σ mean²)
    /// over pixels and channels, what [`crate::film::compare`]'s `rel_rmse`
    /// against the converged image is expected to be. Infinite before two
    /// samples or for a black image.
    pub fn estimated_relative_error(&self) -> f64 {
        let n = self.done.max(1) as f64;
        let (mut variance, mut signal) = (0.0, 0.0);
        for (s, q) in self.sum.iter().zip(&self.sum_square) {
            variance += self.variance_of_mean(*s, *q).element_sum();
            signal += (*s / n).length_squared();
        }
        if signal > 0.0 { (variance / signal).sqrt() } else { f64::INFINITY }
    }
}
