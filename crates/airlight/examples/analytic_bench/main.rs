//! Equal-error timing of the analytic integrator against ray marching
//! (the analytic integrator's benchmark), against an independent converged reference.
//!
//! For each scene, at 1 sample per pixel (every integrator traces the same
//! camera ray in a pixel and shades the surface the same way, so the error is
//! that of the medium alone):
//!
//! 1. the reference: adaptive Gauss–Kronrod along each ray, with the
//!    integrand written out in f64 and shadow rays through the BVH
//!    (reference.rs), to a relative tolerance `tol`; how converged it is
//!    is measured on a 160×120 crop by the same with tol/10 (and against a
//!    jittered 4096-step march);
//! 2. `analytic` (best of three) and its error against the reference;
//! 3. `raymarch` (midpoints, no jitter) at 8, 16, 32, … steps until its
//!    relative RMSE against the reference is at most 1%, then bisection on
//!    the step count between the last two powers of two for the first
//!    count that reaches 1%;
//! 4. `direct` (camera ray and surface shading only, no medium): the floor
//!    that both integrators pay.
//!
//!     cargo run --release -p airlight --example analytic_bench -- [WIDTH HEIGHT] [--max-steps N] [--tol T]

mod reference;

use airlight::film;
use airlight::integrator::RaymarchOptions;
use airlight::integrator::analytic::{Analytic, AnalyticOptions};
use airlight::integrator::{Direct, Integrator, Raymarch};
use airlight::prelude::*;
use airlight::render::render;
use reference::Reference;
use std::path::PathBuf;
use std::time::Instant;

fn load(name: &str, w: u32, h: u32) -> Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    let mut scene = airlight::SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}")).scene;
    scene.settings_mut().film.width = w;
    scene.settings_mut().film.height = h;
    scene.settings_mut().spp = 1;
    scene
}

fn timed(scene: &Scene, integrator: &dyn Integrator) -> (Image, f64) {
    let start = Instant::now();
    let image = render(scene, integrator, &RenderObserver::none());
    (image, start.elapsed().as_secs_f64())
}

fn err(a: &Image, b: &Image) -> f64 {
    film::compare(a, b).unwrap().rel_rmse
}

struct Args {
    w: u32,
    h: u32,
    max_steps: u32,
    tol: f64,
}

fn args() -> Args {
    let mut a = Args { w: 640, h: 480, max_steps: 1024, tol: 1e-5 };
    let list: Vec<String> = std::env::args().skip(1).collect();
    let mut sizes = Vec::new();
    let mut i = 0;
    while i < list.len() {
        match list[i].as_str() {
            "--max-steps" => {
                a.max_steps = list[i + 1].parse().expect("--max-steps N");
                i += 1;
            }
            "--tol" => {
                a.tol = list[i + 1].parse().expect("--tol T");
                i += 1;
            }
            s => sizes.push(s.parse::<u32>().expect("WIDTH HEIGHT")),
        }
        i += 1;
    }
    if let [w, h] = sizes[..] {
        (a.w, a.h) = (w, h);
    }
    a
}

fn main() {
    let a = args();
    reference::check_rule();
    println!("threads: {}, {}×{}, 1 spp, reference tol {:e}", rayon::current_num_threads(), a.w, a.h, a.tol);
    for (name, shadows) in [("glow.toml", false), ("shadow_spheres.toml", true)] {
        let scene = load(name, a.w, a.h);
        let options = AnalyticOptions { shadows, ..AnalyticOptions::default() };
        let analytic = Analytic::new(&scene, options).unwrap();
        println!("\n## {name}, shadows = {shadows}");

        // How converged the reference is, on a small image.
        let small = load(name, 160, 120);
        let (r1, _) = timed(&small, &Reference { tol: a.tol });
        let (r2, _) = timed(&small, &Reference { tol: a.tol / 10.0 });
        let (jm, _) = timed(&small, &Raymarch::new(RaymarchOptions { steps: 4096, jitter: true }));
        println!(
            "reference at 160×120: vs itself at tol/10: rel_rmse {:.2e}; vs raymarch 4096 jittered: {:.2e}",
            err(&r1, &r2),
            err(&jm, &r2)
        );

        let (reference, t_ref) = timed(&scene, &Reference { tol: a.tol });
        println!("reference: {t_ref:.1} s");

        let mut best = f64::INFINITY;
        let mut image = None;
        for _ in 0..3 {
            let (im, t) = timed(&scene, &analytic);
            best = best.min(t);
            image = Some(im);
        }
        let e_an = err(&image.unwrap(), &reference);
        let (_, t_direct) = timed(&scene, &Direct);
        println!("analytic: {best:.3} s, rel_rmse vs reference {e_an:.2e}");
        println!("direct (camera rays + surface shading, no medium): {t_direct:.3} s");

        println!("| raymarch steps | time (s) | rel_rmse | time / analytic |");
        println!("|---:|---:|---:|---:|");
        let run = |steps: u32| {
            let (im, t) = timed(&scene, &Raymarch::new(RaymarchOptions { steps, jitter: false }));
            let e = err(&im, &reference);
            println!("| {steps} | {t:.3} | {e:.4} | {:.1}× |", t / best);
            (e, t)
        };
        let mut steps = 8;
        let mut last_fail = 0;
        let found = loop {
            let (e, t) = run(steps);
            if e <= 0.01 {
                break Some((steps, t));
            }
            last_fail = steps;
            if steps >= a.max_steps {
                println!(
                    "raymarch does not reach 1% by {steps} steps ({e:.4}, {t:.3} s): analytic at least {:.1}× faster \
                     at equal error",
                    t / best
                );
                break None;
            }
            steps *= 2;
        };
        if let Some((mut pass, mut t_pass)) = found {
            // The first step count reaching 1%, between last_fail and pass.
            let mut fail = last_fail;
            while pass - fail > (pass / 16).max(1) {
                let mid = (fail + pass) / 2;
                let (e, t) = run(mid);
                if e <= 0.01 {
                    (pass, t_pass) = (mid, t);
                } else {
                    fail = mid;
                }
            }
            println!(
                "equal error (1%): raymarch {pass} steps, {t_pass:.3} s; analytic {best:.3} s \
                 (its error {e_an:.2e}): analytic {:.1}× faster",
                t_pass / best
            );
        }
    }
}
