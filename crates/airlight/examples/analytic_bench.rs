//! Equal-error timing of the analytic integrator against ray marching
//! (issue 4's benchmark). For each scene: render with `analytic`, then with
//! `raymarch` at 8, 16, 32, … steps until its relative RMSE against the
//! converged reference is at most 1%, timing every render in this one run.
//!
//! The reference is the analytic image itself: the tests show it within
//! 1e-5 (glow) and 1e-4 (shadows) relative RMSE of raymarch at 4096 steps,
//! and this program also checks it against raymarch at 4096 steps on a
//! 160×120 crop of the same camera (printed).
//!
//! One sample per pixel and no jitter: both integrators then trace the same
//! camera ray per pixel (the first numbers of each pixel's stream) and the
//! surface term is the same, so the error is that of the medium alone.
//!
//!     cargo run --release -p airlight --example analytic_bench [WIDTH HEIGHT]

use airlight::film;
use airlight::integrator::analytic::{Analytic, AnalyticOptions};
use airlight::integrator::{Integrator, Raymarch};
use airlight::prelude::*;
use airlight::render::render_with;
use std::path::PathBuf;
use std::time::Instant;

fn load(name: &str, w: u32, h: u32) -> Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    let mut scene = airlight::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.settings.width = w;
    scene.settings.height = h;
    scene.settings.spp = 1;
    scene.settings.jitter = false;
    scene
}

fn timed(scene: &Scene, integrator: &dyn Integrator) -> (Image, f64) {
    let start = Instant::now();
    let image = render_with(scene, integrator, &RenderObserver::none());
    (image, start.elapsed().as_secs_f64())
}

fn main() {
    let args: Vec<u32> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (w, h) = match args[..] {
        [w, h] => (w, h),
        _ => (640, 480),
    };
    println!("threads: {}", rayon::current_num_threads());
    for (name, shadows) in [("glow.toml", false), ("shadow_spheres.toml", true)] {
        let scene = load(name, w, h);
        let analytic =
            Analytic::new(&scene, AnalyticOptions { shadows, ..AnalyticOptions::from_settings(&scene.settings) })
                .unwrap();
        // Best of three, as the machine is shared.
        let mut best = f64::INFINITY;
        let mut reference = None;
        for _ in 0..3 {
            let (image, t) = timed(&scene, &analytic);
            best = best.min(t);
            reference = Some(image);
        }
        let reference = reference.unwrap();

        // The reference against a fine march on a small image.
        let check = load(name, 160, 120);
        let check_analytic =
            Analytic::new(&check, AnalyticOptions { shadows, ..AnalyticOptions::from_settings(&check.settings) })
                .unwrap();
        let fine = Raymarch { steps: 4096, jitter: false };
        let (a, _) = timed(&check, &check_analytic);
        let (b, _) = timed(&check, &fine);
        let ref_err = film::compare(&a, &b).unwrap().rel_rmse;

        println!("\n## {name} at {w}×{h}, 1 spp, shadows = {shadows}");
        println!("analytic: {best:.3} s (reference; vs raymarch 4096 at 160×120: rel_rmse {ref_err:.2e})");
        println!("| raymarch steps | time (s) | rel_rmse | time / analytic |");
        println!("|---:|---:|---:|---:|");
        let mut steps = 8;
        loop {
            let rm = Raymarch { steps, jitter: false };
            let (image, t) = timed(&scene, &rm);
            let e = film::compare(&image, &reference).unwrap().rel_rmse;
            println!("| {steps} | {t:.3} | {e:.4} | {:.1}× |", t / best);
            if e <= 0.01 {
                println!(
                    "equal error (1%): raymarch {steps} steps, {t:.3} s; analytic {best:.3} s: \
                     analytic {:.1}× faster",
                    t / best
                );
                break;
            }
            if steps >= 4096 {
                println!(
                    "raymarch does not reach 1% by 4096 steps ({e:.4} at {t:.3} s): \
                     analytic at least {:.1}× faster at equal error",
                    t / best
                );
                break;
            }
            steps *= 2;
        }
    }
}
