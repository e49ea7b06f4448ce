//! `airlight render` with the stochastic integrator's options.

use std::path::Path;
use std::process::{Command, Output};

fn airlight(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_airlight")).current_dir(dir).args(args).output().unwrap()
}

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/sdf_isometric.toml").to_str().unwrap().to_string()
}

#[test]
fn progressive_render_writes_the_image_and_matches_the_plain_one() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let common = ["render", &scene, "--width", "40", "--height", "30", "--spp", "8", "--quiet"];
    let plain = airlight(dir.path(), &[&common[..], &["-o", "plain.exr"]].concat());
    let progressive =
        airlight(dir.path(), &[&common[..], &["--progressive", "-o", "prog.exr", "-o", "prog.png"]].concat());
    assert!(plain.status.success() && progressive.status.success(), "{}", String::from_utf8_lossy(&progressive.stderr));
    // Nothing temporary is left behind; both outputs are whole.
    let mut names: Vec<String> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["plain.exr", "prog.exr", "prog.png"]);
    let cmp = airlight(dir.path(), &["compare", "prog.exr", "plain.exr"]);
    let text = String::from_utf8_lossy(&cmp.stdout);
    let max: f64 = text.lines().find_map(|l| l.strip_prefix("max: ")).unwrap().trim().parse().unwrap();
    assert!(max < 1e-3, "{text}");
}

#[test]
fn sampling_option_is_checked_and_changes_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let common = ["render", &scene, "--width", "24", "--height", "16", "--spp", "2", "--quiet"];
    let bad = airlight(dir.path(), &[&common[..], &["--sampling", "importance"]].concat());
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("expected uniform, equiangular or mis"));
    for (sampling, out) in [("uniform", "u.exr"), ("mis", "m.exr")] {
        let run = airlight(dir.path(), &[&common[..], &["--sampling", sampling, "--no-stratify", "-o", out]].concat());
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    }
    let a = std::fs::read(dir.path().join("u.exr")).unwrap();
    let b = std::fs::read(dir.path().join("m.exr")).unwrap();
    assert!(a != b);
}
