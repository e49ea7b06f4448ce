//! The viewer's window, for real: under a virtual X server (Xvfb), keys
//! sent with xdotool, the screen read back with ImageMagick's `import`.
//!
//! It needs `Xvfb`, `xdotool` and `import` (Debian: xvfb, xdotool,
//! imagemagick), which .ci/run installs. Without them the test says so and
//! is skipped, except under `AIRLIGHT_CI=1` (as .ci/run sets), where it
//! fails.
#![cfg(feature = "viewer")]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Ends and reaps a child process when dropped, so that a failing
/// assertion leaves no X server or viewer behind: SIGTERM first, which lets
/// Xvfb remove its socket and lock file, then SIGKILL after a grace period.
struct Reaped(Child);

impl Drop for Reaped {
    fn drop(&mut self) {
        if let Ok(None) = self.0.try_wait() {
            let _ = Command::new("kill").args(["-TERM", &self.0.id().to_string()]).status();
            let start = Instant::now();
            while matches!(self.0.try_wait(), Ok(None)) && start.elapsed() < Duration::from_secs(5) {
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A display number with no server and no stale lock.
fn free_display() -> u32 {
    (90..400)
        .find(|n| {
            !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() && !Path::new(&format!("/tmp/.X{n}-lock")).exists()
        })
        .expect("no free X display number between :90 and :399")
}

fn wait_for(what: &str, timeout: Duration, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < timeout, "timed out after {timeout:?} waiting for {what}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

struct Display {
    name: String,
    _server: Reaped,
}

impl Display {
    fn start() -> Display {
        let n = free_display();
        let name = format!(":{n}");
        let server = Command::new("Xvfb")
            .args([&name, "-screen", "0", "800x600x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start Xvfb");
        let server = Reaped(server);
        // The socket file appears before the server accepts clients, and a
        // client that connects in between is refused: wait until one is
        // answered.
        let display = Display { name, _server: server };
        wait_for("Xvfb to answer", Duration::from_secs(30), || {
            Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
                && Command::new("xdotool")
                    .env("DISPLAY", &display.name)
                    .arg("getdisplaygeometry")
                    .stdout(Stdio::null())
                    .stderr(Stdio::null())
                    .status()
                    .is_ok_and(|s| s.success())
        });
        display
    }

    fn run(&self, tool: &str, args: &[&str]) -> String {
        let out = Command::new(tool).env("DISPLAY", &self.name).args(args).output().unwrap();
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    }

    /// Holds `key` down long enough for a frame or two to see it.
    fn hold(&self, key: &str, seconds: f32) {
        self.run("xdotool", &["keydown", key]);
        std::thread::sleep(Duration::from_secs_f32(seconds));
        self.run("xdotool", &["keyup", key]);
    }

    /// The whole screen as RGB bytes, width and height.
    fn screenshot(&self, file: &Path) -> (Vec<u8>, usize, usize) {
        let target = format!("ppm:{}", file.display());
        let status = Command::new("import")
            .env("DISPLAY", &self.name)
            .args(["-window", "root", "-depth", "8", &target])
            .status();
        assert!(status.is_ok_and(|s| s.success()), "import failed");
        read_ppm(&std::fs::read(file).unwrap())
    }
}

/// A binary PPM (P6, maxval 255): header fields separated by whitespace.
fn read_ppm(bytes: &[u8]) -> (Vec<u8>, usize, usize) {
    let mut fields = Vec::new();
    let mut i = 0;
    while fields.len() < 4 {
        while bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let start = i;
        while !bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        fields.push(std::str::from_utf8(&bytes[start..i]).unwrap().to_string());
    }
    assert_eq!((fields[0].as_str(), fields[3].as_str()), ("P6", "255"));
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    (bytes[i + 1..i + 1 + w * h * 3].to_vec(), w, h)
}

/// The bytes of the window's rectangle (x, y, w, h) of a screenshot.
fn crop(shot: &(Vec<u8>, usize, usize), rect: (usize, usize, usize, usize)) -> Vec<u8> {
    let (pixels, width, _) = shot;
    let (x, y, w, h) = rect;
    (y..y + h).flat_map(|row| pixels[(row * width + x) * 3..(row * width + x + w) * 3].iter().copied()).collect()
}

#[test]
fn the_window_shows_the_scene_keys_move_the_camera_switch_integrators_save_and_quit() {
    let tools = ["Xvfb", "xdotool", "import"];
    if !common::tools_present("the viewer's window test", &tools, "apt-get install xvfb xdotool imagemagick") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let display = Display::start();
    // The viewer's messages go to a file, shown if it ends before its time.
    let log = dir.path().join("viewer.log");
    // One sample per frame keeps frames short, so that key presses are seen.
    let viewer = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .env("DISPLAY", &display.name)
        .current_dir(dir.path())
        .args(["view", "--width", "320", "--height", "180", "--batch", "1", "--out", "saved"])
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    let viewer = std::cell::RefCell::new(Reaped(viewer));
    std::fs::create_dir(dir.path().join("saved")).unwrap();
    // Waits for `ready`, failing with the viewer's own words if it ends
    // first or the time runs out.
    let wait = |what: &str, timeout: Duration, ready: &mut dyn FnMut() -> bool| {
        let said = || std::fs::read_to_string(&log).unwrap_or_default();
        let start = Instant::now();
        while !ready() {
            if let Some(status) = viewer.borrow_mut().0.try_wait().unwrap() {
                panic!("the viewer ended ({status}) before {what}; it said:\n{}", said());
            }
            assert!(
                start.elapsed() < timeout,
                "timed out after {timeout:?} waiting for {what}; the viewer said:\n{}",
                said()
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    };

    let mut window = String::new();
    wait("the window", Duration::from_secs(120), &mut || {
        window = display.run("xdotool", &["search", "--name", "airlight view"]);
        !window.is_empty()
    });
    let window = window.lines().next().unwrap().to_string();
    let title = || display.run("xdotool", &["getwindowname", &window]);
    let spp = |t: &str| -> u32 {
        t.split(" | ").find_map(|f| f.strip_suffix(" spp")).and_then(|n| n.parse().ok()).unwrap_or(0)
    };
    wait("a few samples", Duration::from_secs(60), &mut || spp(&title()) >= 4);
    let t = title();
    assert!(t.contains("| preview |") && t.contains("ms/frame") && t.contains("light 1/1"), "title: {t}");

    // Where the window is (no window manager: placed by the viewer's size).
    let geometry = display.run("xdotool", &["getwindowgeometry", &window]);
    let numbers = |key: &str, sep: char| -> (usize, usize) {
        let line = geometry.lines().find(|l| l.trim_start().starts_with(key)).unwrap();
        let value = line.split_once(':').unwrap().1.split_whitespace().next().unwrap();
        let (a, b) = value.split_once(sep).unwrap();
        (a.parse().unwrap(), b.parse().unwrap())
    };
    let ((x, y), (w, h)) = (numbers("Position", ','), numbers("Geometry", 'x'));
    assert_eq!((w, h), (320, 180), "{geometry}");
    let rect = (x, y, w, h);
    display.run("xdotool", &["mousemove", &(x + w / 2).to_string(), &(y + h / 2).to_string()]);

    let before = crop(&display.screenshot(&dir.path().join("before.ppm")), rect);
    let mean = before.iter().map(|&b| b as f64).sum::<f64>() / before.len() as f64;
    let mut colours: Vec<&[u8]> = before.chunks(3).collect();
    colours.sort();
    colours.dedup();
    assert!(mean > 10.0 && colours.len() > 50, "a blank window: mean {mean:.1}, {} colours", colours.len());

    // W flies forward: the view changes, and refines again once still.
    display.hold("w", 0.8);
    wait("refinement after the move", Duration::from_secs(60), &mut || spp(&title()) >= 4);
    let after = crop(&display.screenshot(&dir.path().join("after.ppm")), rect);
    let change =
        before.iter().zip(&after).map(|(&a, &b)| (a as f64 - b as f64).abs()).sum::<f64>() / before.len() as f64;
    assert!(change > 5.0, "holding W changed the window by only {change:.2} levels on average");

    // 2 switches to ray marching.
    display.hold("2", 0.5);
    wait("the raymarch integrator", Duration::from_secs(30), &mut || title().contains("| raymarch |"));

    // F12 saves the image, EXR and PNG.
    display.hold("F12", 0.5);
    let saved = |ext: &str| -> PathBuf { dir.path().join(format!("saved/airlight-view-0001.{ext}")) };
    wait("the saved image", Duration::from_secs(30), &mut || saved("exr").exists() && saved("png").exists());
    let image = airlight::film::Image::read_exr(&saved("exr")).unwrap();
    assert_eq!((image.width, image.height), (320, 180));

    // Esc quits, with success.
    display.hold("Escape", 0.5);
    let mut status = None;
    wait_for("the viewer to quit", Duration::from_secs(30), || {
        status = viewer.borrow_mut().0.try_wait().unwrap();
        status.is_some()
    });
    assert!(status.unwrap().success());
}
