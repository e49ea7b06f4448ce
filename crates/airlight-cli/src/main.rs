//! `airlight`: render scenes, check them, compare images.

use airlight::film::{self, Image};
use airlight::integrator::IntegratorKind;
use airlight::integrator::analytic::LightQuadrature;
use airlight::render::{RenderObserver, render_with};
use airlight::scene::{self, Scene};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The built-in demo scene: spheres on a checker floor under a spot light in fog.
const DEMO_SCENE: &str = include_str!("../../../scenes/demo.toml");

#[derive(Parser)]
#[command(
    name = "airlight",
    version,
    about = "Renders light that you can see: glows, light cones, volumetric shadows"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (with none: the built-in demo scene) to an image.
    Render(RenderArgs),
    /// Check a scene file and print what it holds.
    Info { scene: PathBuf },
    /// Compare two EXR images: prints rmse, rel_mse, mae and max.
    Compare {
        image: PathBuf,
        reference: PathBuf,
        /// Write a greyscale map of |a − b| (white = the largest difference).
        #[arg(long, value_name = "OUT.png")]
        map: Option<PathBuf>,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (TOML). Without one, the built-in demo scene.
    scene: Option<PathBuf>,
    /// Output image, .png or .exr; may be given more than once.
    /// Default: airlight.png for the demo, else the scene's name with .png.
    #[arg(short, long = "output", value_name = "OUT")]
    output: Vec<PathBuf>,
    /// Integrator: direct, raymarch, analytic (stochastic, path, radiosity are planned).
    #[arg(long)]
    integrator: Option<IntegratorKind>,
    /// Samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    spp: Option<u32>,
    /// March samples per ray.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    steps: Option<u32>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    width: Option<u32>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    height: Option<u32>,
    #[arg(long)]
    seed: Option<u64>,
    /// analytic: volumetric shadows (the lit intervals of each ray).
    #[arg(long)]
    shadows: bool,
    /// analytic: points per dimension over line and quad lights.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    light_steps: Option<u32>,
    /// analytic: gauss (Gauss–Legendre) or uniform (the seed's stepping) over lights.
    #[arg(long, value_parser = parse_light_quadrature)]
    light_quadrature: Option<LightQuadrature>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    threads: Option<u32>,
    /// No progress bar or summary.
    #[arg(long, short)]
    quiet: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render(args),
        Command::Info { scene } => info(&scene),
        Command::Compare {
            image,
            reference,
            map,
        } => compare(&image, &reference, map.as_deref()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn parse_light_quadrature(s: &str) -> Result<LightQuadrature, String> {
    match s {
        "gauss" => Ok(LightQuadrature::Gauss),
        "uniform" => Ok(LightQuadrature::Uniform),
        _ => Err(format!(
            "unknown light quadrature `{s}`; expected gauss or uniform"
        )),
    }
}

fn load(path: Option<&Path>) -> Result<Scene, String> {
    match path {
        Some(path) => scene::load(path).map_err(|e| e.to_string()),
        None => {
            scene::from_toml_str(DEMO_SCENE, None).map_err(|e| format!("built-in demo scene: {e}"))
        }
    }
}

fn render(args: RenderArgs) -> Result<(), String> {
    let mut scene = load(args.scene.as_deref())?;
    let s = &mut scene.settings;
    if let Some(v) = args.integrator {
        s.integrator = v;
    }
    if let Some(v) = args.spp {
        s.spp = v;
    }
    if let Some(v) = args.steps {
        s.steps = v;
    }
    if let Some(v) = args.width {
        s.width = v;
    }
    if let Some(v) = args.height {
        s.height = v;
    }
    if let Some(v) = args.seed {
        s.seed = v;
    }
    if args.shadows {
        s.shadows = true;
    }
    if let Some(v) = args.light_steps {
        s.light_steps = v;
    }
    if let Some(v) = args.light_quadrature {
        s.light_quadrature = v;
    }
    let outputs = if args.output.is_empty() {
        vec![match &args.scene {
            Some(path) => PathBuf::from(path.file_stem().unwrap_or_default()).with_extension("png"),
            None => PathBuf::from("airlight.png"),
        }]
    } else {
        args.output
    };
    for out in &outputs {
        match out
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png" | "exr") => {}
            _ => {
                return Err(format!(
                    "cannot write `{}`: the output must end in .png or .exr",
                    out.display()
                ));
            }
        }
    }
    let integrator = airlight::integrator::for_scene(&scene)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0) as usize)
        .build()
        .map_err(|e| format!("cannot start worker threads: {e}"))?;
    let s = &scene.settings;
    let pixels = s.width as u64 * s.height as u64;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(pixels), ProgressDrawTarget::stderr())
    };
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent}% {elapsed} (eta {eta})")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(format!(
        "{} {}×{} {} spp",
        s.integrator, s.width, s.height, s.spp
    ));
    let progress = |n: u64| bar.inc(n);
    let observer = RenderObserver {
        progress: Some(&progress),
        cancel: None,
    };
    let start = Instant::now();
    let image = pool.install(|| render_with(&scene, integrator.as_ref(), &observer));
    let elapsed = start.elapsed();
    bar.finish_and_clear();
    for out in &outputs {
        image
            .write(out, s.exposure, s.tonemap)
            .map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
    }
    if !args.quiet {
        let names: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
        eprintln!(
            "rendered {}×{} in {:.2} s → {}",
            s.width,
            s.height,
            elapsed.as_secs_f64(),
            names.join(", ")
        );
    }
    Ok(())
}

fn info(path: &Path) -> Result<(), String> {
    let scene = load(Some(path))?;
    let s = &scene.settings;
    println!("scene: {}", path.display());
    println!(
        "image: {}×{}, {} spp, integrator {}",
        s.width, s.height, s.spp, s.integrator
    );
    println!(
        "camera: {:?} at {} looking along {}",
        scene.camera.projection, scene.camera.position, scene.camera.forward
    );
    let (prims, planes) = scene.geometry.primitive_count();
    println!("geometry: {prims} bounded primitives, {planes} planes");
    println!("materials: {}", scene.materials.len() - 1);
    println!("lights: {}", scene.lights.len());
    for light in &scene.lights {
        println!("  {light:?}");
    }
    match &scene.medium {
        Some(m) => println!("medium: {m:?}"),
        None => println!("medium: none (vacuum)"),
    }
    Ok(())
}

fn compare(a: &Path, b: &Path, map: Option<&Path>) -> Result<(), String> {
    let image = Image::read_exr(a).map_err(|e| format!("cannot read `{}`: {e}", a.display()))?;
    let reference =
        Image::read_exr(b).map_err(|e| format!("cannot read `{}`: {e}", b.display()))?;
    let e = film::compare(&image, &reference).ok_or_else(|| {
        format!(
            "the images differ in size: {}×{} and {}×{}",
            image.width, image.height, reference.width, reference.height
        )
    })?;
    println!("rmse: {}", e.rmse);
    println!("rel_mse: {}", e.rel_mse);
    println!("mae: {}", e.mae);
    println!("max: {}", e.max);
    println!("rel_rmse: {}", e.rel_rmse);
    if let Some(map) = map {
        film::error_map(&image, &reference, e.max as f32)
            .write(map, 0.0, scene::Tonemap::Clamp)
            .map_err(|e| format!("cannot write `{}`: {e}", map.display()))?;
    }
    Ok(())
}
