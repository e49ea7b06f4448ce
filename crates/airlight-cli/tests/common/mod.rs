//! What tests that need system tools share: a check that skips them, with
//! the reason printed, when a tool is missing, unless `AIRLIGHT_CI=1` (set
//! by `.ci/run` after it installs the tools), where a missing tool fails.

#![allow(dead_code)]

use std::path::Path;

/// Whether `tool` is an executable file in one of PATH's folders.
pub fn on_path(tool: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| is_executable(&dir.join(tool))))
}

fn is_executable(path: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    path.metadata().is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

/// True when every tool in `tools` is on PATH. Otherwise prints why the
/// calling test is skipped and returns false, or, under `AIRLIGHT_CI=1`,
/// fails: CI installs the tools, so a skip there would hide a failure.
pub fn tools_present(test: &str, tools: &[&str], install: &str) -> bool {
    let missing: Vec<&str> = tools.iter().copied().filter(|t| !on_path(t)).collect();
    if missing.is_empty() {
        return true;
    }
    let message = format!("{test} needs {missing:?} on PATH ({install}); skipped");
    if std::env::var("AIRLIGHT_CI").is_ok_and(|v| v == "1") {
        panic!("AIRLIGHT_CI=1: {message}, which CI must not do");
    }
    eprintln!("SKIPPED: {message}");
    false
}

/// Every channel of the file's first layer, by name.
pub fn exr_channels(path: &Path) -> std::collections::HashMap<String, Vec<f32>> {
    use exr::prelude::*;
    let image = read().no_deep_data().largest_resolution_level().all_channels().first_valid_layer().all_attributes();
    let image = image.from_file(path).unwrap();
    let mut out = std::collections::HashMap::new();
    for c in &image.layer_data.channel_data.list {
        out.insert(c.name.to_string(), c.sample_data.values_as_f32().collect());
    }
    out
}
