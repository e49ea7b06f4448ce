//! `airlight render`: one image, progressive passes (optionally until an
//! error target), the numbered frames of a light animation, or a part of a
//! render (a range of samples, a band of rows, one frame) for a render farm
//! to merge.

mod args;

pub use args::RenderArgs;

use crate::aovs::Layers;
use crate::preflight::Forecast;
use crate::progress::Progress;
use crate::progressive::{State, render_progressive, state_path};
use crate::timing::Timing;
use airlight::SceneFile;
use airlight::aov::Aov;
use airlight::film::Image;
use airlight::film::partial::{Partial, PartialHeader, piece};
use airlight::integrator::{Integrator, IntegratorKind};
use airlight::memory::RenderFilm;
use airlight::render::{RenderObserver, accumulate, frame_time, set_time};
use airlight::scene::Scene;
use args::{configure, output_paths};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
