//! `airlight render`: one image, progressive passes (optionally until an
//! error target), or the numbered frames of a light animation.

use crate::load;
use crate::preflight::Forecast;
use airlight::SceneFile;
use airlight::film::Image;
use airlight::integrator::analytic::LightQuadrature;
use airlight::integrator::{Integrator, IntegratorKind, MAX_LIGHT_STEPS, MAX_STEPS, Sampling};
use airlight::render::{Progressive, RenderObserver, frame_time, set_time};
use airlight::scene::{MAX_IMAGE_SIDE, MAX_SPP, Scene};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file (TOML). Without one, the built-in demo scene.
    scene: Option<PathBuf>,
    /// Output image, .png or .exr; may be given more than once.
    /// Default: airlight.png for the demo, else the scene's name with .png.
    #[arg(short, long = "output", value_name = "OUT")]
    output: Vec<PathBuf>,
    /// Integrator: direct, raymarch, analytic, stochastic, path, radiosity.
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
    /// Stop once the estimated relative error of the image (√(Σ variance of
    /// the pixel means / Σ mean²)) is below E, or at spp; implies
    /// --progressive. The estimate is close for independent samples, high
    /// for stratified ones (stochastic), and low while rare bright samples
    /// (fireflies) are still missing.
    #[arg(long, value_name = "E", value_parser = parse_target_error)]
    target_error: Option<f64>,
    /// Also write the estimated variance of each pixel's mean (per channel)
    /// as an EXR; implies --progressive.
    #[arg(long, value_name = "OUT.exr")]
    variance: Option<PathBuf>,
    /// Render N frames of the scene's light animation (lights with
    /// keyframes), frame k at time k/(N − 1), each output numbered:
    /// NAME_0000.png, NAME_0001.png, ...
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_FRAMES as i64))]
    frames: Option<u32>,
    /// Samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP as i64))]
    spp: Option<u32>,
    /// March samples per ray.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_STEPS as i64))]
    steps: Option<u32>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    width: Option<u32>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    height: Option<u32>,
    #[arg(long)]
    seed: Option<u64>,
    /// Falloff for every point, spot and sphere light: physical, sphere,
    /// cutoff, window_tan, window_rational, window_ue4 (each keeps its cutoff).
    #[arg(long, value_parser = parse_attenuation)]
    attenuation: Option<airlight::light::AttenuationModel>,
    /// analytic: volumetric shadows (the lit intervals of each ray).
    #[arg(long)]
    shadows: bool,
    /// analytic: points per dimension over line and quad lights.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_LIGHT_STEPS as i64))]
    light_steps: Option<u32>,
    /// analytic: gauss (Gauss–Legendre) or uniform (the seed's stepping) over lights.
    #[arg(long, value_parser = parse_light_quadrature)]
    light_quadrature: Option<LightQuadrature>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_THREADS as i64))]
    threads: Option<u32>,
    /// No progress bar or summary.
    #[arg(long, short)]
    quiet: bool,
}

/// Where one frame goes: its images and, on request, its variance.
struct FrameOutputs {
    images: Vec<PathBuf>,
    variance: Option<PathBuf>,
}

pub fn render(args: RenderArgs) -> Result<(), String> {
    let SceneFile { mut scene, integrator: desc } = configure(&args)?;
    let outputs = output_paths(&args)?;
    if let Some(v) = &args.variance
        && !v.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        return Err(format!("cannot write `{}`: the variance is written as .exr", v.display()));
    }
    if args.variance.is_some() && scene.settings().spp < 2 {
        return Err("--variance: a variance needs at least 2 samples per pixel (--spp)".into());
    }
    if args.frames.is_some() && !scene.is_animated() {
        return Err("--frames: the scene has no light with keyframes to animate".into());
    }
    let progressive = args.progressive || args.target_error.is_some() || args.variance.is_some();
    let (files, variance) = (scene.files(), args.variance.as_deref());
    crate::outputs::check_render(args.scene.as_deref(), files, &outputs, variance, args.frames)?;
    crate::preflight::render_memory(&scene, progressive)?;
    crate::preflight::warn_if_dark(&scene, desc.kind != IntegratorKind::Direct);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0) as usize)
        .build()
        .map_err(|e| format!("cannot start worker threads: {e}"))?;
    let frames = args.frames.unwrap_or(1);
    let s = scene.settings();
    let per_frame = s.width as u64 * s.height as u64 * s.spp as u64;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(per_frame * frames as u64), ProgressDrawTarget::stderr())
    };
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent}% {elapsed} (eta {eta})") {
        bar.set_style(style.progress_chars("=> "));
    }
    let start = Instant::now();
    // Built once: between frames the integrator only hears that the lights
    // moved (radiosity relights without recompiling).
    let mut integrator = pool.install(|| desc.build(&scene)).map_err(|e| e.to_string())?;
    let what = describe(&scene, args.frames);
    let probe = crate::preflight::probe(&scene, integrator.as_ref(), pool.current_num_threads(), frames, &what);
    if let Some(warning) = &probe {
        bar.suspend(|| eprintln!("{warning}"));
    }
    let forecast = Forecast::new(per_frame * frames as u64, what, probe.is_some());
    let mut written = Vec::new();
    for frame in 0..frames {
        let outputs = match args.frames {
            Some(_) => {
                pool.install(|| set_time(&mut scene, integrator.as_mut(), frame_time(frame, frames)))
                    .map_err(|e| e.to_string())?;
                FrameOutputs {
                    images: outputs.iter().map(|p| numbered(p, frame)).collect(),
                    variance: args.variance.as_deref().map(|p| numbered(p, frame)),
                }
            }
            None => FrameOutputs { images: outputs.clone(), variance: args.variance.clone() },
        };
        let frame_label = args.frames.map(|n| format!(" frame {}/{n}", frame + 1)).unwrap_or_default();
        let label = format!("{}{frame_label}", desc.kind);
        let summary = if progressive {
            render_progressive(
                &scene,
                integrator.as_ref(),
                &pool,
                (&bar, &forecast),
                &outputs,
                args.target_error,
                &label,
            )?
        } else {
            render_once(&scene, integrator.as_ref(), &pool, (&bar, &forecast), &outputs, &label)?
        };
        if !args.quiet && args.frames.is_none() && !summary.is_empty() {
            bar.suspend(|| eprintln!("{summary}"));
        }
        written.extend(outputs.images.iter().map(|p| p.display().to_string()));
        written.extend(outputs.variance.iter().map(|p| p.display().to_string()));
    }
    let elapsed = start.elapsed();
    bar.finish_and_clear();
    if !args.quiet {
        let s = scene.settings();
        let what = match args.frames {
            Some(n) => format!("{n} frames of {}×{}", s.width, s.height),
            None => format!("{}×{}", s.width, s.height),
        };
        let shown = if written.len() > 4 {
            format!("{}, …, {}", written[0], written[written.len() - 1])
        } else {
            written.join(", ")
        };
        eprintln!("rendered {what} in {:.2} s → {shown}", elapsed.as_secs_f64());
    }
    Ok(())
}

/// The scene file with the command line's overrides applied and checked.
fn configure(args: &RenderArgs) -> Result<SceneFile, String> {
    let mut file = load(args.scene.as_deref())?;
    let s = file.scene.settings_mut();
    if let Some(v) = args.spp {
        s.spp = v;
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
    s.validate()?;
    let d = &mut file.integrator;
    if let Some(v) = args.integrator {
        d.kind = v;
    }
    if let Some(v) = args.steps {
        d.raymarch.steps = v;
    }
    if let Some(v) = args.sampling {
        d.stochastic.sampling = v;
    }
    if args.no_stratify {
        d.stochastic.stratify = false;
    }
    if args.shadows {
        d.analytic.shadows = true;
    }
    if let Some(v) = args.light_steps {
        d.analytic.light_steps = v;
    }
    if let Some(v) = args.light_quadrature {
        d.analytic.quadrature = v;
    }
    d.validate().map_err(|e| format!("--{}", e.to_string().replace('_', "-")))?;
    if let Some(model) = args.attenuation {
        file.scene.set_attenuation_model(model).map_err(|e| format!("--attenuation: {e}"))?;
    }
    Ok(file)
}

/// The image outputs: as given, or NAME.png after the scene file.
fn output_paths(args: &RenderArgs) -> Result<Vec<PathBuf>, String> {
    let outputs = if args.output.is_empty() {
        vec![match &args.scene {
            Some(path) => PathBuf::from(path.file_stem().unwrap_or_default()).with_extension("png"),
            None => PathBuf::from("airlight.png"),
        }]
    } else {
        args.output.clone()
    };
    for out in &outputs {
        match out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png" | "exr") => {}
            _ => {
                return Err(format!("cannot write `{}`: the output must end in .png or .exr", out.display()));
            }
        }
    }
    Ok(outputs)
}

/// `path` with `_NNNN` (the frame number) before its extension.
fn numbered(path: &Path, frame: u32) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let name = match path.extension() {
        Some(ext) => format!("{stem}_{frame:04}.{}", ext.to_string_lossy()),
        None => format!("{stem}_{frame:04}"),
    };
    path.with_file_name(name)
}

fn write_images(scene: &Scene, image: &Image, outputs: &[PathBuf]) -> Result<(), String> {
    let s = scene.settings();
    for out in outputs {
        image.save_with(out, s.exposure, s.tonemap).map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
    }
    Ok(())
}

/// All samples in one go; returns nothing to report.
fn render_once(
    scene: &Scene,
    integrator: &dyn Integrator,
    pool: &rayon::ThreadPool,
    (bar, forecast): (&ProgressBar, &Forecast),
    outputs: &FrameOutputs,
    label: &str,
) -> Result<String, String> {
    let s = scene.settings();
    bar.set_message(format!("{label} {}×{} {} spp", s.width, s.height, s.spp));
    let progress = |n: u64| advance(bar, forecast, n);
    let observer = RenderObserver { progress: Some(&progress), cancel: None };
    let image = pool.install(|| airlight::render(scene, integrator, &observer));
    write_images(scene, &image, &outputs.images)?;
    Ok(String::new())
}

/// Passes of doubling size, each rewriting the outputs (atomically, so
/// stopping the render loses at most the pass under way), until spp or the
/// error target; returns the samples reached and the estimated error.
fn render_progressive(
    scene: &Scene,
    integrator: &dyn Integrator,
    pool: &rayon::ThreadPool,
    (bar, forecast): (&ProgressBar, &Forecast),
    outputs: &FrameOutputs,
    target_error: Option<f64>,
    label: &str,
) -> Result<String, String> {
    let s = scene.settings();
    let mut progressive = Progressive::new(scene);
    let mut error = f64::INFINITY;
    while !progressive.finished() && !target_error.is_some_and(|target| error < target) {
        let progress = |n: u64| advance(bar, forecast, n);
        let observer = RenderObserver { progress: Some(&progress), cancel: None };
        pool.install(|| progressive.pass(scene, integrator, &observer));
        error = progressive.estimated_relative_error();
        bar.set_message(format!(
            "{label} {}×{} {}/{} spp, est. error {}",
            s.width,
            s.height,
            progressive.samples(),
            s.spp,
            format_error(error),
        ));
        write_images(scene, &progressive.image(), &outputs.images)?;
        // The variance is known from the second sample on (EXR: linear, the
        // tone map is not applied).
        if let Some(path) = outputs.variance.as_ref().filter(|_| progressive.samples() >= 2) {
            progressive.variance().save(path).map_err(|e| format!("cannot write `{}`: {e}", path.display()))?;
        }
    }
    // Samples skipped by reaching the target still count toward the bar.
    let skipped = (s.spp - progressive.samples()) as u64 * s.width as u64 * s.height as u64;
    bar.inc(skipped);
    Ok(format!("{} spp, estimated relative error {}", progressive.samples(), format_error(error)))
}
/// Counts finished samples on the bar and warns if the run looks endless.
fn advance(bar: &ProgressBar, forecast: &Forecast, samples: u64) {
    bar.inc(samples);
    if let Some(warning) = forecast.advance(samples) {
        bar.suspend(|| eprintln!("{warning}"));
    }
}

/// "this render (N frames of W×H at S spp)", for the forecast.
fn describe(scene: &Scene, frames: Option<u32>) -> String {
    let s = scene.settings();
    let frames = frames.map(|n| format!("{n} frames of ")).unwrap_or_default();
    format!("this render ({frames}{}×{} at {} spp)", s.width, s.height, s.spp)
}

fn format_error(error: f64) -> String {
    if error.is_finite() { format!("{error:.4}") } else { "unknown (fewer than 2 samples)".into() }
}

fn parse_target_error(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(e) if e > 0.0 && e.is_finite() => Ok(e),
        _ => Err(format!("`{s}` is not a positive number (a relative error, e.g. 0.01)")),
    }
}

fn parse_light_quadrature(s: &str) -> Result<LightQuadrature, String> {
    s.parse()
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
