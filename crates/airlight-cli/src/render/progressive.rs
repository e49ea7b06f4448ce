//! `render --progressive` (also `--target-error`, `--variance`): passes of
//! doubling size, each rewriting the outputs and the samples so far, which
//! `--resume` continues from after an interruption.

use super::{FrameOutputs, Run, format_error, write_images};
use crate::progress::Progress;
use crate::timing::Timing;
use airlight::film::partial::{self, Partial, PartialHeader};
use airlight::render::{Progressive, RenderObserver};
use airlight::scene::Scene;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// Where a progressive render keeps its samples so far, and what they are.
pub(crate) struct State {
    pub path: PathBuf,
    /// The render's header, for any number of samples.
    pub header: PartialHeader,
    /// Continue from the file if it is there.
    pub resume: bool,
}

/// `NAME.partial.exr` beside the output `NAME.png` or `NAME.exr`.
pub(crate) fn state_path(output: &Path) -> PathBuf {
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    output.with_file_name(format!("{stem}.partial.exr"))
}

/// The progressive render that `state` holds the first samples of, when
/// resuming and it is there; it must be of this very render.
fn resumed(scene: &Scene, state: &State, outputs: &FrameOutputs, progress: &Progress) -> Result<Progressive, String> {
    if state.resume && !state.path.exists() {
        // Without its samples, a finished image would be replaced pass by
        // pass by one of fewer samples.
        if let Some(done) = outputs.images.iter().chain(&outputs.variance).find(|p| p.exists()) {
            return Err(format!(
                "--resume: there are no samples to continue (`{}`), and `{}` exists: the render finished, or another \
                 wrote it; remove it to render again",
                state.path.display(),
                done.display()
            ));
        }
    }
    if !state.resume || !state.path.exists() {
        if state.resume {
            progress.println(&format!("--resume: no `{}`, starting from the first sample", state.path.display()));
        }
        return Ok(Progressive::new(scene));
    }
    let name = state.path.display();
    let part = Partial::read(&state.path).map_err(|e| format!("--resume: {name}: {e}"))?;
    let (a, b) = (&part.header, &state.header);
    if (&a.scene, a.seed, a.width, a.height, a.spp, a.frame) != (&b.scene, b.seed, b.width, b.height, b.spp, b.frame)
        || a.version != b.version
    {
        return Err(format!(
            "--resume: {name} holds samples of another render (scene, seed, size, spp, frame or Airlight version \
             differ); remove it to start again"
        ));
    }
    if a.samples.start != 0 || a.rows != (0..b.height) || a.samples.end > b.spp as u64 {
        return Err(format!("--resume: {name} does not hold the first samples of every row"));
    }
    progress.println(&format!("resuming from {} samples per pixel in {name}", a.samples.end));
    progress.inc(a.samples.end * b.width as u64 * b.height as u64);
    Ok(Progressive::resume(scene, part.sums, a.samples.end as u32))
}

/// Passes of doubling size, each rewriting the outputs and the samples so
/// far (atomically, so stopping the render loses at most the pass under
/// way), until spp or the error target; returns the samples reached and the
/// estimated error. The samples-so-far file is removed once done.
pub(crate) fn render_progressive(
    run: &Run,
    outputs: &FrameOutputs,
    target_error: Option<f64>,
    state: &State,
    timing: &mut Timing,
) -> Result<String, String> {
    let Run { job, scene, integrator, pool, progress, label } = *run;
    let s = scene.settings();
    let mut progressive = resumed(scene, state, outputs, progress)?;
    if progressive.samples() > 0
        && (progressive.finished()
            || target_error.is_some_and(|target| progressive.estimated_relative_error() < target))
    {
        // Stopped after its last pass, before it tidied up: the images again.
        let variance = outputs.layers.wants_variance().then(|| progressive.variance());
        timing.writing(|| write_images(scene, &progressive.image(), outputs, variance.as_ref()))?;
    }
    let inc = |n: u64| progress.inc(n);
    let observer = RenderObserver { progress: Some(&inc), cancel: None };
    let after_pass = |progressive: &Progressive, timing: &mut Timing| -> Result<ControlFlow<()>, String> {
        let error = progressive.estimated_relative_error();
        progress.set_message(format!(
            "{label} {}×{} {}/{} spp, est. error {}",
            s.film.width,
            s.film.height,
            progressive.samples(),
            s.spp,
            format_error(error),
        ));
        timing.writing(|| {
            // The variance is known from the second sample on; made once for
            // the image's layers and the --variance file (EXR: linear, the
            // tone map is not applied).
            let variance_file = outputs.variance.as_ref().filter(|_| progressive.samples() >= 2);
            let variance = (outputs.layers.wants_variance() || variance_file.is_some()).then(|| progressive.variance());
            write_images(
                scene,
                &progressive.image(),
                outputs,
                variance.as_ref().filter(|_| outputs.layers.wants_variance()),
            )?;
            if let (Some(path), Some(variance)) = (variance_file, &variance) {
                variance.save(path).map_err(|e| format!("cannot write `{}`: {e}", path.display()))?;
            }
            let header = PartialHeader { samples: 0..progressive.samples() as u64, ..state.header.clone() };
            // The running sums themselves, not a copy (112 bytes a pixel).
            partial::write(&state.path, &header, progressive.accumulator())
                .map_err(|e| format!("cannot write `{}`: {e}", state.path.display()))
        })?;
        Ok(ControlFlow::Continue(()))
    };
    timing.image_writing(|timing| {
        job.run_passes(pool, scene, integrator, &mut progressive, &observer, target_error, |p| after_pass(p, timing))
    })?;
    let error = progressive.estimated_relative_error();
    let _ = std::fs::remove_file(&state.path);
    // Samples skipped by reaching the target still count toward the bar.
    let skipped = (s.spp - progressive.samples()) as u64 * s.film.pixels();
    progress.inc(skipped);
    Ok(format!("{} spp, estimated relative error {}", progressive.samples(), format_error(error)))
}
