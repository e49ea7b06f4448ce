//! `airlight render --shard/--tile/--frame` and `airlight merge` as a render
//! farm runs them: the merged image is the single render's file, byte for
//! byte, and a set of parts that is not one whole render is refused, with
//! what is wrong named and nothing written.

use std::path::Path;
use std::process::{Command, Output};

fn airlight(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_airlight")).current_dir(dir).args(args).output().unwrap()
}

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/spheres_spot_fog.toml").display().to_string()
}

const SIZE: [&str; 8] = ["--width", "40", "--height", "30", "--spp", "6", "--steps", "16"];

fn render(dir: &Path, extra: &[&str]) {
    let scene = scene();
    let out = airlight(dir, &[&["render", &scene, "--quiet"], &SIZE[..], extra].concat());
    assert!(out.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&out.stderr));
}

fn merge_fails(dir: &Path, parts: &[&str], phrase: &str) {
    let out = airlight(dir, &[&["merge"], parts, &["-o", "out.exr"]].concat());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{parts:?} merged");
    assert!(stderr.contains(phrase), "{parts:?}: `{stderr}` lacks `{phrase}`");
    assert!(!dir.join("out.exr").exists(), "{parts:?}: an output was written");
}

#[test]
fn shards_and_tiles_merge_to_the_single_render_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, &["-o", "single.exr"]);
    for k in 0..3 {
        for t in 0..2 {
            render(d, &["--shard", &format!("{k}/3"), "--tile", &format!("{t}/2"), "-o", &format!("p{k}{t}.exr")]);
        }
    }
    let parts: Vec<String> = (0..6).map(|i| format!("p{}{}.exr", i / 2, i % 2)).collect();
    let parts: Vec<&str> = parts.iter().map(String::as_str).collect();
    let out = airlight(d, &[&["merge"], &parts[..], &["-o", "merged.exr", "--quiet"]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(std::fs::read(d.join("merged.exr")).unwrap(), std::fs::read(d.join("single.exr")).unwrap());
}

#[test]
fn a_frame_alone_is_the_frame_of_the_whole_animation() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell_box.toml").display().to_string();
    let small = ["--width", "24", "--height", "24", "--spp", "2", "--quiet"];
    let all = airlight(d, &[&["render", &cornell, "--frames", "3", "-o", "all.exr"], &small[..]].concat());
    assert!(all.status.success(), "{}", String::from_utf8_lossy(&all.stderr));
    let one =
        airlight(d, &[&["render", &cornell, "--frames", "3", "--frame", "2", "-o", "one.exr"], &small[..]].concat());
    assert!(one.status.success(), "{}", String::from_utf8_lossy(&one.stderr));
    assert!(!d.join("one_0000.exr").exists() && !d.join("one_0001.exr").exists());
    assert_eq!(std::fs::read(d.join("one_0002.exr")).unwrap(), std::fs::read(d.join("all_0002.exr")).unwrap());
    let bad =
        airlight(d, &[&["render", &cornell, "--frames", "3", "--frame", "3", "-o", "x.exr"], &small[..]].concat());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("frames 0 to 2"));
}

#[test]
fn merge_refuses_parts_that_are_not_one_whole_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for k in 0..3 {
        render(d, &["--shard", &format!("{k}/3"), "-o", &format!("s{k}.exr")]);
    }
    render(d, &["--shard", "0/2", "-o", "half.exr"]);
    render(d, &["--shard", "2/3", "--seed", "5", "-o", "seed.exr"]);
    render(d, &["--shard", "2/3", "--attenuation", "sphere", "-o", "scene.exr"]);
    let scene = scene();
    let size = ["--width", "41", "--height", "30", "--spp", "6", "--steps", "16", "--shard", "2/3", "--quiet"];
    assert!(airlight(d, &[&["render", &scene, "-o", "size.exr"], &size[..]].concat()).status.success());
    render(d, &["-o", "plain.exr"]);
    let whole = std::fs::read(d.join("s2.exr")).unwrap();
    std::fs::write(d.join("truncated.exr"), &whole[..whole.len() / 2]).unwrap();

    merge_fails(d, &["s0.exr", "s1.exr"], "samples 4..6 of rows 0..30 are in no part");
    merge_fails(d, &["s0.exr", "s1.exr", "s2.exr", "half.exr"], "both hold samples 0..2 of rows 0..30");
    merge_fails(d, &["s0.exr", "s1.exr", "seed.exr"], "seed 5 and 0");
    merge_fails(d, &["s0.exr", "s1.exr", "scene.exr"], "scene fingerprint");
    merge_fails(d, &["s0.exr", "s1.exr", "size.exr"], "size 41×30 and 40×30");
    merge_fails(d, &["s0.exr", "s1.exr", "truncated.exr"], "truncated.exr: ");
    merge_fails(d, &["s0.exr", "s1.exr", "plain.exr"], "plain.exr: not an Airlight partial render");
    merge_fails(d, &["s0.exr", "s1.exr", "missing.exr"], "missing.exr: ");
    // And with all three: merged.
    let out = airlight(d, &["merge", "s0.exr", "s1.exr", "s2.exr", "-o", "out.exr", "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn shard_and_tile_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scene();
    for (extra, phrase) in [
        (&["--shard", "3/3", "-o", "p.exr"][..], "is not K/N"),
        (&["--shard", "1/7", "-o", "p.exr"][..], "only 6 samples per pixel"),
        (&["--tile", "0/2", "-o", "p.png"][..], "give one `-o PART.exr`"),
        (&["--shard", "0/2", "--progressive", "-o", "p.exr"][..], "does not go with passes"),
    ] {
        let out = airlight(d, &[&["render", &scene], &SIZE[..], extra].concat());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(phrase), "{extra:?}: {stderr}");
    }
}

#[test]
fn farm_logs_get_plain_progress_lines_when_stderr_is_not_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let out = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .current_dir(dir.path())
        .env("AIRLIGHT_PROGRESS_SECONDS", "0")
        .args([&["render", &scene, "-o", "a.exr"], &SIZE[..]].concat())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let line = stderr.lines().find(|l| l.starts_with("airlight: ")).unwrap_or_else(|| panic!("{stderr}"));
    assert!(line.contains('%') && line.contains("samples/s") && line.contains("left"), "{line}");
}
