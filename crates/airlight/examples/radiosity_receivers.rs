//! What clusters that receive light cost in accuracy and save in links:
//! the Cornell box compiled with patches only and with several receiver
//! shares, the same patches each time; per share the links, the compile
//! time and the mean per-patch relative difference of the one-bounce
//! indirect irradiance from the patches-only solution.
//!
//! `cargo run --release -p airlight --example radiosity_receivers -- PATCH_SIZE SHARE...`

use airlight::SceneFile;
use airlight::integrator::RadiosityOptions;
use airlight::radiosity::{CompileParams, Radiosity};
use std::time::Instant;

fn main() {
    let args: Vec<f32> = std::env::args().skip(1).map(|a| a.parse().expect("a number")).collect();
    let (h, shares) = args.split_first().expect("PATCH_SIZE SHARE...");
    let text = include_str!("../../../scenes/cornell_box.toml");
    let scene = SceneFile::from_toml_str(text, None).unwrap().scene;
    let options = RadiosityOptions { patch_size: Some(*h), bounces: 1, ..RadiosityOptions::default() };
    let base = CompileParams::for_scene(&scene, &options);
    let solve = |share: f32| {
        let t = Instant::now();
        let mut r = Radiosity::compile_with(&scene, CompileParams { receiver_share: share, ..base }).unwrap();
        let compile = t.elapsed().as_secs_f64();
        r.update(&scene, 1);
        (r, compile)
    };
    let (reference, compile) = solve(0.0);
    let patches = reference.patches().len();
    println!("patch_size {h}: {patches} patches");
    println!(
        "share 0: {} links ({:.1} per patch), compile {compile:.1} s",
        reference.stats().links,
        reference.stats().links as f64 / patches as f64
    );
    for &share in shares {
        let (r, compile) = solve(share);
        assert_eq!(r.patches(), reference.patches());
        // Area-weighted: Σ A |E − E₀| / Σ A E₀, over all patches and over
        // those whose E₀ is at least a tenth of the mean (the dark ones,
        // such as the floor under a block, are hidden from the camera).
        let pairs: Vec<(f64, f64, f64)> = r
            .indirect_irradiance()
            .iter()
            .zip(reference.indirect_irradiance())
            .zip(reference.patches())
            .map(|((a, b), p)| (a.element_sum() as f64, b.element_sum() as f64, p.area as f64))
            .collect();
        let area: f64 = pairs.iter().map(|p| p.2).sum();
        let mean = pairs.iter().map(|p| p.1 * p.2).sum::<f64>() / area;
        let l1 = |floor: f64| {
            let kept = pairs.iter().filter(|p| p.1 >= floor);
            let (d, e) = kept.fold((0.0, 0.0), |(d, e), p| (d + (p.0 - p.1).abs() * p.2, e + p.1 * p.2));
            100.0 * d / e
        };
        let mut rel: Vec<f64> = pairs.iter().filter(|p| p.1 >= 0.1 * mean).map(|p| (p.0 / p.1 - 1.0).abs()).collect();
        rel.sort_by(f64::total_cmp);
        let p95 = 100.0 * rel[rel.len() * 95 / 100];
        let total = pairs.iter().map(|p| p.0 * p.2).sum::<f64>() / (mean * area) - 1.0;
        println!(
            "share {share}: {} links ({:.1} per patch), compile {compile:.1} s; vs share 0: L1 {:.2}% (patches above mean/10: {:.2}%, p95 {p95:.1}%), total {:+.3}%",
            r.stats().links,
            r.stats().links as f64 / patches as f64,
            l1(0.0),
            l1(0.1 * mean),
            100.0 * total
        );
    }
}
