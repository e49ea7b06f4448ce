//! `airlight view`: fly through a scene and move its lights while the
//! radiosity bounce light follows.
//!
//! One frame loop ([`engine::Engine`]) serves two drivers: the window
//! ([`window`], behind the `viewer` cargo feature, minifb on X11), where
//! keys and the mouse move the camera and the lights, and the headless mode
//! ([`headless`]), where a script ([`path`]) does, for tests and benchmarks.
//! The library stays free of window code; what the viewer needed of it is
//! [`airlight::preview`].

// Without the window, parts of the frame loop that only keys reach go unused.
#[cfg_attr(not(feature = "viewer"), allow(dead_code))]
pub mod engine;
pub mod headless;
#[cfg(any(feature = "viewer", test))]
pub mod input;
pub mod script;
#[cfg(feature = "viewer")]
mod window;

use engine::{Engine, Mode};
use headless::Start;
use script::Script;
use std::path::PathBuf;

/// The scene viewed when none is named: the Cornell box, whose ceiling light
/// slides along keyframes (Space plays them).
pub const DEFAULT_SCENE: &str = include_str!("../../../../scenes/cornell_box.toml");

#[derive(clap::Args)]
pub struct ViewArgs {
    /// Scene file (TOML). Without one, the built-in Cornell box with a moving light.
    scene: Option<PathBuf>,
    /// Image width (the window's, and of headless frames).
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(1..=8192))]
    width: u32,
    #[arg(long, default_value_t = 360, value_parser = clap::value_parser!(u32).range(1..=8192))]
    height: u32,
    /// Integrator to start with: preview, raymarch or stochastic (keys 1, 2, 3).
    /// Default: the path file's, else preview.
    #[arg(long, value_parser = Mode::parse)]
    integrator: Option<Mode>,
    /// No window: replay --path (without one, the scene's light keyframes)
    /// for --frames frames and print per-frame times.
    #[arg(long)]
    headless: bool,
    /// Headless: frames to run.
    #[arg(long, default_value_t = 60, requires = "headless", value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_FRAMES as i64))]
    frames: u32,
    /// Headless: the scripted camera and light path (TOML; see docs/guide/viewer.md).
    #[arg(long, value_name = "CAMERA.toml", requires = "headless")]
    path: Option<PathBuf>,
    /// Headless: write every frame as DIR/frame_0000.exr and .png. Window:
    /// where F12 saves (default: the current directory).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Most samples per pixel a frame adds while nothing moves (passes
    /// double from 1 up to this).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..))]
    batch: u32,
    /// Samples per pixel at which refinement stops.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..))]
    max_spp: u32,
    /// Window: seconds one pass of the light keyframes takes (Space plays it).
    #[arg(long, default_value_t = 8.0)]
    period: f32,
    /// Window: always render at full size (by default frames are rendered at
    /// half size while moving if a full-size frame takes over 1/30 s).
    #[arg(long)]
    no_dynamic_resolution: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_THREADS as i64))]
    threads: Option<u32>,
}

pub fn run(args: ViewArgs) -> Result<(), String> {
    let (file, name) = match &args.scene {
        Some(p) => (crate::load::load(Some(p))?, p.display().to_string()),
        None => (
            airlight::SceneFile::from_toml_str(DEFAULT_SCENE, None).map_err(|e| format!("built-in scene: {e}"))?,
            "the built-in Cornell box".to_string(),
        ),
    };
    let scene = &file.scene;
    // The view's frames add samples into running sums, as passes do: a
    // progressive job of the window's size, on its threads.
    let mut settings = scene.settings().clone();
    (settings.film.width, settings.film.height) = (args.width, args.height);
    let request = airlight::render::RenderRequest { passes: true, threads: args.threads, ..Default::default() };
    let job = request.check(&settings, file.integrator.kind)?;
    job.mode.check_memory(&settings.film).map_err(|e| format!("{e}: make it smaller (--width, --height)"))?;
    crate::preflight::warn_if_dark(scene, true);
    if let Some(dir) = args.out.as_deref().filter(|_| args.headless) {
        let names = (0..args.frames).flat_map(|k| ["exr", "png"].map(|ext| format!("frame_{k:04}.{ext}")));
        let inputs: Vec<&std::path::Path> = args
            .scene
            .iter()
            .map(std::path::PathBuf::as_path)
            .chain(args.path.as_deref())
            .chain(scene.files().iter().map(std::path::PathBuf::as_path))
            .collect();
        crate::outputs::check_in_folder("--out", dir, names, &inputs)?;
    }
    if !(args.period.is_finite() && args.period > 0.0) {
        return Err(format!("--period must be a positive number of seconds, got {}", args.period));
    }
    let script = match &args.path {
        Some(p) => script::load(p, scene).map_err(|e| e.to_string())?,
        None => Script::scene_keyframes(),
    };
    let start = Start { camera: *scene.camera(), lights: scene.lights().to_vec(), paths: scene.light_paths().to_vec() };
    let pool = job.thread_pool()?;
    pool.install(|| {
        let mode = args.integrator.or(script.integrator).unwrap_or(Mode::Preview);
        let t = std::time::Instant::now();
        let mut engine = Engine::new(file, args.width, args.height, mode);
        match engine.solution() {
            Some(s) => eprintln!(
                "{name}: radiosity compiled in {:.0} ms ({} patches)",
                t.elapsed().as_secs_f64() * 1e3,
                s.stats().patches
            ),
            None => eprintln!("{name}: {}", engine.solution_note.as_deref().unwrap_or("no radiosity")),
        }
        (engine.batch, engine.max_spp) = (args.batch, args.max_spp);
        if args.headless {
            headless::run(&mut engine, &script, &start, args.frames, args.out.as_deref())
        } else {
            windowed(&mut engine, &start, &args)
        }
    })
}

#[cfg(feature = "viewer")]
fn windowed(engine: &mut Engine, start: &Start, args: &ViewArgs) -> Result<(), String> {
    let options = window::Options {
        period: args.period,
        dynamic: !args.no_dynamic_resolution,
        out: args.out.clone().unwrap_or_else(|| PathBuf::from(".")),
    };
    window::run(engine, start, &options)
}

#[cfg(not(feature = "viewer"))]
fn windowed(_: &mut Engine, _: &Start, _: &ViewArgs) -> Result<(), String> {
    Err("this airlight was built without the `viewer` feature, so it has no window: \
         use --headless, or build with `--features viewer`"
        .into())
}
