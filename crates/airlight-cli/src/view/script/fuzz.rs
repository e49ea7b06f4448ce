//! Structure-aware fuzzing of the path-file reader, with the library's
//! fuzz mutator: scenes/paths/cornell_fly.toml (and a script with light
//! keys) mutated as TOML trees and text, read against the Cornell box. No
//! input may panic, every error must give its line, and every script read
//! must give finite cameras at every frame of 0..=200.
//!
//! 10,000 inputs in the normal run; the ignored test a million
//! (`cargo test --release -p airlight-cli -- --ignored path_files`);
//! `AIRLIGHT_FUZZ_INPUTS` sets the count, `AIRLIGHT_FUZZ_SEED` replays one.

use super::*;
use crate::mutate::{self, Rng, mutate_text, mutate_tree};
use std::panic::{AssertUnwindSafe, catch_unwind};

const NAMES: &[&str] = &[
    "integrator",
    "scene_keyframes",
    "camera",
    "light",
    "frame",
    "position",
    "look_at",
    "fov",
    "preview",
    "raymarch",
    "stochastic",
];

const LIGHT_KEYS: &str = "integrator = \"raymarch\"\n[[light]]\nlight = 0\nframe = 0\nposition = [2.78, 5.4, 2.8]\n\
                          [[light]]\nlight = 0\nframe = 40\nposition = [1, 5.4, 1]\n";

fn one(seed: u64, bases: &[toml::Table], scene: &Scene) -> Result<bool, String> {
    let mut rng = Rng(seed);
    let mut doc = rng.pick(bases).clone();
    mutate_tree(&mut rng, &mut doc, NAMES, 3);
    let text = toml::to_string(&doc).map_err(|e| format!("the mutator wrote no TOML: {e}"))?;
    let bytes = if rng.chance(4) { mutate_text(&mut rng, &text) } else { text.into_bytes() };
    // The loader's own UTF-8 check is fuzzed by the scene test; here, text.
    let text = String::from_utf8_lossy(&bytes);
    match parse(&text, scene) {
        Ok(script) => {
            for frame in 0..=200 {
                let c = script.camera_at(frame, scene.camera());
                if !(c.forward.is_finite() && c.right.is_finite() && c.up.is_finite()) {
                    return Err(format!("frame {frame} has a broken camera: {c:?}"));
                }
                script.lights_at(frame, 201, scene.lights(), scene.light_paths());
            }
            Ok(true)
        }
        Err(e) if e.location.is_some() => Ok(false),
        Err(e) => Err(format!("error without a line: {e}")),
    }
}

fn run(n: u64) {
    let scene = airlight::SceneFile::from_toml_str(crate::view::DEFAULT_SCENE, None).unwrap().scene;
    let fly = include_str!("../../../../../scenes/paths/cornell_fly.toml");
    let bases: Vec<toml::Table> = [fly, LIGHT_KEYS].iter().map(|t| toml::from_str(t).unwrap()).collect();
    let n = std::env::var("AIRLIGHT_FUZZ_INPUTS").ok().and_then(|v| v.parse().ok()).unwrap_or(n);
    let seeds: Vec<u64> = match std::env::var("AIRLIGHT_FUZZ_SEED").ok().and_then(|s| s.parse().ok()) {
        Some(seed) => vec![seed],
        None => (0..n).map(|i| mutate::seed(0x9A7E, i)).collect(),
    };
    let start = std::time::Instant::now();
    let (mut accepted, mut failures) = (0, Vec::new());
    for &seed in &seeds {
        match catch_unwind(AssertUnwindSafe(|| one(seed, &bases, &scene))) {
            Ok(Ok(ok)) => accepted += ok as usize,
            Ok(Err(m)) => failures.push((seed, m)),
            Err(_) => failures.push((seed, "panic (message above)".into())),
        }
    }
    eprintln!(
        "fuzz path files: {} inputs in {:.1} s, {accepted} accepted, {} failures",
        seeds.len(),
        start.elapsed().as_secs_f64(),
        failures.len()
    );
    for (seed, m) in failures.iter().take(20) {
        eprintln!("  AIRLIGHT_FUZZ_SEED={seed}: {m}");
    }
    assert!(failures.is_empty(), "{} of {} path files failed (seeds above)", failures.len(), seeds.len());
}

#[test]
fn mutated_path_files_never_panic_and_errors_give_the_line() {
    run(10_000);
}

#[test]
#[ignore = "a million inputs: run by hand (BENCHMARKS.md)"]
fn a_million_mutated_path_files() {
    run(1_000_000);
}
