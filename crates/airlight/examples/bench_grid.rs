//! Density-grid benchmarks (BENCHMARKS.md):
//!
//! 1. The path tracer in the cloud of scenes/cloud_sun.toml (its grid,
//!    scenes/models/cloud.vol, seen from its camera, the sun only), single
//!    scattering, with the majorant grid (16³ cells) and with one global
//!    majorant, side by side at equal samples: both are unbiased, so the
//!    time per sample and the error against a long render decide.
//! 2. Load time and memory of a large dense grid (N³ voxels, default 512):
//!    written to a temporary .vol, read back through a scene file.
//!
//!     cargo run --release -p airlight --example bench_grid [-- N]

use airlight::SceneFile;
use airlight::assets::vol::{self, VolGrid};
use airlight::film::compare;
use airlight::integrator::{PathOptions, PathTracer};
use airlight::medium::{DensityGrid, Medium};
use airlight::prelude::*;
use glam::Affine3A;
use std::time::Instant;

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kib: f64 = status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    kib / 1024.0
}

fn cloud_scene(cells: usize, spp: u32) -> Scene {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/models/cloud.vol");
    let bytes = std::fs::read(path).expect("run the cloud_grid example first");
    let g = vol::read(&bytes[..], bytes.len() as u64).unwrap();
    let mut grid = DensityGrid::new(g.resolution, g.values, g.min, g.max, Affine3A::IDENTITY).unwrap();
    grid.set_majorant_resolution(cells);
    SceneBuilder::new()
        .size(160, 90)
        .with_settings(|s| {
            s.spp = spp;
            s.seed = 1;
            s.max_distance = 90.0;
        })
        .camera(Camera::look_at(vec3(0.0, 1.7, -16.0), vec3(0.0, 6.0, 20.0), Vec3::Y, 60.0))
        .light(Light::distant(vec3(0.1, -0.36, -1.0), Rgb::new(5.0, 4.4, 3.5)))
        .medium(Medium::grid(Rgb::splat(0.02), Rgb::splat(1.0), 0.6, grid))
        .build()
        .unwrap()
}

fn main() {
    if let (Some("load"), Some(dir)) = (std::env::args().nth(1).as_deref(), std::env::args().nth(2)) {
        return load(std::path::Path::new(&dir));
    }
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(512);
    let tracer = PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() });
    let reference = render(&cloud_scene(16, 1024), &tracer, &RenderObserver::none());
    println!("path tracer, cloud_sun's grid (72×20×96), 160×90, single scattering, 64 spp:");
    for (cells, name) in [(16, "majorant grid 16³"), (1, "one global majorant")] {
        let scene = cloud_scene(cells, 64);
        let start = Instant::now();
        let image = render(&scene, &tracer, &RenderObserver::none());
        let seconds = start.elapsed().as_secs_f64();
        let e = compare(&image, &reference).unwrap().rel_rmse;
        println!(
            "  {name}: {seconds:.2} s, relative RMSE against 1024 spp {e:.4}, time × error² {:.5}",
            seconds * e * e
        );
    }
    // A large dense grid through a scene file, loaded in a fresh process
    // so that its peak memory is the load's alone.
    let dir = tempfile_dir();
    let file = dir.join("large.vol");
    let values: Vec<f32> = (0..n * n * n).map(|i| ((i % 7) as f32) * 0.1).collect();
    let bytes = vol::write(&VolGrid { resolution: [n; 3], min: Vec3::splat(-1.0), max: Vec3::ONE, values });
    std::fs::write(&file, &bytes).unwrap();
    drop(bytes);
    let out = std::process::Command::new(std::env::current_exe().unwrap()).arg("load").arg(&dir).output().unwrap();
    print!("{n}³ dense grid ({} MiB of float32): {}", (n * n * n * 4) >> 20, String::from_utf8_lossy(&out.stdout));
    std::fs::remove_file(&file).ok();
}

/// Loads large.vol in `dir` through a scene file; prints time and memory.
fn load(dir: &std::path::Path) {
    let before = peak_rss_mib();
    let text = "[medium]\ntype = \"grid\"\nfile = \"large.vol\"\nsigma_s = 1\n[[lights]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = 1\n";
    let start = Instant::now();
    let scene = SceneFile::from_toml_str(text, Some(dir)).unwrap();
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "loaded in {seconds:.2} s; peak resident memory {:.0} MiB (before loading {before:.0} MiB)",
        peak_rss_mib()
    );
    drop(scene);
}

fn tempfile_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("airlight-bench-grid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
