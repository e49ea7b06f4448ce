//! Error against a converged reference and time per sample of the
//! stochastic integrator's strategies, on the glow scene (point lights in
//! fog) and the SDF scene with shadows.
//!
//! `cargo run --release --example bench_stochastic [-- WIDTH HEIGHT REF_SPP]`
//! (default 320 240 4096; BENCHMARKS.md used 320 240 2048)
//!
//! For each scene: a reference of REF_SPP samples per pixel (equiangular,
//! stratified, another seed), checked against the closed form (`analytic`,
//! exact for the glow's point lights) or `raymarch` (256 steps, 16 spp, for
//! the SDF scene);
//! then the relative RMSE (√(Σ(a − b)²/Σb²)) of each strategy at 1, 2, 4,
//! 8, 16, 64 spp, and the time per spp (all threads). The target:
//! equiangular with stratification reaches uniform's 64-spp error at 8 spp
//! or fewer.

use airlight::SceneFile;
use airlight::film::{Image, compare};
use airlight::integrator::{Integrator, IntegratorDesc, Raymarch, RaymarchOptions, Sampling, Stochastic};
use airlight::render::RenderObserver;
use airlight::scene::Scene;
use std::time::Instant;

const SPPS: [u32; 6] = [1, 2, 4, 8, 16, 64];

/// The scene at `path`, at the benchmark's size, spp and seed. (Scenes hold
/// a BVH and are not Clone; loading is cheap next to rendering.)
fn load(path: &str, (width, height): (u32, u32), spp: u32, seed: u64) -> (Scene, IntegratorDesc) {
    let SceneFile { mut scene, integrator } = SceneFile::load(path.as_ref()).unwrap_or_else(|e| panic!("{e}"));
    let s = scene.settings_mut();
    (s.film.width, s.film.height, s.spp, s.seed) = (width, height, spp, seed);
    (scene, integrator)
}

fn render(scene: &Scene, integrator: &dyn Integrator) -> (Image, f64) {
    let t = Instant::now();
    let image = airlight::render(scene, integrator, &RenderObserver::none());
    (image, t.elapsed().as_secs_f64())
}

fn main() {
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse().expect("WIDTH HEIGHT REF_SPP")).collect();
    let (w, h, ref_spp) = match args[..] {
        [w, h, r] => (w, h, r),
        _ => (320, 240, 4096),
    };
    let strategies = [
        ("uniform, independent (Hoff)", Sampling::Uniform, false),
        ("uniform, stratified", Sampling::Uniform, true),
        ("equiangular, independent", Sampling::Equiangular, false),
        ("equiangular, stratified", Sampling::Equiangular, true),
        ("mis, stratified", Sampling::Mis, true),
    ];
    for path in ["scenes/glow.toml", "scenes/sdf_isometric.toml"] {
        let size = (w, h);
        let equiangular = Stochastic { sampling: Sampling::Equiangular, stratify: true };
        let (reference, ref_secs) = render(&load(path, size, ref_spp, 1_000_003).0, &equiangular);
        // An independent check of the reference: the closed form where it
        // is exact (point lights, no shadows: the glow), else the march.
        let (check_name, check) = if path.contains("glow") {
            let (scene, desc) = load(path, size, 64, 7);
            let analytic = desc.build(&scene).expect("glow.toml names analytic");
            ("analytic (closed form, 64 spp)", render(&scene, analytic.as_ref()).0)
        } else {
            let march = Raymarch::new(RaymarchOptions { steps: 256, jitter: true });
            ("raymarch (256 steps, 16 spp, jittered)", render(&load(path, size, 16, 7).0, &march).0)
        };
        println!("\n## {path}, {w}×{h}\n");
        println!(
            "Reference: {ref_spp} spp equiangular + stratified ({ref_secs:.1} s); against {check_name}: relative RMSE {:.4}.\n",
            compare(&check, &reference).unwrap().rel_rmse
        );
        print!("| strategy |");
        for spp in SPPS {
            print!(" {spp} spp |");
        }
        println!(" ms per spp |");
        println!("|---|{}---|", "---|".repeat(SPPS.len()));
        let mut rows = Vec::new();
        for (name, sampling, stratify) in strategies {
            let integrator = Stochastic { sampling, stratify };
            let mut errors = Vec::new();
            let mut per_spp = 0.0;
            for spp in SPPS {
                let (image, secs) = render(&load(path, size, spp, 42).0, &integrator);
                errors.push(compare(&image, &reference).unwrap().rel_rmse);
                if spp == 64 {
                    per_spp = secs / 64.0;
                }
            }
            print!("| {name} |");
            for e in &errors {
                print!(" {e:.4} |");
            }
            println!(" {:.1} |", per_spp * 1e3);
            rows.push((name, errors));
        }
        let target = rows[0].1[SPPS.len() - 1];
        let reached = rows[3].1.iter().zip(SPPS).find(|(e, _)| **e <= target).map(|(_, s)| s);
        println!(
            "\nUniform (Hoff's estimator) at 64 spp: {target:.4}. Equiangular + stratified reaches it at {} spp.",
            reached.map_or("more than 64".to_string(), |s| s.to_string())
        );
    }
}
