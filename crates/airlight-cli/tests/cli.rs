//! The `airlight` command as a user runs it.

use std::path::Path;
use std::process::{Command, Output};

fn airlight(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_airlight")).current_dir(dir).args(args).output().unwrap()
}

fn scenes() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

#[test]
fn render_with_no_arguments_writes_the_demo_to_airlight_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = airlight(dir.path(), &["render", "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let png = image_size(&dir.path().join("airlight.png"));
    assert_eq!(png, (640, 480));
}

/// Width and height from a PNG's IHDR chunk.
fn image_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn thread_count_does_not_change_a_single_byte() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scenes().join("demo.toml");
    let scene = scene.to_str().unwrap();
    let common = ["render", scene, "--width", "96", "--height", "64", "--spp", "2", "--quiet"];
    let one = airlight(dir.path(), &[&common[..], &["--threads", "1", "-o", "one.exr"]].concat());
    let two = airlight(dir.path(), &[&common[..], &["--threads", "2", "-o", "two.exr"]].concat());
    assert!(one.status.success() && two.status.success());
    let a = std::fs::read(dir.path().join("one.exr")).unwrap();
    let b = std::fs::read(dir.path().join("two.exr")).unwrap();
    assert!(a.len() > 1000);
    assert!(a == b, "EXR bytes differ between --threads 1 and --threads 2");
}

#[test]
fn compare_prints_the_four_measures_and_a_map() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scenes().join("spot_spheres.toml");
    let scene = scene.to_str().unwrap();
    for (seed, name) in [("1", "a.exr"), ("2", "b.exr")] {
        let out = airlight(
            dir.path(),
            &["render", scene, "--width", "48", "--height", "32", "--spp", "1", "--seed", seed, "-o", name, "-q"],
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let out = airlight(dir.path(), &["compare", "a.exr", "b.exr", "--map", "map.png"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for key in ["rmse: ", "rel_mse: ", "mae: ", "max: "] {
        let line = text.lines().find(|l| l.starts_with(key)).unwrap_or_else(|| panic!("no `{key}` in {text}"));
        let value: f64 = line[key.len()..].parse().unwrap();
        assert!(value.is_finite() && value >= 0.0);
    }
    assert!(dir.path().join("map.png").exists());
    // An image against itself: all zero.
    let same = String::from_utf8(airlight(dir.path(), &["compare", "a.exr", "a.exr"]).stdout).unwrap();
    assert!(same.contains("rmse: 0\n") && same.contains("max: 0\n"), "{same}");
}

#[test]
fn a_bad_scene_names_file_line_and_column_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.toml"),
        "[render]\nwidth = 64\n\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -2\nmaterial = \"m\"\n",
    )
    .unwrap();
    let out = airlight(dir.path(), &["render", "bad.toml", "-o", "bad.png"]);
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("bad.toml:7:10: objects[0] (sphere).radius must be a positive finite number, got -2"),
        "{err}"
    );
    assert!(!dir.path().join("bad.png").exists());
    let info = airlight(dir.path(), &["info", "bad.toml"]);
    assert!(!info.status.success());
}

#[test]
fn bad_options_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["render", "--width", "0"][..],
        &["render", "--integrator", "magic"],
        &["render", "-o", "out.jpg"],
        &["render", "missing.toml"],
        &["compare", "nothing.exr", "none.exr"],
    ] {
        let out = airlight(dir.path(), args);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(!out.stderr.is_empty());
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written");
}

#[test]
fn info_describes_a_scene() {
    let out = airlight(&scenes(), &["info", "spot_spheres.toml"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("640×480") && text.contains("lights: 1"), "{text}");
    // An emitting mesh is counted with its power: Blender's 1 m² lamp of
    // radiance 4 sends out π × 1 m² × 4 = 12.566 W from its side.
    let out = airlight(&scenes(), &["info", "models/blender_room.glb"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("2 triangles of emitting meshes, sending out [12.5664, 12.5664, 12.5664] W in all"),
        "{text}"
    );
}

#[test]
fn medium_puts_fog_into_a_gltf_as_a_scene_file_would() {
    // The Blender-exported glTF with --medium, against the same file
    // included by a scene file that says [medium]: the same image, byte
    // for byte; without the option, a different one.
    let dir = tempfile::tempdir().unwrap();
    let models = scenes().join("models");
    std::fs::copy(models.join("blender_room.glb"), dir.path().join("room.glb")).unwrap();
    std::fs::write(
        dir.path().join("fog.toml"),
        "[render]\nwidth = 32\nheight = 24\n[medium]\nsigma_s = [0.05, 0.05, 0.1]\nsigma_a = 0.01\ng = 0.3\n\
         [[include]]\nfile = \"room.glb\"\n",
    )
    .unwrap();
    let common = ["--width", "32", "--height", "24", "--spp", "2", "--integrator", "raymarch", "--steps", "8", "-q"];
    let run = |args: &[&str]| {
        let out = airlight(dir.path(), &[&["render"], args, &common[..]].concat());
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    };
    run(&["room.glb", "--medium", "sigma_s=[0.05,0.05,0.1],sigma_a=0.01,g=0.3", "-o", "option.exr"]);
    run(&["fog.toml", "-o", "file.exr"]);
    run(&["room.glb", "-o", "clear.exr"]);
    run(&["fog.toml", "--medium", "none", "-o", "removed.exr"]);
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert!(read("option.exr") == read("file.exr"), "--medium and [medium] differ");
    assert!(read("option.exr") != read("clear.exr"), "--medium changed nothing");
    assert!(read("removed.exr") == read("clear.exr"), "--medium none left fog");
    // Checked by the scene file's rules.
    let out = airlight(dir.path(), &["render", "room.glb", "--medium", "sigma_s=0.1,g=1.5", "-o", "x.exr"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("medium.g must lie strictly between -1 and 1, got 1.5"), "{err}");
    assert!(!dir.path().join("x.exr").exists());
}
