//! `airlight`: render scenes, check them, compare images.

use airlight::SceneFile;
use airlight::film::{self, Image};
use airlight::integrator::IntegratorKind;
use airlight::light::Light;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod aovs;
mod gi;
mod load;
mod merge;
/// The library fuzz tests' seeded mutator, shared by the path-file and
/// job-script fuzz tests.
#[cfg(test)]
#[path = "../../airlight/tests/fuzz/mutate.rs"]
mod mutate;
mod options;
mod outputs;
mod plot;
mod preflight;
mod progress;
mod render;
mod study;
mod submit;
mod timing;
mod view;

#[derive(Parser)]
#[command(name = "airlight", version, about = "Renders light that you can see: glows, light cones, volumetric shadows")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (with none: the built-in demo scene) to an image.
    Render(render::RenderArgs),
    /// Check a scene file and print what it holds.
    Info { scene: PathBuf },
    /// Plot the attenuation curves of a light of given radius, intensity and
    /// cutoff as a PNG, and print where each reaches zero (d_max).
    Attenuation(AttenuationArgs),
    /// Radiosity in real time: compile the scene once, then relight it for
    /// each frame with its lights moved along their keyframes; prints the
    /// compile figures and per-frame milliseconds (median, p95) of
    /// direct + push + gather.
    Gi(gi::GiArgs),
    /// Fly through a scene and move its lights in a window (with none: the
    /// built-in Cornell box), or replay a scripted path with --headless.
    View(view::ViewArgs),
    /// Add up partial renders (`render --shard/--tile`) into the image.
    Merge(merge::MergeArgs),
    /// Render on a cluster's scheduler: shards, tiles and frames as a job
    /// array, then a merge job.
    #[command(subcommand)]
    Submit(Submit),
    /// Every integrator that supports the scene, at a ladder of settings,
    /// timed and measured against a path-traced truth: an HTML report with
    /// an error-versus-time plot, the same table here, and JSON on request.
    Study(study::StudyArgs),
    /// Compare two EXR images: prints rmse, rel_mse, mae and max.
    Compare {
        image: PathBuf,
        reference: PathBuf,
        /// Write a greyscale map of |a − b| (white = the largest difference).
        #[arg(long, value_name = "OUT.png")]
        map: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum Submit {
    /// Submit to Slurm: a job array of `airlight render --shard/--tile/--frame`
    /// tasks and a merge job that runs after every task succeeds.
    Slurm(submit::SlurmArgs),
}

#[derive(clap::Args)]
struct AttenuationArgs {
    /// The light's radius (a sphere light's, or the size that sets a point light's curve).
    #[arg(long, default_value_t = 0.5)]
    radius: f32,
    /// Its intensity in W/sr (a sphere light of radiance L has π r² L).
    #[arg(long, default_value_t = 10.0)]
    intensity: f32,
    /// Irradiance below which light is dropped (Madams's I_c); sets d_max.
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
    // Die quietly of SIGPIPE, as command-line tools do, when the reader of
    // our output goes away (`airlight info s.toml | head -1`); Rust ignores
    // it, which turns every later print into a panic.
    // SAFETY: setting a signal's disposition to the default, before any thread starts.
    unsafe { libc::signal(libc::SIGPIPE, libc::SIG_DFL) };
    let cli = Cli::parse();
    // A memory limit that cannot be read is refused before any work.
    if let Err(message) = airlight::memory::limit_var() {
        eprintln!("error: {message}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Render(args) => render::render(args),
        Command::Merge(args) => merge::merge(args),
        Command::Study(args) => study::study(args),
        Command::Submit(Submit::Slurm(args)) => submit::slurm(args),
        Command::Info { scene } => info(&scene),
        Command::Compare { image, reference, map } => compare(&image, &reference, map.as_deref()),
        Command::Attenuation(args) => attenuation(args),
        Command::Gi(args) => gi::gi(args),
        Command::View(args) => view::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn info(path: &Path) -> Result<(), String> {
    let SceneFile { scene, integrator } = load::load(Some(path))?;
    preflight::warn_if_dark(&scene, integrator.kind != IntegratorKind::Direct);
    let s = scene.settings();
    println!("scene: {}", path.display());
    println!("image: {}×{}, {} spp, integrator {}", s.film.width, s.film.height, s.spp, integrator.kind);
    if integrator.kind == IntegratorKind::Stochastic {
        let o = integrator.stochastic;
        println!("sampling: {}, {}", o.sampling, if o.stratify { "stratified" } else { "independent" });
    }
    let camera = scene.camera();
    println!("camera: {:?} at {} looking along {}", camera.projection, camera.position, camera.forward);
    let (prims, planes) = scene.geometry().primitive_count();
    println!("geometry: {prims} bounded primitives, {planes} planes");
    println!("materials: {}", scene.materials().len());
    println!("lights: {}", scene.lights().len());
    // An emitting mesh is a light per triangle: counted, not listed, with
    // the power they send out (π × area × radiance each: a Lambertian
    // emitter's, from one side), their textures' means where they glow
    // unevenly.
    let triangles: Vec<&Light> = scene.lights().iter().filter(|l| matches!(l, Light::Triangle { .. })).collect();
    if !triangles.is_empty() {
        let power = triangles.iter().fold(glam::DVec3::ZERO, |sum, l| match **l {
            Light::Triangle { edge_1, edge_2, radiance, .. } => {
                let area = 0.5 * edge_1.as_dvec3().cross(edge_2.as_dvec3()).length();
                sum + radiance.as_dvec3() * (std::f64::consts::PI * area)
            }
            _ => sum,
        });
        let watts = |x: f64| format!("{x:.4}");
        println!(
            "  {} triangles of emitting meshes, sending out [{}, {}, {}] W in all",
            triangles.len(),
            watts(power.x),
            watts(power.y),
            watts(power.z)
        );
    }
    let others = scene.lights().iter().zip(scene.light_paths()).filter(|(l, _)| !matches!(l, Light::Triangle { .. }));
    for (light, path) in others {
        println!("  {light:?}");
        if let Some(path) = path {
            println!("    moves along {} keyframes", path.keys().len());
        }
    }
    match scene.medium() {
        Some(m) => println!("medium: {m:?}"),
        None => println!("medium: none (vacuum)"),
    }
    Ok(())
}
fn compare(a: &Path, b: &Path, map: Option<&Path>) -> Result<(), String> {
    let image = Image::read_exr(a).map_err(|e| format!("cannot read `{}`: {e}", a.display()))?;
    let reference = Image::read_exr(b).map_err(|e| format!("cannot read `{}`: {e}", b.display()))?;
    if let Some(map) = map {
        outputs::check(&[outputs::Output { option: "--map", path: map }], &[a, b])?;
    }
    preflight::finite_pixels(&image, a)?;
    preflight::finite_pixels(&reference, b)?;
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
    let (ma, mb) = (image.mean(), reference.mean());
    println!("mean_a: {} {} {}", ma.x, ma.y, ma.z);
    println!("mean_b: {} {} {}", mb.x, mb.y, mb.z);
    if let Some(map) = map {
        film::error_map(&image, &reference, e.max as f32)
            .save(map)
            .map_err(|e| format!("cannot write `{}`: {e}", map.display()))?;
    }
    Ok(())
}

fn attenuation(args: AttenuationArgs) -> Result<(), String> {
    use airlight::light::{Attenuation, AttenuationModel as M};
    let positive = |v: f32, name: &str| {
        if v.is_finite() && v > 0.0 { Ok(v) } else { Err(format!("--{name} must be a positive number, got {v}")) }
    };
    outputs::check(&[outputs::Output { option: "-o", path: &args.output }], &[])?;
    let r = positive(args.radius, "radius")?;
    let e0 = positive(args.intensity, "intensity")? / (r * r);
    if !(e0.is_normal() && e0.is_finite()) {
        return Err(format!(
            "the irradiance at the light's surface, --intensity / --radius² = {:.3e}, is out of the range of 32-bit \
             floats (about 1e-38 to 3e38)",
            args.intensity as f64 / (r as f64 * r as f64)
        ));
    }
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
    if finite <= 0.0 {
        return Err(format!(
            "no curve reaches zero at a finite distance: I/r² / --cutoff = {:.3e} overflows 32-bit floats; \
             give a larger --cutoff, or a --range",
            e0 as f64 / cutoff as f64
        ));
    }
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
    let image = plot.render().map_err(|e| format!("cannot plot these curves: {e}"))?;
    image.save(&args.output).map_err(|e| format!("cannot write `{}`: {e}", args.output.display()))?;
    Ok(())
}
