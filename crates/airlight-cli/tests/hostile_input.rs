//! The hostile-input cases for the `airlight` command, as a careless or hostile
//! user meets them: outputs that would replace inputs or each other,
//! folders that are not there, sizes that do not fit, broken pixels and
//! pipes, values that make a run endless, scenes that can only be black.

use airlight::{Image, Rgb};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn airlight(dir: &Path, args: &[&str]) -> Output {
    airlight_env(dir, args, &[])
}

fn airlight_env(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_airlight"));
    c.current_dir(dir).args(args).env_remove("AIRLIGHT_ASSET_PATH").env_remove("AIRLIGHT_MEMORY_LIMIT");
    c.envs(env.iter().copied()).output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Fails unless the command exited with 1 and one `error:` line holding `phrase`, and no panic.
fn refused(out: &Output, phrase: &str) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: ") && err.contains(phrase), "expected «{phrase}», got: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

fn scene_text(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name)).unwrap()
}

/// A small scene in `dir` under `name`.
fn small_scene(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, scene_text("spot_spheres.toml")).unwrap();
    path
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

const SMALL: [&str; 7] = ["--width", "8", "--height", "6", "--spp", "1", "-q"];

#[test]
fn render_never_replaces_its_scene_or_writes_two_outputs_to_one_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = scene_text("spot_spheres.toml");
    small_scene(d, "foo.png");
    small_scene(d, "s.exr");
    // `render foo.png` would write foo.png (its default output) over itself.
    refused(&airlight(d, &[&["render", "foo.png"][..], &SMALL].concat()), "-o `foo.png` would replace an input");
    refused(&airlight(d, &[&["render", "s.exr", "-o", "s.exr"][..], &SMALL].concat()), "would replace an input");
    let same = ["render", "s.exr", "-o", "x.png", "-o", "./x.png"];
    refused(&airlight(d, &[&same[..], &SMALL].concat()), "-o `x.png` and -o `./x.png` are the same file");
    let variance = ["render", "s.exr", "-o", "X.exr", "--variance", "X.exr", "--spp", "2"];
    refused(
        &airlight(d, &[&variance[..], &SMALL[..4]].concat()),
        "-o `X.exr` and --variance `X.exr` are the same file",
    );
    assert_eq!(std::fs::read_to_string(d.join("foo.png")).unwrap(), original);
    assert_eq!(std::fs::read_to_string(d.join("s.exr")).unwrap(), original);
    assert_eq!(files(d), ["foo.png", "s.exr"], "nothing written");
}

#[test]
fn frames_written_into_a_folder_never_replace_an_input() {
    // A scene file named as the first frame, in the folder the frames go to.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = scene_text("cornell_box.toml");
    std::fs::write(d.join("frame_0000.png"), &original).unwrap();
    let gi = airlight(d, &["gi", "frame_0000.png", "--frames", "2", "--output-dir", "."]);
    refused(&gi, "--output-dir `.`: its `frame_0000.png` would replace an input");
    std::fs::write(d.join("frame_0001.exr"), &original).unwrap();
    let view = ["view", "frame_0001.exr", "--headless", "--frames", "3", "--out", ".", "--width", "8", "--height", "6"];
    refused(&airlight(d, &view), "--out `.`: its `frame_0001.exr` would replace an input");
    assert_eq!(std::fs::read_to_string(d.join("frame_0000.png")).unwrap(), original);
    assert_eq!(std::fs::read_to_string(d.join("frame_0001.exr")).unwrap(), original);
    assert_eq!(files(d), ["frame_0000.png", "frame_0001.exr"], "nothing written");
}

/// Runs `args` for at most `limit`; the output, or None if it had to be killed.
fn bounded(dir: &Path, args: &[&str], limit: Duration) -> Option<Output> {
    let mut child: Child = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Some(child.wait_with_output().unwrap())
}

#[test]
fn output_folders_are_checked_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_scene(d, "s.toml");
    std::fs::create_dir(d.join("locked")).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(d.join("locked"), std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root writes into read-only folders: then there is nothing to refuse.
    let root = std::fs::write(d.join("locked/probe"), "").is_ok();
    // A render that would take hours: refused at once, or the test times out.
    let endless = ["render", "s.toml", "--spp", "16777216", "-q"];
    for (out, phrase) in
        [("missing/a.png", "cannot write -o `missing/a.png`: the folder `missing`"), ("locked/a.png", "the folder")]
    {
        if root && out.starts_with("locked") {
            continue;
        }
        let run = bounded(d, &[&endless[..], &["-o", out]].concat(), Duration::from_secs(60));
        refused(&run.unwrap_or_else(|| panic!("-o {out}: the render started")), phrase);
    }
}

#[test]
fn an_output_that_is_a_link_is_replaced_not_followed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_scene(d, "s.toml");
    std::fs::write(d.join("precious"), "keep me").unwrap();
    std::os::unix::fs::symlink(d.join("precious"), d.join("out.png")).unwrap();
    let out = airlight(d, &[&["render", "s.toml", "-o", "out.png"][..], &SMALL].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(d.join("precious")).unwrap(), "keep me");
    assert!(!std::fs::symlink_metadata(d.join("out.png")).unwrap().file_type().is_symlink());
    assert_eq!(files(d), ["out.png", "precious", "s.toml"], "no temporary file left");
}

#[test]
fn compare_refuses_broken_pixels_and_oversized_headers_without_aborting() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut image = Image::new(4, 3);
    image.save(d.join("a.exr")).unwrap();
    image.pixels[5] = Rgb::new(f32::NAN, 0.0, 0.0);
    image.save(d.join("nan.exr")).unwrap();
    let out = airlight(d, &["compare", "nan.exr", "a.exr"]);
    refused(&out, "`nan.exr` has 1 pixel that are not finite numbers (NaN or infinite), the first at (1, 1)");
    assert!(!String::from_utf8_lossy(&out.stdout).contains("max: 0"));
    // A 1×1 file whose header claims 100000×100000 pixels.
    std::fs::write(d.join("huge.exr"), exr_claiming(d, 100_000, 100_000)).unwrap();
    refused(&airlight(d, &["compare", "huge.exr", "a.exr"]), "declares 100000×100000 pixels; at most 65536 on a side");
    // The map may not replace an input.
    refused(&airlight(d, &["compare", "a.exr", "a.exr", "--map", "a.exr"]), "--map `a.exr` would replace an input");
}

fn exr_claiming(dir: &Path, w: i32, h: i32) -> Vec<u8> {
    let path = dir.join("one.exr");
    Image::new(1, 1).save(&path).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    for name in [&b"dataWindow\0box2i\0"[..], b"displayWindow\0box2i\0"] {
        let at = bytes.windows(name.len()).position(|x| x == name).unwrap() + name.len() + 4;
        bytes[at + 8..at + 12].copy_from_slice(&(w - 1).to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&(h - 1).to_le_bytes());
    }
    bytes
}

#[test]
fn attenuation_at_the_ends_of_f32_fails_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    for (args, phrase) in [
        (&["--radius", "1e-20"][..], "--intensity / --radius² = 1.000e41"),
        (&["--intensity", "1e38", "--radius", "0.1"], "is out of the range of 32-bit floats"),
        (&["--cutoff", "1e-45"], "no curve reaches zero at a finite distance"),
    ] {
        refused(&airlight(dir.path(), &[&["attenuation"][..], args].concat()), phrase);
    }
    // Tiny but representable: plotted, axis labels and all.
    let out = airlight(dir.path(), &["attenuation", "--radius", "1e-8", "--intensity", "1e-10", "--cutoff", "1e-20"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("attenuation.png").exists());
}

#[test]
fn info_into_a_closed_pipe_ends_quietly() {
    use std::os::fd::FromRawFd;
    use std::os::unix::process::ExitStatusExt;
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/room_moving_lights.toml");
    // As `| head -0`: the pipe's reading end is closed before the child
    // starts, so its first write meets a closed pipe (closing it after the
    // spawn raced a quick child, which could finish writing first).
    let mut fds = [0; 2];
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
    let (read_end, write_end) =
        unsafe { (std::os::fd::OwnedFd::from_raw_fd(fds[0]), std::os::fd::OwnedFd::from_raw_fd(fds[1])) };
    drop(read_end);
    let child = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .args(["info", scene.to_str().unwrap()])
        .stdout(Stdio::from(write_end))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.signal(), Some(13), "killed by SIGPIPE, as `cat` would be: {:?}", out.status);
    assert_eq!(stderr(&out), "", "no panic, no message");
}

#[test]
fn sizes_that_do_not_fit_in_memory_are_refused_with_size_and_limit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_scene(d, "s.toml");
    let limit = [("AIRLIGHT_MEMORY_LIMIT", "64M")];
    let out = airlight_env(d, &["render", "s.toml", "--width", "4096", "--height", "4096", "-q"], &limit);
    refused(&out, "a 4096×4096 render needs about 384.0 MiB, more than the 64.0 MiB of AIRLIGHT_MEMORY_LIMIT");
    // A part of a render keeps every pixel's sums; passes the images too.
    let out = airlight_env(
        d,
        &["render", "s.toml", "--width", "4096", "--height", "4096", "--shard", "0/2", "-o", "p.exr", "-q"],
        &limit,
    );
    refused(&out, "a 4096×4096 render needs about 2.1 GiB, more than the");
    let out =
        airlight_env(d, &["render", "s.toml", "--width", "4096", "--height", "4096", "--progressive", "-q"], &limit);
    refused(&out, "a 4096×4096 render needs about 2.5 GiB, more than the");
    // The largest image allowed, in passes, needs more than most machines have.
    let out = airlight_env(
        d,
        &["render", "s.toml", "--width", "16384", "--height", "16384", "--progressive", "-q"],
        &[("AIRLIGHT_MEMORY_LIMIT", "32G")],
    );
    refused(&out, "a 16384×16384 render needs about 40.0 GiB, more than the");
    // A mesh counted before it is read.
    std::fs::write(d.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_string() + &"f 1 2 3\n".repeat(1000)).unwrap();
    let mesh = "[materials.m]\n[[objects]]\ntype = \"mesh\"\nfile = \"m.obj\"\nmaterial = \"m\"\n";
    std::fs::write(d.join("mesh.toml"), mesh).unwrap();
    let out = airlight_env(d, &["info", "mesh.toml"], &[("AIRLIGHT_MEMORY_LIMIT", "16K")]);
    refused(&out, "mesh.toml:4:8: objects[0] (mesh): cannot load mesh");
    assert!(stderr(&out).contains("the scene's meshes (1000 triangles in this one) needs about 93.8 KiB"));
    assert!(airlight_env(d, &["info", "mesh.toml"], &[]).status.success());
    // Radiosity's patches.
    let cornell = d.join("cornell.toml");
    std::fs::write(&cornell, scene_text("cornell_box.toml")).unwrap();
    let out = airlight_env(d, &["gi", "cornell.toml", "--frames", "1", "--patch-size", "0.02"], &limit);
    refused(&out, "radiosity: compiling about");
    assert!(stderr(&out).contains("more than the 64.0 MiB of AIRLIGHT_MEMORY_LIMIT"));
}

#[test]
fn a_texture_is_counted_before_it_is_decoded() {
    // 2048² pixels of 16-bit RGBA: a few kilobytes of PNG that decode to
    // 32 MiB. Under a 16 MiB limit it is refused before the decoder
    // allocates, with what it would take.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    image::ImageBuffer::<image::Rgba<u16>, Vec<u16>>::new(2048, 2048).save(d.join("big.png")).unwrap();
    assert!(std::fs::metadata(d.join("big.png")).unwrap().len() < 1 << 20);
    let scene = "[materials.t]\ntype = \"texture\"\nfile = \"big.png\"\n\
                 [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"t\"\n";
    std::fs::write(d.join("t.toml"), scene).unwrap();
    let out = airlight_env(d, &["info", "t.toml"], &[("AIRLIGHT_MEMORY_LIMIT", "16M")]);
    refused(&out, "decoding a 2048×2048 texture needs about");
    assert!(airlight_env(d, &["info", "t.toml"], &[("AIRLIGHT_MEMORY_LIMIT", "256M")]).status.success());
}

#[test]
fn a_memory_limit_that_is_not_a_size_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_scene(d, "s.toml");
    for value in ["abc", "-1", "1P", "NaN", "", "12 apples"] {
        let out = airlight_env(d, &["info", "s.toml"], &[("AIRLIGHT_MEMORY_LIMIT", value)]);
        refused(&out, &format!("AIRLIGHT_MEMORY_LIMIT={value:?} is not a size"));
    }
    assert!(airlight_env(d, &["info", "s.toml"], &[("AIRLIGHT_MEMORY_LIMIT", "512M")]).status.success());
}

#[test]
fn bounds_name_the_real_limit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_scene(d, "s.toml");
    let cases: [(&[&str], &str); 6] = [
        (&["render", "s.toml", "--spp", "1099511627776"], "--spp must be an integer from 1 to 16777216"),
        (&["render", "s.toml", "--steps", "2097152"], "--steps must be an integer from 1 to 1048576"),
        (&["render", "s.toml", "--frames", "2000000"], "1..=1048576"),
        (&["gi", "s.toml", "--frames", "4294967295"], "1..=1048576"),
        (&["render", "s.toml", "--width", "100000"], "--width must be an integer from 1 to 65536"),
        (&["render", "s.toml", "--threads", "100000"], "1..=4096"),
    ];
    for (args, phrase) in cases {
        let out = airlight(d, args);
        let err = stderr(&out);
        assert!(out.status.code() == Some(2) && err.contains(phrase), "{args:?}: {err}");
    }
    std::fs::write(d.join("spp.toml"), "[render]\nspp = 1099511627776\n").unwrap();
    refused(&airlight(d, &["info", "spp.toml"]), "spp.toml:2:7: render.spp must be an integer from 1 to 16777216");
}

#[test]
fn a_run_that_would_take_hours_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    small_scene(dir.path(), "s.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .current_dir(dir.path())
        .args(["render", "s.toml", "--spp", "16777216", "--threads", "1", "-q"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let warning = lines.next().map(Result::unwrap).unwrap_or_default();
    let _ = child.kill();
    let _ = child.wait();
    assert!(
        warning
            .starts_with("warning: by a probe of 16 samples, this render (640×480 at 16777216 spp) will take about ")
    );
    assert!(warning.ends_with("(stop it with Ctrl-C)"), "{warning}");
}

#[test]
fn scenes_that_can_only_be_black_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dark = "[render]\nwidth = 8\nheight = 6\n[materials.m]\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 1, 0]\nradius = 1\nmaterial = \"m\"\n";
    std::fs::write(d.join("dark.toml"), dark).unwrap();
    let warning = "warning: the scene has no lights and a black background: the image will be black";
    let out = airlight(d, &["render", "dark.toml", "-q"]);
    assert!(out.status.success() && stderr(&out).contains(warning), "{}", stderr(&out));
    let out = airlight(d, &["gi", "dark.toml", "--frames", "2"]);
    assert!(out.status.success() && stderr(&out).contains(warning), "{}", stderr(&out));
    assert!(!stderr(&airlight(d, &[&["render"][..], &SMALL].concat())).contains("warning"), "the demo is lit");
}

#[test]
fn a_headless_path_through_the_camera_target_is_refused_with_frame_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = "[[camera]]\nframe = 0\nposition = [2.78, 2.7, -4]\nlook_at = [2.78, 2.7, 4]\n\n\
                [[camera]]\nframe = 40\nposition = [2.78, 2.7, 4]\nlook_at = [2.78, 2.7, -4]\n";
    std::fs::write(dir.path().join("fly.toml"), path).unwrap();
    let out = airlight(
        dir.path(),
        &["view", "--headless", "--path", "fly.toml", "--frames", "41", "--width", "8", "--height", "6"],
    );
    refused(
        &out,
        "fly.toml:7:9: between the camera keys at frames 0 and 40, the camera at frame 20 would stand on its look_at point",
    );
}

#[test]
fn meshes_are_found_in_asset_folders_named_by_airlight_asset_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("scene")).unwrap();
    std::fs::create_dir_all(d.join("assets")).unwrap();
    std::fs::write(d.join("assets/tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let text = "[materials.m]\n[[objects]]\ntype = \"mesh\"\nfile = \"tri.obj\"\nmaterial = \"m\"\n\
                [[lights]]\ntype = \"point\"\nposition = [0, 2, -2]\nintensity = 1\n";
    std::fs::write(d.join("scene/s.toml"), text).unwrap();
    refused(
        &airlight(d, &["info", "scene/s.toml"]),
        "no file `tri.obj` in the scene's folder `scene` (more folders: AIRLIGHT_ASSET_PATH)",
    );
    let assets = d.join("assets");
    let out = airlight_env(d, &["info", "scene/s.toml"], &[("AIRLIGHT_ASSET_PATH", assets.to_str().unwrap())]);
    assert!(out.status.success(), "{}", stderr(&out));
    refused(
        &airlight(d, &["info", "/dev/zero"]),
        "/dev/zero: cannot read the scene file: it holds more than 16777216 bytes",
    );
}
