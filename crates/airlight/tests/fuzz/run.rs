//! The fuzz tests' runner: a count of inputs (`AIRLIGHT_FUZZ_INPUTS`), or
//! the one input `AIRLIGHT_FUZZ_SEED` names, each under `catch_unwind`,
//! and a failure listing the seeds that replay what went wrong.

#![allow(dead_code)]

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

/// Inputs to try: `AIRLIGHT_FUZZ_INPUTS`, or `default`.
pub fn count(default: u64) -> u64 {
    std::env::var("AIRLIGHT_FUZZ_INPUTS").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Whether one input is being replayed (then the inputs are printed).
pub fn replaying() -> bool {
    std::env::var_os("AIRLIGHT_FUZZ_SEED").is_some()
}

fn panic_message(payload: Box<dyn std::any::Any + Send>) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(a panic without a message)".into())
}

/// Runs `n` inputs (or the one of `AIRLIGHT_FUZZ_SEED`), `one(seed)` each
/// (true: the input was accepted), and fails listing the seeds of any that
/// panicked or misreported.
pub fn fuzz(what: &str, base: u64, n: u64, mut one: impl FnMut(u64) -> Result<bool, String>) {
    let seeds: Vec<u64> = match std::env::var("AIRLIGHT_FUZZ_SEED").ok().and_then(|s| s.parse().ok()) {
        Some(seed) => vec![seed],
        None => (0..n).map(|i| super::mutate::seed(base, i)).collect(),
    };
    let start = Instant::now();
    let (mut accepted, mut failures) = (0u64, Vec::new());
    for &seed in &seeds {
        match catch_unwind(AssertUnwindSafe(|| one(seed))) {
            Ok(Ok(ok)) => accepted += ok as u64,
            Ok(Err(message)) => failures.push((seed, message)),
            Err(payload) => failures.push((seed, format!("panic: {}", panic_message(payload)))),
        }
    }
    eprintln!(
        "fuzz {what}: {} inputs in {:.1} s, {accepted} accepted, {} refused, {} failures",
        seeds.len(),
        start.elapsed().as_secs_f64(),
        seeds.len() as u64 - accepted - failures.len() as u64,
        failures.len()
    );
    for (seed, message) in failures.iter().take(20) {
        eprintln!("  AIRLIGHT_FUZZ_SEED={seed}: {message}");
    }
    assert!(failures.is_empty(), "{} of {} {what} inputs failed (seeds above)", failures.len(), seeds.len());
}
