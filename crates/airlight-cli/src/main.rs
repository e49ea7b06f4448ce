//! `airlight`: render scenes, check them, compare images.

use airlight::film::{self, Image};
use airlight::integrator::{IntegratorKind, Sampling};
use airlight::render::{Progressive, RenderObserver, render_with};
use airlight::scene::{self, Scene};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

mod plot;

/// The built-in demo scene: spheres on a checker floor under a spot light in fog.
const DEMO_SCENE: &str = include_str!("../../../scenes/demo.toml");

#[derive(Parser)]
#[command(name = "airlight", version, about = "Renders light that you can see: glows, light cones, volumetric shadows")]
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
    /// Plot the attenuation curves of a light of given radius, intensity and
    /// cutoff as a PNG, and print where each reaches zero (d_max).
    Attenuation(AttenuationArgs),
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
    /// Integrator: direct, raymarch, stochastic (analytic, path, radiosity are planned).
    #[arg(long)]
    integrator: Option<IntegratorKind>,
    /// Stochastic: how points on the camera segment are drawn: uniform,
    /// equiangular or mis.
    #[arg(long)]
    sampling: Option<Sampling>,
    /// Stochastic: independent random samples instead of stratified ones.
    #[arg(long)]
    no_stratify: bool,
    /// Render in passes of 1, 1, 2, 4, ... samples per pixel up to spp,
    /// rewriting the output after each pass.
    #[arg(long)]
    progressive: bool,
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
    /// Falloff for every point, spot and sphere light: physical, sphere,
    /// cutoff, window_tan, window_rational, window_ue4 (each keeps its cutoff).
    #[arg(long, value_parser = parse_attenuation)]
    attenuation: Option<airlight::light::AttenuationModel>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    threads: Option<u32>,
    /// No progress bar or summary.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(clap::Args)]
struct AttenuationArgs {
    /// The light's radius (a sphere light's, or the size that sets a point light's curve).
    #[arg(long, default_value_t = 0.5)]
    radius: f32,
    /// Its intensity in W/sr (a sphere light of radiance L has π r² L).
    #[arg(long, default_value_t = 10.0)]
    intensity: f32,
    /// Irradiance below which light is dropped (the seed's I_c); sets d_max.
    #[arg(long, default_value_t = 0.05)]
    cutoff: f32,
    /// d_max for the windows, overriding the one the cutoff implies.
    #[arg(long)]
    range: Option<f32>,
    /// Output PNG.
    #[arg(short, long, default_value = "attenuation.png")]
    output: PathBuf,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render(args),
        Command::Info { scene } => info(&scene),
        Command::Compare { image, reference, map } => compare(&image, &reference, map.as_deref()),
        Command::Attenuation(args) => attenuation(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn load(path: Option<&Path>) -> Result<Scene, String> {
    match path {
        Some(path) => scene::load(path).map_err(|e| e.to_string()),
        None => scene::from_toml_str(DEMO_SCENE, None).map_err(|e| format!("built-in demo scene: {e}")),
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
    if let Some(v) = args.sampling {
        s.sampling = v;
    }
    if args.no_stratify {
        s.stratify = false;
    }
    if let Some(model) = args.attenuation {
        for light in &mut scene.lights {
            if let Some(a) = light.attenuation() {
                let a = a.with_model(model).map_err(|e| format!("--attenuation: {e}"))?;
                *light = light.with_attenuation(a);
            }
        }
        scene.light_culling = airlight::scene::LightCulling::new(&scene.lights);
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
        match out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png" | "exr") => {}
            _ => {
                return Err(format!("cannot write `{}`: the output must end in .png or .exr", out.display()));
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
    let total = if args.progressive { pixels * s.spp as u64 } else { pixels };
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr())
    };
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent}% {elapsed} (eta {eta})") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(format!("{} {}×{} {} spp", s.integrator, s.width, s.height, s.spp));
    let write = |image: &Image| -> Result<(), String> {
        for out in &outputs {
            image.write(out, s.exposure, s.tonemap).map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
        }
        Ok(())
    };
    let start = Instant::now();
    if args.progressive {
        // Each pass rewrites the outputs (atomically), so stopping the
        // render loses at most the pass under way.
        let mut progressive = Progressive::new(&scene);
        while !progressive.finished() {
            let count = progressive.next_pass_size() as u64;
            let progress = |n: u64| bar.inc(n * count);
            let observer = RenderObserver { progress: Some(&progress), cancel: None };
            pool.install(|| progressive.pass(&scene, integrator.as_ref(), &observer));
            bar.set_message(format!(
                "{} {}×{} {}/{} spp",
                s.integrator,
                s.width,
                s.height,
                progressive.samples(),
                s.spp
            ));
            write(&progressive.image())?;
        }
    } else {
        let progress = |n: u64| bar.inc(n);
        let observer = RenderObserver { progress: Some(&progress), cancel: None };
        let image = pool.install(|| render_with(&scene, integrator.as_ref(), &observer));
        write(&image)?;
    }
    let elapsed = start.elapsed();
    bar.finish_and_clear();
    if !args.quiet {
        let names: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
        eprintln!("rendered {}×{} in {:.2} s → {}", s.width, s.height, elapsed.as_secs_f64(), names.join(", "));
    }
    Ok(())
}

fn info(path: &Path) -> Result<(), String> {
    let scene = load(Some(path))?;
    let s = &scene.settings;
    println!("scene: {}", path.display());
    println!("image: {}×{}, {} spp, integrator {}", s.width, s.height, s.spp, s.integrator);
    if s.integrator == IntegratorKind::Stochastic {
        println!("sampling: {}, {}", s.sampling, if s.stratify { "stratified" } else { "independent" });
    }
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
    let reference = Image::read_exr(b).map_err(|e| format!("cannot read `{}`: {e}", b.display()))?;
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

fn attenuation(args: AttenuationArgs) -> Result<(), String> {
    use airlight::light::{Attenuation, AttenuationModel as M};
    let positive = |v: f32, name: &str| {
        if v.is_finite() && v > 0.0 { Ok(v) } else { Err(format!("--{name} must be a positive number, got {v}")) }
    };
    let r = positive(args.radius, "radius")?;
    let e0 = positive(args.intensity, "intensity")? / (r * r);
    let cutoff = positive(args.cutoff, "cutoff")?;
    let range = args.range.map(|d| positive(d, "range")).transpose()?;
    if cutoff >= e0 {
        return Err(format!("--cutoff {cutoff} is not below the irradiance at the light's surface, I/r² = {e0}"));
    }
    let models = [
        (M::Physical, "physical", airlight::Rgb::new(0.0, 0.0, 0.0)),
        (M::Cutoff, "cutoff", airlight::Rgb::new(0.9, 0.1, 0.1)),
        (M::WindowTan, "window_tan", airlight::Rgb::new(0.1, 0.5, 0.1)),
        (M::WindowRational, "window_rational", airlight::Rgb::new(0.1, 0.2, 0.9)),
        (M::WindowUe4, "window_ue4", airlight::Rgb::new(0.8, 0.45, 0.0)),
    ];
    let mut curves = Vec::new();
    for (model, name, color) in models {
        let a = Attenuation::new(model, r, e0, Some(cutoff), range)?;
        println!("{name}: d_max = {}", a.range);
        curves.push((a, name, color));
    }
    println!("sphere: same curve as physical (1/(d/r + 1)^2), d_max = inf");
    let finite = curves.iter().map(|(a, ..)| a.range).filter(|d| d.is_finite()).fold(0.0, f32::max);
    let x_max = 1.15 * finite;
    let series = curves
        .iter()
        .map(|(a, name, color)| plot::Series {
            label: if a.range.is_finite() { format!("{name} (d_max {:.2})", a.range) } else { name.to_string() },
            color: *color,
            points: (0..=600).map(|i| x_max * i as f32 / 600.0).map(|d| (d, a.factor(d))).collect(),
        })
        .collect();
    let plot = plot::Plot {
        title: format!("r = {r}, I = {}, I_c = {cutoff}", args.intensity),
        x_label: "d, distance from the light's surface".into(),
        y_label: "E / E0".into(),
        x_max,
        y_min: -5.0,
        y_max: 0.0,
        log_y: true,
        series,
    };
    plot.render()
        .write(&args.output, 0.0, scene::Tonemap::Clamp)
        .map_err(|e| format!("cannot write `{}`: {e}", args.output.display()))?;
    Ok(())
}

fn parse_attenuation(s: &str) -> Result<airlight::light::AttenuationModel, String> {
    use airlight::light::AttenuationModel as M;
    Ok(match s {
        "physical" => M::Physical,
        "sphere" => M::Sphere,
        "cutoff" => M::Cutoff,
        "window_tan" => M::WindowTan,
        "window_rational" => M::WindowRational,
        "window_ue4" => M::WindowUe4,
        _ => {
            return Err(format!(
                "unknown attenuation `{s}`; expected physical, sphere, cutoff, window_tan, window_rational or window_ue4"
            ));
        }
    })
}
