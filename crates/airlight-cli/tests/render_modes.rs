//! `airlight render` with --frames (light animation), --target-error,
//! --variance, --adaptive and --reuse.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn airlight(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_airlight")).current_dir(dir).args(args).output().unwrap()
}

fn scene(name: &str) -> String {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    path.to_str().unwrap().to_string()
}

fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    names
}

#[test]
fn frames_are_numbered_and_follow_the_moving_lights() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("room_moving_lights.toml");
    let size = ["--width", "32", "--height", "24", "--spp", "2", "--quiet"];
    let run = airlight(dir.path(), &[&["render", &scene, "--frames", "3", "-o", "room.exr"][..], &size].concat());
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert_eq!(names(dir.path()), ["room_0000.exr", "room_0001.exr", "room_0002.exr"]);
    let frames: Vec<Vec<u8>> =
        (0..3).map(|k| std::fs::read(dir.path().join(format!("room_{k:04}.exr"))).unwrap()).collect();
    // The lights move, so every frame differs from the others.
    assert!(frames[0] != frames[1] && frames[1] != frames[2] && frames[0] != frames[2]);
    // Frame 0 is the animation at time 0, rendered again the same way.
    let again = airlight(dir.path(), &[&["render", &scene, "--frames", "1", "-o", "again.exr"][..], &size].concat());
    assert!(again.status.success());
    assert!(std::fs::read(dir.path().join("again_0000.exr")).unwrap() == frames[0]);
}

#[test]
fn frames_of_a_still_scene_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = airlight(dir.path(), &["render", &scene("glow.toml"), "--frames", "4", "--quiet"]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("no light with keyframes"));
    assert!(names(dir.path()).is_empty());
}

#[test]
fn target_error_stops_early_and_writes_the_variance() {
    let dir = tempfile::tempdir().unwrap();
    let run = airlight(
        dir.path(),
        &[
            "render",
            "--width",
            "48",
            "--height",
            "36",
            "--spp",
            "4096",
            "--target-error",
            "0.1",
            "--variance",
            "var.exr",
            "-o",
            "demo.exr",
        ],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert_eq!(names(dir.path()), ["demo.exr", "var.exr"]);
    // "N spp, estimated relative error E": stopped before 4096 with E < 0.1.
    let line = stderr.lines().find(|l| l.contains("estimated relative error")).expect("a summary line");
    let spp: u32 = line.split(" spp").next().unwrap().trim().parse().unwrap();
    let error: f64 = line.rsplit(' ').next().unwrap().parse().unwrap();
    assert!(spp < 4096 && error < 0.1, "{line}");
}

#[test]
fn bad_convergence_options_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["render", "--target-error", "0"][..],
        &["render", "--target-error", "-0.1"],
        &["render", "--target-error", "nan"],
        &["render", "--variance", "var.png"],
        &["render", "--variance", "var.exr", "--spp", "1"],
        &["render", "--frames", "0"],
    ] {
        let out = airlight(dir.path(), args);
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(!out.stderr.is_empty());
    }
    assert!(names(dir.path()).is_empty(), "nothing written");
}

#[test]
fn an_interrupted_progressive_render_resumes_to_the_uninterrupted_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/spheres_spot_fog.toml");
    let scene = scene.to_str().unwrap();
    let args = ["render", scene, "--integrator", "path", "--width", "48", "--height", "36", "--spp", "256"];
    let whole = airlight(d, &[&args[..], &["--progressive", "-o", "whole.exr", "--quiet"]].concat());
    assert!(whole.status.success(), "{}", String::from_utf8_lossy(&whole.stderr));
    assert!(!d.join("whole.partial.exr").exists(), "a finished render leaves no state behind");
    // Killed once its state holds some samples: mid-render, at no chosen point.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_airlight"))
        .current_dir(d)
        .args([&args[..], &["--progressive", "-o", "cut.exr", "--quiet"]].concat())
        .spawn()
        .unwrap();
    let state = d.join("cut.partial.exr");
    let start = std::time::Instant::now();
    while !state.exists() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success(), "the render was stopped before it finished");
    assert!(state.exists());
    let resumed = airlight(d, &[&args[..], &["--progressive", "--resume", "-o", "cut.exr"]].concat());
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(resumed.status.success(), "{stderr}");
    assert!(stderr.contains("resuming from"), "{stderr}");
    assert_eq!(std::fs::read(d.join("cut.exr")).unwrap(), std::fs::read(d.join("whole.exr")).unwrap());
    assert!(!state.exists());
    // A state of another render is refused.
    let other = airlight(d, &[&args[..], &["--progressive", "-o", "x.exr", "--quiet"]].concat());
    assert!(other.status.success());
    std::fs::copy(d.join("whole.exr"), d.join("y.partial.exr")).unwrap();
    let refused = airlight(d, &[&args[..], &["--progressive", "--resume", "-o", "y.exr"]].concat());
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("not an Airlight partial render"));
    // Resuming a finished render would replace it pass by pass: refused.
    let finished = std::fs::read(d.join("whole.exr")).unwrap();
    let again = airlight(d, &[&args[..], &["--progressive", "--resume", "-o", "whole.exr", "--quiet"]].concat());
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(!again.status.success() && stderr.contains("the render finished"), "{stderr}");
    assert_eq!(std::fs::read(d.join("whole.exr")).unwrap(), finished);
    // The checkpoint may be no output and no input.
    let small = ["--quiet"];
    for (extra, phrase) in [
        (&["-o", "p.exr", "-o", "p.partial.exr"][..], "is where the passes keep their samples"),
        (&["-o", "q.exr", "--variance", "q.partial.exr"][..], "is where the passes keep their samples"),
    ] {
        let run = airlight(d, &[&args[..], &["--progressive"], extra, &small].concat());
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success() && stderr.contains(phrase), "{extra:?}: {stderr}");
    }
    std::fs::copy(scene, d.join("a.partial.exr")).unwrap();
    let run = airlight(d, &["render", "a.partial.exr", "--progressive", "-o", "a.exr", "--spp", "2", "--quiet"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && stderr.contains("would replace an input"), "{stderr}");
    assert_eq!(std::fs::read(d.join("a.partial.exr")).unwrap(), std::fs::read(scene).unwrap());
}

#[test]
fn adaptive_sampling_renders_in_one_go_and_refuses_passes_and_parts() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cornell = scene("compare_cornell.toml");
    let small = ["--width", "24", "--height", "16", "--spp", "16"];
    let out = airlight(d, &[&["render", &cornell, "--adaptive", "-o", "a.exr", "--quiet"][..], &small].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // The same counts and samples whatever the thread count.
    let out = airlight(
        d,
        &[&["render", &cornell, "--adaptive", "--threads", "1", "-o", "b.exr", "--quiet"][..], &small].concat(),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(std::fs::read(d.join("a.exr")).unwrap(), std::fs::read(d.join("b.exr")).unwrap());
    for extra in [
        &["--progressive"][..],
        &["--target-error", "0.1"],
        &["--variance", "v.exr"],
        &["--shard", "0/2"],
        &["--tile", "0/2"],
    ] {
        let args = [&["render", &cornell, "--adaptive", "-o", "p.exr"][..], &small, extra].concat();
        let out = airlight(d, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains("renders in one go"), "{extra:?}: {stderr}");
    }
    let fog = ["--integrator", "raymarch", "--aov", "inscatter"];
    let args = [&["render", &cornell, "--adaptive", "-o", "p.exr"][..], &small, &fog].concat();
    let out = airlight(d, &args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("does not go with adaptive"), "{stderr}");
    assert_eq!(names(d), ["a.exr", "b.exr"], "nothing else written");
}

#[test]
fn reuse_comes_from_the_flag_or_the_scene_file_and_a_bad_value_is_placed() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("compare_cornell.toml");
    let size = ["--width", "24", "--height", "16", "--spp", "4", "--quiet"];
    let render = |args: &[&str], out: &str| {
        let run = airlight(dir.path(), &[&["render"][..], args, &size, &["-o", out]].concat());
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        std::fs::read(dir.path().join(out)).unwrap()
    };
    let plain = render(&[&cornell], "plain.exr");
    let flag = render(&[&cornell, "--reuse"], "flag.exr");
    let text = std::fs::read_to_string(&cornell).unwrap().replace("[render]\n", "[render]\nreuse = true\n");
    std::fs::write(dir.path().join("reuse.toml"), &text).unwrap();
    let file = render(&["reuse.toml"], "file.exr");
    // The same pixels either way, and not the plain path tracer's.
    assert!(flag == file && flag != plain);
    let bad = text.replace("reuse = true", "reuse = \"yes\"");
    std::fs::write(dir.path().join("bad.toml"), bad).unwrap();
    let run = airlight(dir.path(), &[&["render", "bad.toml"][..], &size].concat());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success() && stderr.contains("bad.toml:5") && stderr.contains("render.reuse must be true or false"),
        "{stderr}"
    );
}
