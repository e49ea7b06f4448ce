//! Times the radiosity lookup (`Radiosity::irradiance_at`) at the hits of
//! the Cornell box's camera rays, the viewer's anchors of three views of
//! its flight (every other pixel of every other row at 640×360), in pixel
//! order as the viewer makes them; then each twice in a row, the second
//! finding its candidate list in the cache, which shows how much of a
//! lookup is waiting for memory.
//!
//! `cargo run --release -p airlight --example bench_lookup -- [ROUNDS]`

use airlight::integrator::RadiosityOptions;
use airlight::radiosity::Radiosity;
use airlight::{Camera, SceneFile};
use glam::{Vec2, Vec3, vec3};
use std::time::Instant;

fn main() {
    let rounds: usize = std::env::args().nth(1).map_or(20, |a| a.parse().expect("a number of rounds"));
    let text = include_str!("../../../scenes/cornell_box.toml");
    let scene = SceneFile::from_toml_str(text, None).unwrap().scene;
    let mut solution = Radiosity::compile(&scene, &RadiosityOptions::default()).unwrap();
    solution.update(&scene, 1);
    let views = [
        (vec3(2.78, 2.73, -8.0), vec3(2.78, 2.73, 0.0)),
        (vec3(2.78, 2.2, -3.0), vec3(2.78, 1.5, 2.8)),
        (vec3(2.0, 2.0, -1.0), vec3(5.56, 2.0, 2.0)),
    ];
    let (w, h) = (640, 360);
    let mut queries: Vec<(Vec3, Vec3)> = Vec::new();
    for (position, target) in views {
        let camera = Camera::look_at(position, target, Vec3::Y, 39.3).rays(w, h);
        for y in (0..h).step_by(2) {
            for x in (0..w).step_by(2) {
                let ray = camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::ZERO);
                if let Some(hit) = scene.geometry().intersect(&ray, f32::INFINITY) {
                    let s = scene.geometry().surface(&ray, hit);
                    queries.push((s.p, s.facing(ray.dir)));
                }
            }
        }
    }
    // Nanoseconds a lookup: the fastest of `rounds` passes over the
    // queries, each looked up `times` times in a row.
    let mut check = Vec3::ZERO;
    let mut time = |times: usize| {
        let mut best = f64::INFINITY;
        for _ in 0..rounds {
            let start = Instant::now();
            for &(p, n) in &queries {
                for _ in 0..times {
                    check += solution.irradiance_at(p, n).unwrap_or(Vec3::ZERO);
                }
            }
            best = best.min(start.elapsed().as_secs_f64());
        }
        best * 1e9 / (queries.len() * times) as f64
    };
    let (once, twice) = (time(1), time(2));
    println!("{} lookups: {once:.1} ns a lookup (fastest of {rounds} rounds)", queries.len());
    println!("twice each: {twice:.1} ns a lookup (sum {check})");
}
