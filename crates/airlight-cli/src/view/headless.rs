//! `airlight view --headless`: the window's frame loop without a window,
//! driven by a script ([`super::script`]) instead of keys; it prints each
//! frame's times and their median and p95, and writes the frames if asked.
//! Tests and benchmarks use it.

use super::engine::{Engine, FrameStats};
use super::script::Script;
use airlight::Camera;
use airlight::light::{Keyframes, Light};
use std::path::Path;
use std::time::Duration;

/// What stays fixed while the script runs: the scene's own camera and
/// lights, which the script's keys move away from.
pub struct Start {
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub paths: Vec<Option<Keyframes>>,
}

/// Runs `frames` frames of `script`; with `out`, writes each frame as
/// `frame_0000.exr` and `.png` there (after its timing, so not timed).
pub fn run(engine: &mut Engine, script: &Script, start: &Start, frames: u32, out: Option<&Path>) -> Result<(), String> {
    if let Some(dir) = out {
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
    }
    let (w, h) = engine.size();
    println!("frames: {frames} at {w}×{h}, integrator {}, threads {}", describe(engine), rayon::current_num_threads());
    let mut stats = Vec::with_capacity(frames as usize);
    let forecast = crate::preflight::Forecast::new(frames as u64, format!("{frames} headless frames"), false);
    for k in 0..frames {
        if let Some(warning) = forecast.advance(1) {
            eprintln!("{warning}");
        }
        engine.set_camera(script.camera_at(k, &start.camera));
        engine.set_lights(&script.lights_at(k, frames, &start.lights, &start.paths));
        let s = engine.frame();
        println!(
            "frame {k}: radiosity {:.3} ms, image {:.3} ms, +{} → {} spp",
            ms(s.radiosity),
            ms(s.image),
            s.added,
            s.samples
        );
        stats.push(s);
        if let Some(dir) = out {
            let image = engine.image();
            let settings = engine.scene.settings();
            for ext in ["exr", "png"] {
                let file = dir.join(format!("frame_{k:04}.{ext}"));
                image
                    .save_with(&file, settings.film.exposure, settings.film.tonemap)
                    .map_err(|e| format!("cannot write `{}`: {e}", file.display()))?;
            }
        }
    }
    let summary = Summary::of(&stats);
    println!(
        "per frame: median {:.3} ms ({:.1} fps), p95 {:.3} ms",
        summary.total.0,
        1e3 / summary.total.0.max(1e-9),
        summary.total.1
    );
    println!("  radiosity update: median {:.3} ms, p95 {:.3} ms", summary.radiosity.0, summary.radiosity.1);
    println!("  image: median {:.3} ms, p95 {:.3} ms", summary.image.0, summary.image.1);
    if let Some(dir) = out {
        println!("frames written to {}", dir.display());
    }
    Ok(())
}

/// The integrator's name, with what the preview does about the medium.
pub fn describe(engine: &Engine) -> String {
    let mode = engine.mode();
    if mode != super::engine::Mode::Preview {
        return mode.name().to_string();
    }
    let glow = engine.preview().glow_name();
    let indirect = if engine.solution().is_some() { "radiosity indirect" } else { "no indirect" };
    format!("preview (direct + {indirect} + glow: {glow})")
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Medians and 95th percentiles, in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    pub total: (f64, f64),
    pub radiosity: (f64, f64),
    pub image: (f64, f64),
}

impl Summary {
    pub fn of(stats: &[FrameStats]) -> Summary {
        let q = |f: &dyn Fn(&FrameStats) -> Duration| {
            let mut v: Vec<f64> = stats.iter().map(|s| ms(f(s))).collect();
            v.sort_by(f64::total_cmp);
            (quantile(&v, 0.5), quantile(&v, 0.95))
        };
        Summary { total: q(&|s| s.total()), radiosity: q(&|s| s.radiosity), image: q(&|s| s.image) }
    }
}

/// The `q` quantile of sorted values, by the nearest rank (0 when empty).
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_by_nearest_rank() {
        let v: Vec<f64> = (1..=21).map(f64::from).collect();
        assert_eq!(quantile(&v, 0.5), 11.0);
        assert_eq!(quantile(&v, 0.95), 20.0);
        assert_eq!(quantile(&[], 0.5), 0.0);
        let s = Summary::of(&[
            FrameStats { radiosity: Duration::from_millis(2), image: Duration::from_millis(10), ..Default::default() },
            FrameStats { radiosity: Duration::ZERO, image: Duration::from_millis(30), ..Default::default() },
            FrameStats { radiosity: Duration::from_millis(4), image: Duration::from_millis(20), ..Default::default() },
        ]);
        assert_eq!(s.total, (24.0, 30.0));
        assert_eq!(s.radiosity, (2.0, 4.0));
        assert_eq!(s.image, (20.0, 30.0));
    }
}
