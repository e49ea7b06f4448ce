//! `airlight render` with the stochastic integrator's options.

mod common;

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

/// A point light in open fog, seen from 6 units away: rays pass it within a
/// fraction of a unit, where drawing the point on the ray uniformly over
/// its 100 units is far noisier than drawing it by angle.
const POINT_IN_FOG: &str = r#"
[render]
width = 24
height = 16
integrator = "stochastic"
spp = 32
[camera]
position = [0, 0, -6]
look_at = [0, 0, 0]
fov = 50
[medium]
sigma_a = 0.01
sigma_s = 0.1
[[lights]]
type = "point"
position = [0.3, 0.2, 0]
intensity = 10
"#;

#[test]
fn sampling_option_is_checked_and_each_choice_is_unbiased_with_its_own_noise() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("fog.toml"), POINT_IN_FOG).unwrap();
    let bad = airlight(dir.path(), &["render", "fog.toml", "--sampling", "importance", "-q"]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("possible values: uniform, equiangular, mis"));
    // Each sampling: the image's sum over pixels and the variance of that
    // sum (the per-pixel variances of the means, from independent samples).
    let mut sums = Vec::new();
    for sampling in ["uniform", "equiangular", "mis"] {
        let (image, variance) = (format!("{sampling}.exr"), format!("{sampling}.var.exr"));
        let args = ["render", "fog.toml", "--sampling", sampling, "--no-stratify", "-q", "-o", &image, "--variance"];
        let run = airlight(dir.path(), &[&args[..], &[&variance]].concat());
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let sum: f64 = common::exr_channels(&dir.path().join(&image))["R"].iter().map(|&v| v as f64).sum();
        let var: f64 = common::exr_channels(&dir.path().join(&variance))["R"].iter().map(|&v| v as f64).sum();
        assert!(sum > 0.0 && var > 0.0, "{sampling}: {sum} {var}");
        sums.push((sampling, sum, var));
    }
    // Three estimators of one integral: their images agree within their
    // noise (a z-score of the difference of sums under 5)...
    for (i, a) in sums.iter().enumerate() {
        for b in &sums[i + 1..] {
            let z = (a.1 - b.1) / (a.2 + b.2).sqrt();
            assert!(z.abs() < 5.0, "{} against {}: z = {z} ({sums:?})", a.0, b.0);
        }
    }
    // ...and the option is heard: sampling by angle near the light is far
    // less noisy than sampling the 100-unit ray uniformly.
    let (uniform, equiangular) = (sums[0].2, sums[1].2);
    assert!(uniform > 4.0 * equiangular, "variance: uniform {uniform}, equiangular {equiangular}");
}
