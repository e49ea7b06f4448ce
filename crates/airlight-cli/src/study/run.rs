//! One progressive run of a study: passes of 1, 1, 2, 4, … samples per
//! pixel until an error target, the run's share of the time budget, the
//! study's deadline or Ctrl-C. Each finished pass is a rung: its image is
//! exactly the one a render at that spp gives (render.rs), and its time the
//! build plus all passes so far.

use airlight::integrator::Integrator;
use airlight::render::{PassesEnd, Progressive, RenderJob, RenderObserver};
use airlight::scene::Scene;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// Reached the error target (truths).
    Target,
    /// Rendered the most samples a run takes.
    Spp,
    /// The next pass would not fit in the run's share of the budget.
    Share,
    /// The study's time budget is spent.
    Deadline,
    /// Ctrl-C.
    User,
    /// The study saw no point in going on (the same image as another series).
    Caller,
    /// A probe before the first pass found that it would end past the
    /// deadline.
    Probe,
}

impl Stop {
    pub fn describe(self) -> &'static str {
        match self {
            Stop::Target => "reached the error target",
            Stop::Spp => "reached the most samples per pixel",
            Stop::Share => "the next rung would not fit in its share of the time budget",
            Stop::Deadline => "the time budget is spent",
            Stop::User => "stopped by Ctrl-C",
            Stop::Caller => "not continued",
            Stop::Probe => "by a probe of a few pixels, its first pass would end past the time budget",
        }
    }
}

pub struct Run<'a> {
    pub scene: &'a Scene,
    pub integrator: &'a dyn Integrator,
    /// Passes that may be cancelled, and their threads (`pool`).
    pub job: &'a RenderJob,
    pub pool: &'a rayon::ThreadPool,
    /// Set by Ctrl-C.
    pub stop: &'a AtomicBool,
    /// No pass runs past this: none starts that would end after it (by
    /// the last pass's pace, or a probe before the first), and one under
    /// way is cancelled as its tiles finish (and lost).
    pub deadline: Instant,
    /// Seconds this run may take, its build included; the first pass runs
    /// whatever it costs (else the run would show nothing), if it fits
    /// before the deadline.
    pub share: f64,
    /// Seconds already spent building the integrator.
    pub built: f64,
    pub target_error: Option<f64>,
    /// Called from the workers as tiles finish (progress display).
    pub tick: &'a (dyn Fn() + Sync),
}

/// What a caller does with each rung: true to go on.
pub type Rung<'a> = dyn FnMut(&Progressive, f64) -> Result<bool, String> + 'a;

/// Renders passes and calls `rung(progressive, seconds)` after each one
/// (not timed: writing images and the report is not the method's cost).
pub fn passes(run: &Run, rung: &mut Rung) -> Result<Stop, String> {
    let mut progressive = Progressive::new(run.scene);
    if progressive.finished() {
        return Ok(Stop::Spp);
    }
    if run.stop.load(Ordering::Relaxed) {
        return Ok(Stop::User);
    }
    if Instant::now() >= run.deadline {
        return Ok(Stop::Deadline);
    }
    // A tile cannot be stopped half way, and one tile of a slow method may
    // take minutes: a first pass that would end past the deadline is not
    // started.
    let Some(probed) = probe(run) else {
        return Ok(Stop::User);
    };
    if Instant::now() + Duration::from_secs_f64(probed.min(1e9)) > run.deadline {
        return Ok(Stop::Probe);
    }
    let cancel = AtomicBool::new(false);
    let tile_done = |_: u64| {
        if run.stop.load(Ordering::Relaxed) || Instant::now() >= run.deadline {
            cancel.store(true, Ordering::Relaxed);
        }
        (run.tick)();
    };
    let observer = RenderObserver { progress: Some(&tile_done), cancel: Some(&cancel) };
    let mut seconds = run.built;
    let mut stopped = None;
    let mut size = progressive.next_pass_size();
    let mut pass_start = Instant::now();
    let after_pass = |p: &Progressive| -> Result<ControlFlow<()>, String> {
        let took = pass_start.elapsed().as_secs_f64();
        seconds += took;
        // Seconds per sample per pixel of the pass just done.
        let per_spp = took / size as f64;
        if !rung(p, seconds)? {
            stopped = Some(Stop::Caller);
            return Ok(ControlFlow::Break(()));
        }
        let now = Instant::now();
        // Pass sizes double, so a pass costs about all before it.
        let predicted = per_spp * p.next_pass_size() as f64;
        stopped = if p.finished() || run.target_error.is_some_and(|t| p.estimated_relative_error() < t) {
            None // run_passes says which
        } else if run.stop.load(Ordering::Relaxed) {
            Some(Stop::User)
        } else if now >= run.deadline {
            Some(Stop::Deadline)
        } else if seconds + predicted > run.share {
            Some(Stop::Share)
        } else if now + Duration::from_secs_f64(predicted.min(1e9)) > run.deadline {
            Some(Stop::Deadline)
        } else {
            None
        };
        size = p.next_pass_size();
        pass_start = Instant::now();
        Ok(if stopped.is_some() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) })
    };
    let (scene, integrator) = (run.scene, run.integrator);
    let end =
        run.job.run_passes(run.pool, scene, integrator, &mut progressive, &observer, run.target_error, after_pass)?;
    Ok(match end {
        PassesEnd::Finished => Stop::Spp,
        PassesEnd::Target => Stop::Target,
        PassesEnd::Cancelled if run.stop.load(Ordering::Relaxed) => Stop::User,
        PassesEnd::Cancelled => Stop::Deadline,
        PassesEnd::Caller => stopped.unwrap_or(Stop::Caller),
    })
}

/// Pixels per side of the grid a probe times.
const PROBE: u32 = 4;

/// The seconds a first pass (one sample of every pixel) would take, by
/// one sample of each of up to 16 pixels spread over the image, spread over
/// the pool's threads; the probe ends early at the deadline. None on
/// Ctrl-C.
fn probe(run: &Run) -> Option<f64> {
    let s = run.scene.settings();
    let start = Instant::now();
    let mut samples = 0;
    for i in 0..PROBE * PROBE {
        if run.stop.load(Ordering::Relaxed) {
            return None;
        }
        let (x, y) =
            ((2 * (i % PROBE) + 1) * s.film.width / (2 * PROBE), (2 * (i / PROBE) + 1) * s.film.height / (2 * PROBE));
        airlight::render::pixel_sum(run.scene, run.integrator, x, y, 0..1);
        samples += 1;
        if Instant::now() >= run.deadline {
            break;
        }
    }
    let per_sample = start.elapsed().as_secs_f64() / samples as f64;
    let pixels = s.film.width as f64 * s.film.height as f64;
    Some(per_sample * pixels / run.pool.current_num_threads().max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use airlight::geometry::Ray;
    use airlight::prelude::*;
    use airlight::sampling::Sampler;

    /// Black, and `per_sample` of sleep for each sample: a slow method.
    struct Slow {
        per_sample: Duration,
    }

    impl Integrator for Slow {
        fn radiance(&self, _: &Scene, _: &Ray, _: &mut Sampler) -> Rgb {
            std::thread::sleep(self.per_sample);
            Rgb::ZERO
        }
    }

    fn scene() -> Scene {
        SceneBuilder::new()
            .size(32, 32)
            .camera(Camera::look_at(vec3(0.0, 1.0, -5.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 40.0))
            .light(Light::point(vec3(0.0, 4.0, -2.0), Rgb::splat(20.0)))
            .build()
            .unwrap()
    }

    /// Runs `integrator` with `seconds` left before the deadline: the stop,
    /// the rungs it made and how long it took.
    fn run_with(integrator: &dyn Integrator, seconds: f64) -> (Stop, u32, Duration) {
        let scene = scene();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let stop = AtomicBool::new(false);
        let start = Instant::now();
        let job = airlight::render::RenderRequest { cancellable: true, ..Default::default() }
            .check(scene.settings(), airlight::integrator::IntegratorKind::Direct)
            .unwrap();
        let run = Run {
            scene: &scene,
            integrator,
            job: &job,
            pool: &pool,
            stop: &stop,
            deadline: start + Duration::from_secs_f64(seconds),
            share: seconds,
            built: 0.0,
            target_error: None,
            tick: &|| {},
        };
        let mut rungs = 0;
        let stopped = passes(&run, &mut |_, _| {
            rungs += 1;
            Ok(true)
        })
        .unwrap();
        (stopped, rungs, start.elapsed())
    }

    #[test]
    fn a_first_pass_that_would_end_past_the_deadline_is_not_started() {
        // A 16×16 tile of 5 ms samples takes 1.3 s on its thread, and the
        // whole first pass 2.6 s on two: a pass started with 0.3 s left would
        // only be cancelled as its first tiles finish, a second late.
        let slow = Slow { per_sample: Duration::from_millis(5) };
        let (stop, rungs, took) = run_with(&slow, 0.3);
        assert_eq!((stop, rungs), (Stop::Probe, 0));
        assert!(took < Duration::from_millis(800), "{took:?}");
    }

    #[test]
    fn a_first_pass_that_fits_runs() {
        // 1 ms samples: a pass of 1 spp takes about 0.5 s on two threads,
        // and the passes of 1, 1, 2 and 4 spp end at about 0.5, 1, 2 and
        // 4 s: the first fits in 2 s even if a loaded machine makes every
        // sleep three times as long, and the run stops because a later
        // pass would not fit. How many passes fit depends on the load, so
        // only their being at least one is asserted, and that the run ends
        // near its share, not a pass late.
        let slow = Slow { per_sample: Duration::from_millis(1) };
        let (stop, rungs, took) = run_with(&slow, 2.0);
        assert_eq!(stop, Stop::Share);
        assert!((1..=3).contains(&rungs), "{rungs} passes");
        assert!(took < Duration::from_millis(3000), "{took:?}");
    }
}
