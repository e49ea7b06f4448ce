//! The path tracer in exponential height fog, on one thread.
//!
//! `cargo run --release -p airlight --example bench_heightfog [-- SCENE PATH_SPP DEPTH8_SPP [REF.exr [REF_SPP]]]`
//! (defaults scenes/heightfog_point.toml, 256, 256, no reference, 65536)
//!
//! 1. `raymarch`, 2048 steps, midpoints (jitter off), 16 spp: seconds and
//!    samples per second. The scene's filter is `point`, so both
//!    integrators trace the same camera rays and the march's image differs
//!    from the exact one by its O(Δ²) error only.
//! 2. `path`, max_depth 1, PATH_SPP spp: seconds, samples per second, and
//!    its relative RMSE against (1) beside the relative error its own pixel
//!    variances predict (√(Σ Var(mean) / Σ mean²)); their ratio near 1 is
//!    agreement within noise.
//! 3. `path`, max_depth 8, in passes of 1, 1, 2, 4, ... spp up to
//!    DEPTH8_SPP: after each pass the seconds so far and the estimated
//!    relative error. Time to 1% is read off, or, when DEPTH8_SPP stops
//!    short of it, extrapolated from the last pass as t·(e/0.01)² (error
//!    falls as 1/√spp). With REF.exr, each pass also shows its relative
//!    RMSE against that reference (read if the file exists, else rendered
//!    at REF_SPP spp with max_depth 8, another seed, all threads, untimed,
//!    and written there): a check of the estimate, which reads low while
//!    rare bright samples are missing.

use airlight::film::{Image, compare};
use airlight::integrator::{Integrator, PathOptions, PathTracer, Raymarch, RaymarchOptions};
use airlight::render::{Progressive, RenderObserver, render as render_with};
use airlight::scene::Scene;
use std::time::Instant;

/// Renders all of the scene's samples in progressive passes, calling
/// `after` with the state and the seconds so far after each pass.
fn progressive(scene: &Scene, integrator: &dyn Integrator, mut after: impl FnMut(&Progressive, f64)) -> Progressive {
    let mut state = Progressive::new(scene);
    let start = Instant::now();
    while !state.finished() {
        state.pass(scene, integrator, &RenderObserver::none());
        after(&state, start.elapsed().as_secs_f64());
    }
    state
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().map_or("scenes/heightfog_point.toml", |s| s.as_str());
    let number =
        |i: usize, default: u32| args.get(i).map_or(default, |s| s.parse().expect("SCENE PATH_SPP DEPTH8_SPP"));
    let (path_spp, depth8_spp, ref_spp) = (number(1, 256), number(2, 256), number(4, 65536));
    let mut scene = airlight::SceneFile::load(path.as_ref()).unwrap_or_else(|e| panic!("{e}")).scene;
    let pixels = (scene.settings().film.width * scene.settings().film.height) as f64;
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    println!("{path}, {}×{}, one thread", scene.settings().film.width, scene.settings().film.height);

    scene.settings_mut().spp = 16;
    let t = Instant::now();
    let marched = one.install(|| {
        render_with(&scene, &Raymarch::new(RaymarchOptions { steps: 2048, jitter: false }), &RenderObserver::none())
    });
    let march_secs = t.elapsed().as_secs_f64();
    println!(
        "raymarch, 2048 steps, jitter off, 16 spp: {march_secs:.2} s, {:.0} samples/s",
        16.0 * pixels / march_secs
    );

    scene.settings_mut().spp = path_spp;
    let tracer = PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() });
    let t = Instant::now();
    let state = one.install(|| progressive(&scene, &tracer, |_, _| {}));
    let path_secs = t.elapsed().as_secs_f64();
    let error = compare(&state.image(), &marched).unwrap().rel_rmse;
    let noise = state.estimated_relative_error();
    println!(
        "path, max_depth 1, {path_spp} spp: {path_secs:.2} s, {:.0} samples/s; \
         relative RMSE against the march {error:.4}, expected from its variance {noise:.4} (ratio {:.2})",
        path_spp as f64 * pixels / path_secs,
        error / noise
    );

    let reference = args.get(3).map(|file| {
        let file = std::path::Path::new(file);
        if let Ok(image) = Image::read_exr(file) {
            return image;
        }
        let (spp, seed) = (scene.settings().spp, scene.settings().seed);
        let s = scene.settings_mut();
        (s.spp, s.seed) = (ref_spp, seed.wrapping_add(1));
        let image = render_with(
            &scene,
            &PathTracer::new(PathOptions { max_depth: 8, ..PathOptions::default() }),
            &RenderObserver::none(),
        );
        let s = scene.settings_mut();
        (s.spp, s.seed) = (spp, seed);
        image.save(file).expect("cannot write the reference");
        image
    });
    scene.settings_mut().spp = depth8_spp;
    println!("path, max_depth 8: spp, seconds, estimated relative error[, relative RMSE against the reference]");
    let mut last = (0.0, f64::INFINITY);
    let mut reached = None;
    one.install(|| {
        progressive(&scene, &PathTracer::new(PathOptions { max_depth: 8, ..PathOptions::default() }), |state, secs| {
            let e = state.estimated_relative_error();
            let measured = reference.as_ref().map(|r| format!(" {:.4}", compare(&state.image(), r).unwrap().rel_rmse));
            println!("  {} {secs:.2} {e:.4}{}", state.samples(), measured.unwrap_or_default());
            last = (secs, e);
            if e <= 0.01 && reached.is_none() {
                reached = Some((state.samples(), secs));
            }
        })
    });
    match reached {
        Some((spp, secs)) => println!("1% reached at {spp} spp, {secs:.2} s"),
        None => println!("1% extrapolated: {:.1} s", last.0 * (last.1 / 0.01).powi(2)),
    }
}
