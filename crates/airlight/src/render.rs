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
    let s = &scene.settings;
    let (w, h) = (s.width, s.height);
    let tiles_x = w.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE)).flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty))).collect();
    let rendered: Vec<Vec<Rgb>> = tiles
        .par_iter()
        .map(|&(tx, ty)| {
            let (x0, y0) = (tx * TILE, ty * TILE);
            let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
            let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            if observer.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                out.resize(((x1 - x0) * (y1 - y0)) as usize, Rgb::ZERO);
                return out;
            }
            for y in y0..y1 {
                for x in x0..x1 {
                    out.push(render_pixel(scene, integrator, x, y, 0));
                }
            }
            if let Some(progress) = observer.progress {
                progress(out.len() as u64);
            }
            out
        })
        .collect();
    let mut image = Image::new(w, h);
    for (&(tx, ty), tile) in tiles.iter().zip(&rendered) {
        let (x0, y0) = (tx * TILE, ty * TILE);
        let tile_w = (x0 + TILE).min(w) - x0;
        for (i, &p) in tile.iter().enumerate() {
            let (x, y) = (x0 + i as u32 % tile_w, y0 + i as u32 / tile_w);
            image.pixels[(y * w + x) as usize] = p;
        }
    }
    image
}

/// The mean of `spp` samples of one pixel in pass `pass`.
///
/// Each sample draws from its own stream, keyed by (seed, pixel, sample
/// number), so its camera ray is the same whatever the integrator draws
/// after it: images of one scene by two integrators share their
/// anti-aliasing and lens samples, and differ only by what the integrators
/// compute.
pub fn render_pixel(scene: &Scene, integrator: &dyn Integrator, x: u32, y: u32, pass: u64) -> Rgb {
    let s = &scene.settings;
    let index = y as u64 * s.width as u64 + x as u64;
    let mut sum = Rgb::ZERO;
    for i in 0..s.spp as u64 {
        let mut sampler = Sampler::for_pixel(s.seed, index, pass * s.spp as u64 + i);
        let jitter = sampler.next2();
        let film = Vec2::new(x as f32, y as f32)
            + match s.filter {
                PixelFilter::Box => jitter,
                PixelFilter::Point => Vec2::splat(0.5),
            };
        let lens = sampler.next2();
        let ray = scene.camera.ray(film, s.width, s.height, lens);
        let l = integrator.radiance(scene, &ray, &mut sampler);
        // One broken sample (NaN, inf) must not spoil the pixel.
        if l.is_finite() {
            sum += l;
        }
    }
    sum / s.spp as f32
}
