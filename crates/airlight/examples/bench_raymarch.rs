//! Ray-marching speed and error on the spot-light scene.
//!
//! `cargo run --release --example bench_raymarch [-- SCENE]`
//! (default scenes/spheres_spot_fog.toml)
//!
//! 1. Time at 640×480, 1 spp, steps 50, 100, 300 on one thread, and shadow
//!    rays traced per second on that thread.
//! 2. Relative RMSE against a 4096-step reference (midpoints, 1 spp) as steps
//!    grow, with jitter off and on. Every image shares its camera rays (each
//!    sample has its own random stream), so the error is the march's alone.

use airlight::film::compare;
use airlight::geometry::shadow_rays_traced;
use airlight::integrator::Raymarch;
use airlight::integrator::RaymarchOptions;
use airlight::render::{RenderObserver, render};
use std::time::Instant;

fn main() {
    let path = std::env::args().nth(1).unwrap_or_else(|| "scenes/spheres_spot_fog.toml".into());
    let mut scene = airlight::SceneFile::load(path.as_ref()).unwrap_or_else(|e| panic!("{e}")).scene;
    (scene.settings_mut().film.width, scene.settings_mut().film.height, scene.settings_mut().spp) = (640, 480, 1);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let traced = || one.broadcast(|_| shadow_rays_traced()).iter().sum::<u64>();
    println!("{path}, 640×480, 1 spp, one thread");
    println!("| steps | seconds | shadow rays | M shadow rays/s |");
    println!("|---|---|---|---|");
    for steps in [50, 100, 300] {
        let integrator = Raymarch::new(RaymarchOptions { steps, jitter: true });
        let before = traced();
        let t = Instant::now();
        one.install(|| render(&scene, &integrator, &RenderObserver::none()));
        let secs = t.elapsed().as_secs_f64();
        let rays = traced() - before;
        println!("| {steps} | {secs:.2} | {rays} | {:.1} |", rays as f64 / secs / 1e6);
    }

    // Shadow rays alone: from random points in the lit volume to the light.
    let light = match scene.lights()[0] {
        airlight::light::Light::Spot { position, .. } | airlight::light::Light::Point { position, .. } => position,
        _ => glam::Vec3::new(0.0, 6.0, 0.0),
    };
    let mut sampler = airlight::sampling::Sampler::for_pixel(0, 0, 0);
    let rays: Vec<(glam::Vec3, glam::Vec3, f32)> = (0..2_000_000)
        .map(|_| {
            let p = glam::Vec3::new(8.0 * sampler.next() - 4.0, 5.0 * sampler.next(), 7.0 * sampler.next() - 3.0);
            let d = light - p;
            (p, d.normalize(), d.length() * (1.0 - 1e-4))
        })
        .collect();
    let t = Instant::now();
    let blocked = rays.iter().filter(|(p, d, tmax)| scene.geometry().occluded(*p, *d, *tmax)).count();
    let secs = t.elapsed().as_secs_f64();
    println!(
        "\nshadow rays alone: {} in {secs:.3} s on one thread, {:.1}% blocked: {:.1} M shadow rays/s",
        rays.len(),
        100.0 * blocked as f64 / rays.len() as f64,
        rays.len() as f64 / secs / 1e6
    );

    (scene.settings_mut().film.width, scene.settings_mut().film.height) = (320, 240);
    let render =
        |steps, jitter| render(&scene, &Raymarch::new(RaymarchOptions { steps, jitter }), &RenderObserver::none());
    let reference = render(4096, false);
    println!("\nrelative RMSE against 4096 steps, 320×240, 1 spp");
    println!("| steps | jitter off | jitter on |");
    println!("|---|---|---|");
    for steps in [16, 32, 50, 64, 100, 128, 256, 300, 512] {
        let off = compare(&render(steps, false), &reference).unwrap().rel_rmse;
        let on = compare(&render(steps, true), &reference).unwrap().rel_rmse;
        println!("| {steps} | {:.4} | {:.4} |", off, on);
    }
}
