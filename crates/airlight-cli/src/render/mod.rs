//! `airlight render`: one image, progressive passes (optionally until an
//! error target), the numbered frames of a light animation, or a part of a
//! render (a range of samples, a band of rows, one frame) for a render farm
//! to merge.

mod args;
mod progressive;

pub use args::RenderArgs;

use crate::aovs::Layers;
use crate::preflight::Forecast;
use crate::progress::Progress;
use crate::timing::Timing;
use airlight::SceneFile;
use airlight::film::Image;
use airlight::film::partial::{Partial, PartialHeader};
use airlight::integrator::{Integrator, IntegratorKind};
use airlight::render::{RenderJob, RenderMode, RenderObserver, RenderRequest, Rendered, frame_time, set_time};
use airlight::scene::Scene;
use args::{configure, output_paths};
use progressive::{State, render_progressive, state_path};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where one frame goes: its images and, on request, its variance and
/// the layers its EXR images carry.
pub(crate) struct FrameOutputs {
    pub images: Vec<PathBuf>,
    pub variance: Option<PathBuf>,
    pub layers: Layers,
}

/// What one `render` command computes: which frames, and the render job
/// of each (its mode, which samples of which rows), checked by the
/// library's rules.
pub struct Plan {
    /// Frame numbers to render, with the count; None for a still image.
    frames: Option<(Vec<u32>, u32)>,
    job: RenderJob,
}

impl Plan {
    fn new(args: &RenderArgs, scene: &Scene, integrator: IntegratorKind) -> Result<Plan, String> {
        let frames = match (args.frames, args.frame) {
            (Some(n), Some(k)) if k >= n => {
                return Err(format!("--frame {k}: the animation has frames 0 to {} (--frames {n})", n - 1));
            }
            (Some(n), Some(k)) => Some((vec![k], n)),
            (Some(n), None) => Some(((0..n).collect(), n)),
            (None, _) => None,
        };
        let request = RenderRequest {
            shard: args.shard,
            tile: args.tile,
            passes: args.progressive || args.target_error.is_some(),
            cancellable: false,
            variance: args.variance.is_some(),
            aovs: args.aov.clone().map(|list| list.0).unwrap_or_default(),
            threads: args.threads,
        };
        let job = request.check(scene.settings(), integrator)?;
        if job.partial() {
            match args.output.as_slice() {
                [one] if one.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) => {}
                _ => return Err("--shard and --tile write one partial render: give one `-o PART.exr`".into()),
            }
        }
        Ok(Plan { frames, job })
    }

    /// Pixel samples this plan renders.
    fn work(&self, scene: &Scene) -> u64 {
        let frames = self.frames.as_ref().map_or(1, |(list, _)| list.len() as u64);
        let rows = &self.job.rows;
        let pixels = scene.settings().film.width as u64 * (rows.end - rows.start) as u64;
        frames * pixels * (self.job.samples.end - self.job.samples.start)
    }
}

/// Everything `render` checks before it renders: the scene with the
/// command line's overrides, what to render, and where it goes.
pub fn prepare(args: &RenderArgs) -> Result<(SceneFile, Plan, Vec<PathBuf>), String> {
    let file = configure(args)?;
    let plan = Plan::new(args, &file.scene, file.integrator.kind)?;
    let outputs = output_paths(args)?;
    if let Some(v) = &args.variance
        && !v.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        return Err(format!("cannot write `{}`: the variance is written as .exr", v.display()));
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
    let job = &plan.job;
    crate::aovs::check(&job.aovs, &outputs)?;
    let (files, variance) = (scene.files(), args.variance.as_deref());
    crate::outputs::check_render(args.scene.as_deref(), files, &outputs, variance, args.frames)?;
    if matches!(job.mode, RenderMode::Progressive { .. }) {
        check_checkpoints(&args, files, &outputs)?;
    }
    crate::preflight::render_memory(&scene, job.mode)?;
    crate::preflight::warn_if_dark(&scene, desc.kind != IntegratorKind::Direct);
    // Found before any sample is spent: a missing library is said at once.
    let denoiser = match (args.denoise, args.shard.is_some() || args.tile.is_some()) {
        (false, _) => None,
        (true, true) => {
            return Err("--denoise: a part's sums are denoised after `airlight merge`, not before".into());
        }
        (true, false) => Some(std::sync::Arc::new(airlight::denoise::Denoiser::load(&crate::aovs::oidn_candidates())?)),
    };
    let pool = job.thread_pool()?;
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
            layers: Layers::of_frame(
                &scene,
                integrator.as_ref(),
                &pool,
                &job.aovs,
                job.samples.clone(),
                denoiser.clone(),
            ),
            ..outputs
        };
        if !job.aovs.is_empty() {
            timing.layers += layers_start.elapsed();
        }
        let frame_label = frame.map(|(k, n)| format!(" frame {k} of {n}")).unwrap_or_default();
        let label = format!("{}{frame_label}", desc.kind);
        let header = PartialHeader {
            version: env!("CARGO_PKG_VERSION").into(),
            scene: fingerprint.clone(),
            seed: scene.settings().seed,
            width: scene.settings().film.width,
            height: scene.settings().film.height,
            spp: scene.settings().spp,
            samples: job.samples.clone(),
            rows: job.rows.clone(),
            frame,
            exposure: scene.settings().film.exposure,
            tonemap: scene.settings().film.tonemap,
        };
        let run = Run {
            job,
            scene: &scene,
            integrator: integrator.as_ref(),
            pool: &pool,
            progress: &progress,
            label: &label,
        };
        let summary = if job.partial() {
            render_partial(&run, &outputs.images[0], header, &mut timing)?
        } else if matches!(job.mode, RenderMode::Progressive { .. }) {
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
        let mut what = format!("{}×{}", s.film.width, s.film.height);
        if let Some((list, n)) = &plan.frames {
            what = format!("{} of {n} frames of {what}", list.len());
        }
        if job.partial() {
            what = format!("samples {:?} of rows {:?} of {what}", job.samples, job.rows);
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

/// Passes keep their samples beside the first output (`NAME.partial.exr`,
/// numbered with the frames): that file is written and, once the render is
/// done, removed, so it may be no input and no other output.
fn check_checkpoints(args: &RenderArgs, files: &[PathBuf], outputs: &[PathBuf]) -> Result<(), String> {
    let first = &outputs[0];
    let inputs: Vec<&Path> = args.scene.as_deref().into_iter().chain(files.iter().map(PathBuf::as_path)).collect();
    match args.frames {
        None => {
            let checkpoint = state_path(first);
            let mut written: Vec<crate::outputs::Output> =
                outputs.iter().map(|path| crate::outputs::Output { option: "-o", path }).collect();
            written.extend(args.variance.as_deref().map(|path| crate::outputs::Output { option: "--variance", path }));
            for out in &written {
                if crate::outputs::same_file(out.path, &checkpoint) {
                    return Err(format!(
                        "{} `{}` is where the passes keep their samples (`{}`), which is removed when the render \
                         is done: choose another name",
                        out.option,
                        out.path.display(),
                        checkpoint.display()
                    ));
                }
            }
            crate::outputs::check(&[crate::outputs::Output { option: "the checkpoint", path: &checkpoint }], &inputs)
        }
        // A frame's checkpoint is NAME_0007.partial.exr: an input of that
        // form, for a frame rendered, would be replaced.
        Some(n) => {
            let stem = first.file_stem().unwrap_or_default().to_string_lossy();
            for input in &inputs {
                let name = input.file_name().unwrap_or_default().to_string_lossy();
                let frame = name.strip_prefix(&format!("{stem}_")).and_then(|r| r.strip_suffix(".partial.exr"));
                if let Some(k) = frame.and_then(|k| k.parse::<u32>().ok()).filter(|&k| k < n)
                    && crate::outputs::same_file(input, &state_path(&numbered(first, k)))
                {
                    return Err(format!(
                        "the checkpoint of frame {k} would replace the input `{}`: choose another -o name",
                        input.display()
                    ));
                }
            }
            Ok(())
        }
    }
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
    let image = outputs.layers.finish(image)?;
    let image = image.as_ref();
    for out in &outputs.images {
        let written = match outputs.layers.channels(variance) {
            Some(channels) if crate::aovs::is_exr(out) => image.save_exr_with_channels(out, &channels),
            _ => image.save_with(out, s.film.exposure, s.film.tonemap),
        };
        written.map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
    }
    Ok(())
}

/// What renders one frame: the job, the scene as it is at the frame, the
/// integrator, the job's worker threads, the progress bar and the frame's
/// label for it ("path frame 3 of 24").
pub(crate) struct Run<'a> {
    pub job: &'a RenderJob,
    pub scene: &'a Scene,
    pub integrator: &'a dyn Integrator,
    pub pool: &'a rayon::ThreadPool,
    pub progress: &'a Progress,
    pub label: &'a str,
}

/// All samples in one go; returns nothing to report.
fn render_once(run: &Run, outputs: &FrameOutputs, timing: &mut Timing) -> Result<String, String> {
    let Run { job, scene, integrator, pool, progress, label } = *run;
    let s = scene.settings();
    progress.set_message(format!("{label} {}×{} {} spp", s.film.width, s.film.height, s.spp));
    let inc = |n: u64| progress.inc(n);
    let observer = RenderObserver { progress: Some(&inc), cancel: None };
    let image = timing.image(|| job.run(pool, scene, integrator, &observer).into_image());
    timing.writing(|| write_images(scene, &image, outputs, None))?;
    Ok(String::new())
}

/// One part of a render (`header`'s samples of its rows), written as a
/// partial EXR.
fn render_partial(run: &Run, output: &Path, header: PartialHeader, timing: &mut Timing) -> Result<String, String> {
    let Run { job, scene, integrator, pool, progress, label } = *run;
    progress.set_message(format!("{label} samples {:?} of rows {:?}", header.samples, header.rows));
    let inc = |n: u64| progress.inc(n);
    let observer = RenderObserver { progress: Some(&inc), cancel: None };
    let Rendered::Sums(sums) = timing.image(|| job.run(pool, scene, integrator, &observer)) else {
        return Err("a part of a render gives its sums".into());
    };
    timing
        .writing(|| Partial { header, sums }.write(output))
        .map_err(|e| format!("cannot write `{}`: {e}", output.display()))?;
    Ok(String::new())
}

/// "this render (N frames of W×H at S spp)", for the forecast.
fn describe(scene: &Scene, frames: Option<u32>) -> String {
    let s = scene.settings();
    let frames = frames.map(|n| format!("{n} frames of ")).unwrap_or_default();
    format!("this render ({frames}{}×{} at {} spp)", s.film.width, s.film.height, s.spp)
}

pub(crate) fn format_error(error: f64) -> String {
    if error.is_finite() { format!("{error:.4}") } else { "unknown (fewer than 2 samples)".into() }
}
