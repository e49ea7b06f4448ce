//! `airlight render`: one image, progressive passes (optionally until an
//! error target), the numbered frames of a light animation, or a part of a
//! render (a range of samples, a band of rows, one frame) for a render farm
//! to merge.

use crate::aovs::Layers;
use crate::load;
use crate::preflight::Forecast;
use crate::progress::Progress;
use crate::progressive::{State, render_progressive, state_path};
use crate::timing::Timing;
use airlight::SceneFile;
use airlight::aov::Aov;
use airlight::film::Image;
use airlight::film::partial::{Partial, PartialHeader, piece};
use airlight::integrator::analytic::LightQuadrature;
use airlight::integrator::{Integrator, IntegratorKind, MAX_LIGHT_STEPS, MAX_STEPS, Sampling};
use airlight::memory::RenderFilm;
use airlight::render::{RenderObserver, accumulate, frame_time, set_time};
use airlight::scene::{MAX_IMAGE_SIDE, MAX_SPP, Scene};
use std::ops::Range;
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
    /// Path: neighbouring pixels' paths share what they gather beyond their
    /// second vertex (scenes without a medium). As `[render] reuse`.
    #[arg(long)]
    reuse: bool,
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
    /// With --frames N: only frame K (0 ≤ K < N), named as --frames names it.
    #[arg(long, value_name = "K", requires = "frames")]
    frame: Option<u32>,
    /// Only the K-th of N contiguous ranges of each pixel's samples
    /// (0 ≤ K < N), written as a partial EXR for `airlight merge`.
    #[arg(long, value_name = "K/N", value_parser = parse_part)]
    shard: Option<(u32, u32)>,
    /// Only the K-th of N bands of rows (0 ≤ K < N), written as a partial
    /// EXR for `airlight merge`; combines with --shard.
    #[arg(long, value_name = "K/N", value_parser = parse_part)]
    tile: Option<(u32, u32)>,
    /// With --progressive: continue the render whose samples so far are kept
    /// beside the output (NAME.partial.exr, rewritten after every pass); the
    /// finished image is the one an uninterrupted render gives, bit for bit.
    #[arg(long, requires = "progressive")]
    resume: bool,
    /// Samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP as i64))]
    spp: Option<u32>,
    /// Spread the samples over the pixels by their noise: spp a pixel on
    /// average, more where a pilot pass found the image noisy (the edges of
    /// lights in view), fewer where it is smooth. As `[render] adaptive`.
    #[arg(long)]
    adaptive: bool,
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
    /// analytic: gauss (Gauss–Legendre) or uniform (equal steps) over lights.
    #[arg(long, value_parser = parse_light_quadrature)]
    light_quadrature: Option<LightQuadrature>,
    /// A medium instead of the scene's (a glTF file has none): the keys of
    /// a scene file's `[medium]` as `key=value` pairs separated by commas,
    /// e.g. `sigma_s=0.05,sigma_a=0.01,g=0.3`, `sigma_s=[0.1,0.1,0.2]` or
    /// `type="height",sigma_s=0.2,falloff=0.5`; `none` for no medium.
    #[arg(long, value_name = "KEY=VALUE,...", value_parser = parse_medium)]
    medium: Option<MediumOption>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_THREADS as i64))]
    threads: Option<u32>,
    /// Also write, as layers of each .exr output, what the camera's first
    /// hits are: a comma-separated list of albedo, normal, depth and
    /// variance (variance implies --progressive); and inscatter, the
    /// medium's light alone (raymarch, analytic, stochastic)
    #[arg(long, value_name = "LIST", value_parser = crate::aovs::parse_list)]
    aov: Option<crate::aovs::AovList>,
    /// No progress bar or summary.
    #[arg(long, short)]
    quiet: bool,
}

/// Where one frame goes: its images and, on request, its variance and
/// the layers its EXR images carry.
pub(crate) struct FrameOutputs {
    pub images: Vec<PathBuf>,
    pub variance: Option<PathBuf>,
    pub layers: Layers,
}

/// What one `render` command computes: which frames, which samples of
/// which rows, and whether as a partial render.
pub struct Plan {
    /// Frame numbers to render, with the count; None for a still image.
    frames: Option<(Vec<u32>, u32)>,
    samples: Range<u64>,
    rows: Range<u32>,
    /// A shard or tile: written as a partial EXR.
    partial: bool,
}

impl Plan {
    fn new(args: &RenderArgs, scene: &Scene) -> Result<Plan, String> {
        let s = scene.settings();
        let frames = match (args.frames, args.frame) {
            (Some(n), Some(k)) if k >= n => {
                return Err(format!("--frame {k}: the animation has frames 0 to {} (--frames {n})", n - 1));
            }
            (Some(n), Some(k)) => Some((vec![k], n)),
            (Some(n), None) => Some(((0..n).collect(), n)),
            (None, _) => None,
        };
        let part = |what: &str, part: Option<(u32, u32)>, total: u64, unit: &str| -> Result<Range<u64>, String> {
            match part {
                None => Ok(0..total),
                Some((_, n)) if n as u64 > total => {
                    Err(format!("--{what} K/{n}: the render has only {total} {unit}, so at most {total} {what}s"))
                }
                Some((k, n)) => Ok(piece(total, k as u64, n as u64)),
            }
        };
        let samples = part("shard", args.shard, s.spp as u64, "samples per pixel")?;
        let rows = part("tile", args.tile, s.height as u64, "rows")?;
        let partial = args.shard.is_some() || args.tile.is_some();
        if partial {
            if args.progressive || args.target_error.is_some() || args.variance.is_some() {
                return Err("--shard and --tile render a fixed part of the samples: they do not go with \
                            --progressive, --target-error or --variance (merge the parts, then compare)"
                    .into());
            }
            match args.output.as_slice() {
                [one] if one.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) => {}
                _ => return Err("--shard and --tile write one partial render: give one `-o PART.exr`".into()),
            }
        }
        Ok(Plan { frames, samples, rows: rows.start as u32..rows.end as u32, partial })
    }

    /// Pixel samples this plan renders.
    fn work(&self, scene: &Scene) -> u64 {
        let frames = self.frames.as_ref().map_or(1, |(list, _)| list.len() as u64);
        let pixels = scene.settings().width as u64 * (self.rows.end - self.rows.start) as u64;
        frames * pixels * (self.samples.end - self.samples.start)
    }
}

/// Everything `render` checks before it renders: the scene with the
/// command line's overrides, what to render, and where it goes.
pub fn prepare(args: &RenderArgs) -> Result<(SceneFile, Plan, Vec<PathBuf>), String> {
    let file = configure(args)?;
    let plan = Plan::new(args, &file.scene)?;
    let outputs = output_paths(args)?;
    if let Some(v) = &args.variance
        && !v.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        return Err(format!("cannot write `{}`: the variance is written as .exr", v.display()));
    }
    if args.variance.is_some() && file.scene.settings().spp < 2 {
        return Err("--variance: a variance needs at least 2 samples per pixel (--spp)".into());
    }
    if args.frames.is_some() && !file.scene.is_animated() {
        return Err("--frames: the scene has no light with keyframes to animate".into());
    }
    Ok((file, plan, outputs))
}

pub fn render(args: RenderArgs) -> Result<(), String> {
    let (SceneFile { mut scene, integrator: desc }, plan, outputs) = prepare(&args)?;
    // Of the scene as resolved, before any frame moves its lights.
    let fingerprint = airlight::fingerprint(&scene, &desc);
    let aovs = args.aov.clone().map(|list| list.0).unwrap_or_default();
    let progressive =
        args.progressive || args.target_error.is_some() || args.variance.is_some() || aovs.contains(&Aov::Variance);
    crate::aovs::check(&aovs, &outputs, plan.partial, desc.kind)?;
    if scene.settings().adaptive && (plan.partial || progressive) {
        return Err("adaptive sampling (--adaptive or `[render] adaptive`) renders in one go, its counts set by a \
                    pilot pass: it does not go with --shard, --tile, --progressive, --target-error, --variance or \
                    --aov variance"
            .into());
    }
    if scene.settings().adaptive && aovs.contains(&Aov::Inscatter) {
        // The layer is drawn with a uniform render's samples, so the image
        // minus it would no longer be the surfaces' light sample for sample.
        return Err("--aov inscatter is drawn with the samples of a uniform render: it does not go with adaptive \
                    sampling (--adaptive or `[render] adaptive`)"
            .into());
    }
    let (files, variance) = (scene.files(), args.variance.as_deref());
    crate::outputs::check_render(args.scene.as_deref(), files, &outputs, variance, args.frames)?;
    // As the frames below are rendered: a part first, then passes.
    let film = match (plan.partial, progressive) {
        (true, _) => RenderFilm::Sums,
        (false, true) => RenderFilm::Progressive { cancellable: false },
        (false, false) if scene.settings().adaptive => RenderFilm::Adaptive,
        (false, false) => RenderFilm::Image,
    };
    crate::preflight::render_memory(&scene, film)?;
    crate::preflight::warn_if_dark(&scene, desc.kind != IntegratorKind::Direct);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0) as usize)
        .build()
        .map_err(|e| format!("cannot start worker threads: {e}"))?;
    let start = Instant::now();
    // Built once: between frames the integrator only hears that the lights
    // moved (radiosity relights without recompiling).
    let mut integrator = pool.install(|| desc.build(&scene)).map_err(|e| e.to_string())?;
    let what = describe(&scene, args.frames);
    let frame_count = plan.frames.as_ref().map_or(1, |(list, _)| list.len() as u32);
    let threads = pool.current_num_threads();
    let probe = pool.install(|| crate::preflight::probe(&scene, integrator.as_ref(), threads, frame_count, &what));
    if let Some(warning) = &probe {
        eprintln!("{warning}");
    }
    let forecast = Forecast::new(plan.work(&scene), what, probe.is_some());
    let progress = Progress::new(plan.work(&scene), args.quiet).with_forecast(forecast);
    let mut written = Vec::new();
    let mut timing = Timing::default();
    let frames: Vec<Option<(u32, u32)>> = match &plan.frames {
        Some((list, n)) => list.iter().map(|&k| Some((k, *n))).collect(),
        None => vec![None],
    };
    for frame in frames {
        let outputs = match frame {
            Some((k, n)) => {
                pool.install(|| set_time(&mut scene, integrator.as_mut(), frame_time(k, n)))
                    .map_err(|e| e.to_string())?;
                FrameOutputs {
                    images: outputs.iter().map(|p| numbered(p, k)).collect(),
                    variance: args.variance.as_deref().map(|p| numbered(p, k)),
                    layers: Layers::none(),
                }
            }
            None => FrameOutputs { images: outputs.clone(), variance: args.variance.clone(), layers: Layers::none() },
        };
        let layers_start = Instant::now();
        let outputs = FrameOutputs {
            layers: Layers::of_frame(&scene, integrator.as_ref(), &pool, &aovs, plan.samples.clone()),
            ..outputs
        };
        if !aovs.is_empty() {
            timing.layers += layers_start.elapsed();
        }
        let frame_label = frame.map(|(k, n)| format!(" frame {k} of {n}")).unwrap_or_default();
        let label = format!("{}{frame_label}", desc.kind);
        let header = PartialHeader {
            version: env!("CARGO_PKG_VERSION").into(),
            scene: fingerprint.clone(),
            seed: scene.settings().seed,
            width: scene.settings().width,
            height: scene.settings().height,
            spp: scene.settings().spp,
            samples: plan.samples.clone(),
            rows: plan.rows.clone(),
            frame,
            exposure: scene.settings().exposure,
            tonemap: scene.settings().tonemap,
        };
        let run =
            Run { scene: &scene, integrator: integrator.as_ref(), pool: &pool, progress: &progress, label: &label };
        let summary = if plan.partial {
            render_partial(&run, &outputs.images[0], header, &mut timing)?
        } else if progressive {
            let state = State { path: state_path(&outputs.images[0]), header, resume: args.resume };
            render_progressive(&run, &outputs, args.target_error, &state, &mut timing)?
        } else {
            render_once(&run, &outputs, &mut timing)?
        };
        if !args.quiet && plan.frames.is_none() && !summary.is_empty() {
            progress.println(&summary);
        }
        written.extend(outputs.images.iter().map(|p| p.display().to_string()));
        written.extend(outputs.variance.iter().map(|p| p.display().to_string()));
    }
    let elapsed = start.elapsed();
    progress.finish();
    if !args.quiet {
        let s = scene.settings();
        let mut what = format!("{}×{}", s.width, s.height);
        if let Some((list, n)) = &plan.frames {
            what = format!("{} of {n} frames of {what}", list.len());
        }
        if plan.partial {
            what = format!("samples {:?} of rows {:?} of {what}", plan.samples, plan.rows);
        }
        let shown = if written.len() > 4 {
            format!("{}, …, {}", written[0], written[written.len() - 1])
        } else {
            written.join(", ")
        };
        eprintln!("rendered {what} in {} → {shown}", timing.summary(elapsed));
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
    if args.adaptive {
        s.adaptive = true;
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
    if args.reuse {
        d.path.reuse = true;
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
    if let Some(MediumOption(medium)) = &args.medium {
        file.scene.set_medium(medium.clone());
    }
    Ok(file)
}

/// `--medium`: a medium, or None for `none`.
#[derive(Clone, Debug)]
pub struct MediumOption(Option<airlight::medium::Medium>);

fn parse_medium(s: &str) -> Result<MediumOption, String> {
    if s.trim() == "none" {
        return Ok(MediumOption(None));
    }
    airlight::scene::medium_from_options(s).map(|m| MediumOption(Some(m)))
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
pub fn numbered(path: &Path, frame: u32) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let name = match path.extension() {
        Some(ext) => format!("{stem}_{frame:04}.{}", ext.to_string_lossy()),
        None => format!("{stem}_{frame:04}"),
    };
    path.with_file_name(name)
}

pub(crate) fn write_images(
    scene: &Scene,
    image: &Image,
    outputs: &FrameOutputs,
    variance: Option<&Image>,
) -> Result<(), String> {
    let s = scene.settings();
    for out in &outputs.images {
        let written = match outputs.layers.channels(variance) {
            Some(channels) if crate::aovs::is_exr(out) => image.save_exr_with_channels(out, &channels),
            _ => image.save_with(out, s.exposure, s.tonemap),
        };
        written.map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
    }
    Ok(())
}

/// What renders one frame: the scene as it is at the frame, the
/// integrator, the worker threads, the progress bar and the frame's label
/// for it ("path frame 3 of 24").
pub(crate) struct Run<'a> {
    pub scene: &'a Scene,
    pub integrator: &'a dyn Integrator,
    pub pool: &'a rayon::ThreadPool,
    pub progress: &'a Progress,
    pub label: &'a str,
}

/// All samples in one go; returns nothing to report.
fn render_once(run: &Run, outputs: &FrameOutputs, timing: &mut Timing) -> Result<String, String> {
    let Run { scene, integrator, pool, progress, label } = *run;
    let s = scene.settings();
    progress.set_message(format!("{label} {}×{} {} spp", s.width, s.height, s.spp));
    let inc = |n: u64| progress.inc(n);
    let observer = RenderObserver { progress: Some(&inc), cancel: None };
    let image = timing.image(|| pool.install(|| airlight::render(scene, integrator, &observer)));
    timing.writing(|| write_images(scene, &image, outputs, None))?;
    Ok(String::new())
}

/// One part of a render (`header`'s samples of its rows), written as a
/// partial EXR.
fn render_partial(run: &Run, output: &Path, header: PartialHeader, timing: &mut Timing) -> Result<String, String> {
    let Run { scene, integrator, pool, progress, label } = *run;
    progress.set_message(format!("{label} samples {:?} of rows {:?}", header.samples, header.rows));
    let inc = |n: u64| progress.inc(n);
    let observer = RenderObserver { progress: Some(&inc), cancel: None };
    let (samples, rows) = (header.samples.clone(), header.rows.clone());
    let sums = timing.image(|| pool.install(|| accumulate(scene, integrator, samples, rows, &observer)));
    timing
        .writing(|| Partial { header, sums }.write(output))
        .map_err(|e| format!("cannot write `{}`: {e}", output.display()))?;
    Ok(String::new())
}

/// "this render (N frames of W×H at S spp)", for the forecast.
fn describe(scene: &Scene, frames: Option<u32>) -> String {
    let s = scene.settings();
    let frames = frames.map(|n| format!("{n} frames of ")).unwrap_or_default();
    format!("this render ({frames}{}×{} at {} spp)", s.width, s.height, s.spp)
}

pub(crate) fn format_error(error: f64) -> String {
    if error.is_finite() { format!("{error:.4}") } else { "unknown (fewer than 2 samples)".into() }
}

fn parse_target_error(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(e) if e > 0.0 && e.is_finite() => Ok(e),
        _ => Err(format!("`{s}` is not a positive number (a relative error, e.g. 0.01)")),
    }
}

/// `K/N` with 0 ≤ K < N.
fn parse_part(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("`{s}` is not K/N with whole numbers 0 ≤ K < N (e.g. 2/8)");
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let (k, n): (u32, u32) = (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if k < n { Ok((k, n)) } else { Err(bad()) }
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
