//! Primary-ray throughput on a mesh of over a million triangles.
//!
//! `cargo run --release --example bench_bvh [-- SUBDIVISIONS]`
//!
//! Builds a displaced sphere (a UV sphere with SUBDIVISIONS² quads, default
//! 750² → 1.12 M triangles, radius modulated by a sum of sines), frames it
//! with a camera and traces one coherent primary ray per pixel of a
//! 1024×1024 image, tile by tile, on one thread and then on all threads.

use airlight::geometry::{GeometryBuilder, Ray, Shape};
use airlight::prelude::*;
use glam::Vec2;
use rayon::prelude::*;
use std::time::Instant;

fn displaced_sphere(n: u32) -> Shape {
    let mut positions = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..=n {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
            let dir = vec3(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let r = 1.0 + 0.05 * (7.0 * theta).sin() * (9.0 * phi).sin() + 0.02 * (31.0 * theta + 3.0 * phi).sin();
            positions.push(dir * r);
        }
    }
    let mut triangles = Vec::with_capacity((2 * n * n) as usize);
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            let b = a + n + 1;
            triangles.push([a, b, a + 1]);
            triangles.push([a + 1, b, b + 1]);
        }
    }
    Shape::Mesh { positions, triangles, uvs: Vec::new() }
}

fn main() {
    let n: u32 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(750);
    let t = Instant::now();
    let mesh = displaced_sphere(n);
    let Shape::Mesh { triangles, .. } = &mesh else { unreachable!() };
    let tris = triangles.len();
    let mut builder = GeometryBuilder::default();
    builder.add(&mesh, 0, None);
    let generated = t.elapsed();
    let t = Instant::now();
    let geometry = builder.build();
    let build = t.elapsed();
    println!(
        "mesh: {tris} triangles (generated in {:.2} s), BVH built in {:.2} s",
        generated.as_secs_f64(),
        build.as_secs_f64()
    );

    let (w, h) = (1024u32, 1024u32);
    let camera = Camera::look_at(vec3(0.0, 0.6, -3.2), Vec3::ZERO, Vec3::Y, 40.0);
    // Rays in 16×16 tiles, as the renderer issues them.
    let mut rays = Vec::with_capacity((w * h) as usize);
    for ty in (0..h).step_by(16) {
        for tx in (0..w).step_by(16) {
            for y in ty..ty + 16 {
                for x in tx..tx + 16 {
                    rays.push(camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), w, h, Vec2::ZERO));
                }
            }
        }
    }
    let trace = |ray: &Ray| geometry.intersect(ray, f32::INFINITY).is_some() as u64;
    // Warm up, then time one thread.
    let hits: u64 = rays.iter().take(100_000).map(trace).sum();
    let t = Instant::now();
    let hits1: u64 = rays.iter().map(trace).sum();
    let one = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let hits2: u64 = rays.par_chunks(256).map(|c| c.iter().map(trace).sum::<u64>()).sum();
    let all = t.elapsed().as_secs_f64();
    assert_eq!(hits1, hits2);
    let _ = hits;
    let threads = rayon::current_num_threads();
    println!(
        "{} primary rays, {:.1}% hit the mesh\n1 thread: {:.2} M rays/s\n{threads} threads: {:.2} M rays/s ({:.2} M rays/s per core)",
        rays.len(),
        100.0 * hits1 as f64 / rays.len() as f64,
        rays.len() as f64 / one / 1e6,
        rays.len() as f64 / all / 1e6,
        rays.len() as f64 / all / 1e6 / threads as f64
    );
}
