//! `airlight render --aov`: albedo, normals, depth and variance as layers
//! of the EXR output, with the channel names compositors read, checked by
//! reading the file back with the `exr` crate.

mod common;

use std::path::Path;
use std::process::{Command, Output};

fn airlight(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_airlight")).current_dir(dir).args(args).output().unwrap()
}

/// A grey floor at y = 0 seen from straight above at height 3, with a
/// sphere of another colour on it, under a point light.
const SCENE: &str = r#"
[render]
width = 16
height = 16
spp = 8
integrator = "path"
[camera]
position = [0, 3, 0]
look_at = [0, 0, 0]
up = [0, 0, 1]
fov = 40
[materials.grey]
albedo = [0.5, 0.5, 0.5]
[materials.blue]
albedo = [0.1, 0.2, 0.7]
[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "grey"
[[objects]]
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = "blue"
[[lights]]
type = "point"
position = [1, 2, 1]
intensity = 5
"#;

#[test]
fn aovs_are_layers_of_the_exr_with_standard_names() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), SCENE).unwrap();
    let run = airlight(
        dir.path(),
        &["render", "s.toml", "--aov", "albedo,normal,depth,variance", "-o", "out.exr", "-o", "out.png", "-q"],
    );
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let plain = airlight(dir.path(), &["render", "s.toml", "--progressive", "-o", "plain.exr", "-q"]);
    assert!(plain.status.success());
    let with = common::exr_channels(&dir.path().join("out.exr"));
    let mut names: Vec<&str> = with.keys().map(String::as_str).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "B",
            "G",
            "N.X",
            "N.Y",
            "N.Z",
            "R",
            "Z",
            "albedo.B",
            "albedo.G",
            "albedo.R",
            "variance.B",
            "variance.G",
            "variance.R"
        ]
    );
    // The image is the render's, AOVs or not.
    let without = common::exr_channels(&dir.path().join("plain.exr"));
    for c in ["R", "G", "B"] {
        assert_eq!(with[c], without[c], "channel {c}");
    }
    // The centre pixel sees the top of the sphere: its albedo, the normal
    // straight up, 2 away (its top is at y = 1). A corner sees the floor,
    // 3/cos θ away.
    let at = |name: &str, x: usize, y: usize| with[name][y * 16 + x];
    let (cx, cy) = (8, 8);
    assert!((at("albedo.B", cx, cy) - 0.7).abs() < 1e-5 && (at("albedo.R", cx, cy) - 0.1).abs() < 1e-5);
    // The pixel's mean normal: pixel (8, 8) covers a quarter-pixel-wide
    // square beside the axis, [0, 1) pixels off it in x and y, so its mean
    // n.y is that of the sphere's cap seen through it (about 0.989), not 1.
    let pixel = 2.0 * 20f64.to_radians().tan() / 16.0;
    let grid = 64;
    let mean_ny = (0..grid * grid)
        .map(|k| {
            let (a, b) =
                (((k % grid) as f64 + 0.5) / grid as f64 * pixel, ((k / grid) as f64 + 0.5) / grid as f64 * pixel);
            // Ray from (0, 3, 0) along (a, −1, b), normalised; sphere at
            // (0, 0.5, 0) of radius 0.5.
            let len = (a * a + 1.0 + b * b).sqrt();
            let d = [a / len, -1.0 / len, b / len];
            let oc_y = 2.5; // origin − centre, along y only
            let half_b = oc_y * d[1];
            let t = -half_b - (half_b * half_b - (oc_y * oc_y - 0.25)).sqrt();
            (3.0 + t * d[1] - 0.5) / 0.5
        })
        .sum::<f64>()
        / (grid * grid) as f64;
    assert!((at("N.Y", cx, cy) as f64 - mean_ny).abs() < 0.003, "{} against {mean_ny}", at("N.Y", cx, cy));
    assert!((at("Z", cx, cy) - 2.0).abs() < 0.02, "{}", at("Z", cx, cy));
    assert!((at("albedo.G", 0, 0) - 0.5).abs() < 1e-5);
    assert!(at("Z", 0, 0) > 3.0 && at("Z", 0, 0) < 3.0 / 20f32.to_radians().cos().powi(2));
    // Variance: finite, not negative, and not zero where the light is noisy.
    assert!(with["variance.R"].iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(with["variance.R"].iter().any(|v| *v > 0.0));

    // Refusals: no EXR output, an unknown name, a shard.
    let no_exr = airlight(dir.path(), &["render", "s.toml", "--aov", "albedo", "-o", "a.png", "-q"]);
    assert!(String::from_utf8_lossy(&no_exr.stderr).contains("give an output ending in .exr"));
    let unknown = airlight(dir.path(), &["render", "s.toml", "--aov", "albedo,colour", "-o", "a.exr", "-q"]);
    assert!(String::from_utf8_lossy(&unknown.stderr).contains("unknown AOV `colour`"));
    let shard = airlight(dir.path(), &["render", "s.toml", "--aov", "depth", "--shard", "0/2", "-o", "p.exr", "-q"]);
    assert!(String::from_utf8_lossy(&shard.stderr).contains("a shard or tile holds part of the samples"));
    assert!(!dir.path().join("a.exr").exists() && !dir.path().join("p.exr").exists());
}

#[test]
fn the_in_scattered_light_is_a_layer_for_single_scattering_integrators() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), SCENE).unwrap();
    let fog = ["--medium", "sigma_s=0.2,sigma_a=0.05", "--steps", "8", "--spp", "2", "-q"];
    let run = airlight(
        dir.path(),
        &[&["render", "s.toml", "--integrator", "raymarch", "--aov", "inscatter,depth", "-o", "fog.exr"], &fog[..]]
            .concat(),
    );
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let c = common::exr_channels(&dir.path().join("fog.exr"));
    let mut names: Vec<&str> = c.keys().map(String::as_str).collect();
    names.sort();
    assert_eq!(names, ["B", "G", "R", "Z", "inscatter.B", "inscatter.G", "inscatter.R"]);
    // Part of the image, never more; the floor's light is the rest.
    for (i, (&r, &s)) in c["R"].iter().zip(&c["inscatter.R"]).enumerate() {
        assert!(s > 0.0 && s <= r * (1.0 + 1e-5), "pixel {i}: image {r}, in-scattered {s}");
    }
    assert!(c["R"].iter().zip(&c["inscatter.R"]).any(|(r, s)| r - s > 0.01), "no surface light left");
    let path = airlight(
        dir.path(),
        &[&["render", "s.toml", "--integrator", "path", "--aov", "inscatter", "-o", "p.exr"], &fog[..]].concat(),
    );
    let err = String::from_utf8_lossy(&path.stderr);
    assert!(err.contains("the inscatter AOV: the path integrator does not separate the medium's light"), "{err}");
    assert!(!dir.path().join("p.exr").exists());
}
