//! The Python package (crates/airlight-py) end to end: its wheel built with
//! maturin in a virtual environment of its own, installed there, and its
//! pytest suite run against this build's `airlight` binary (the same pixels
//! from Python and from the CLI, the CLI's error messages, the GIL released,
//! Ctrl-C).
//!
//! It needs python3 with venv and pip, and PyPI for the packages in
//! crates/airlight-py/tests/requirements.txt. Without python3's venv or pip
//! the test says so and is skipped, except under AIRLIGHT_CI=1 (.ci/run
//! installs them), where that fails.
//!
//! The environment, the packages and the wheel's Cargo build are kept under
//! target/tmp/python, so a second run only rebuilds what changed. Set
//! AIRLIGHT_PYTHON to use another interpreter than `python3`.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longest the pytest suite may run (it takes about a minute).
const PYTEST_TIMEOUT: Duration = Duration::from_secs(15 * 60);

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `cmd` to the end with its output captured; panics with the output
/// when it fails.
fn run(what: &str, cmd: &mut Command) {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: cannot start {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Whether `python` can make a virtual environment with pip in it; if not,
/// says why and skips, or fails under AIRLIGHT_CI=1.
fn python_usable(python: &str) -> bool {
    let probe = Command::new(python).args(["-c", "import venv, ensurepip"]).output();
    if probe.as_ref().is_ok_and(|o| o.status.success()) {
        return true;
    }
    let why = match probe {
        Err(e) => format!("`{python}` cannot be run ({e})"),
        Ok(o) => format!("`{python}` has no venv or ensurepip module: {}", String::from_utf8_lossy(&o.stderr).trim()),
    };
    let message = format!(
        "the Python package's test needs python3 with venv and pip (apt-get install python3-venv python3-pip, as \
         .ci/run does): {why}; skipped"
    );
    if std::env::var("AIRLIGHT_CI").is_ok_and(|v| v == "1") {
        panic!("AIRLIGHT_CI=1: {message}, which CI must not do");
    }
    eprintln!("SKIPPED: {message}");
    false
}

#[test]
fn python_package_builds_installs_and_passes_its_tests() {
    let python = std::env::var("AIRLIGHT_PYTHON").unwrap_or_else(|_| "python3".into());
    if !python_usable(&python) {
        return;
    }
    let repo = repo();
    let crate_dir = repo.join("crates/airlight-py");
    let work = Path::new(env!("CARGO_TARGET_TMPDIR")).join("python");
    let venv = work.join("venv");
    let bin = venv.join("bin");
    if !bin.join("python").exists() {
        run("creating the virtual environment", Command::new(&python).arg("-m").arg("venv").arg(&venv));
    }
    // Already installed packages are not fetched again.
    run(
        "installing the build and test packages",
        Command::new(bin.join("python"))
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "-r"])
            .arg(crate_dir.join("tests/requirements.txt")),
    );

    // The wheel, as `maturin build` makes it for `pip install`, in a Cargo
    // target folder of its own (this test's Cargo holds the other), with
    // the workspace's `wheel-test` profile: release's, but quicker to build.
    let wheels = work.join("wheels");
    let _ = std::fs::remove_dir_all(&wheels);
    run(
        "maturin build",
        Command::new(bin.join("maturin"))
            .args(["build", "--profile", "wheel-test", "--quiet", "--manifest-path"])
            .arg(crate_dir.join("Cargo.toml"))
            .arg("--interpreter")
            .arg(bin.join("python"))
            .arg("--out")
            .arg(&wheels)
            .env("CARGO_TARGET_DIR", work.join("cargo")),
    );
    let built: Vec<PathBuf> = std::fs::read_dir(&wheels).unwrap().map(|e| e.unwrap().path()).collect();
    let [wheel] = built.as_slice() else { panic!("expected one wheel, maturin made {built:?}") };
    let name = wheel.file_name().unwrap().to_string_lossy();
    // abi3: one wheel for every CPython from 3.9 on.
    assert!(name.starts_with("airlight-") && name.contains("-cp39-abi3-"), "{name}");
    run(
        "installing the wheel",
        Command::new(bin.join("python"))
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--force-reinstall", "--no-deps"])
            .arg(wheel),
    );

    // pytest's report goes to this test's output as it runs.
    let mut pytest = Command::new(bin.join("python"))
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "-rfEs"])
        .arg(crate_dir.join("tests"))
        .current_dir(&work)
        .env("AIRLIGHT_BIN", env!("CARGO_BIN_EXE_airlight"))
        .env("AIRLIGHT_CI", "1")
        .env("MPLBACKEND", "Agg")
        .stdin(Stdio::null())
        .spawn()
        .expect("cannot start pytest");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = pytest.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > PYTEST_TIMEOUT {
            let _ = pytest.kill();
            panic!("pytest ran for more than {PYTEST_TIMEOUT:?}; stopped");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(status.success(), "pytest failed ({status}); its report is above");
}
