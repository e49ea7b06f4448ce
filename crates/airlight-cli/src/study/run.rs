//! One progressive run of a study: passes of 1, 1, 2, 4, … samples per
//! pixel until an error target, the run's share of the time budget, the
//! study's deadline or Ctrl-C. Each finished pass is a rung: its image is
//! exactly the one a render at that spp gives (render.rs), and its time the
//! build plus all passes so far.

use airlight::integrator::Integrator;
use airlight::render::{Progressive, RenderObserver};
use airlight::scene::Scene;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

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
        }
    }
}

pub struct Run<'a> {
    pub scene: &'a Scene,
    pub integrator: &'a dyn Integrator,
    pub pool: &'a rayon::ThreadPool,
    /// Set by Ctrl-C.
    pub stop: &'a AtomicBool,
    /// No pass runs past this: one under way is cancelled (and lost).
    pub deadline: Instant,
    /// Seconds this run may take, its build included; the first pass runs
    /// whatever it costs (else the run would show nothing).
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
    let mut seconds = run.built;
    // Seconds per sample per pixel of the last pass.
    let mut per_spp: Option<f64> = None;
    loop {
        if progressive.finished() {
            return Ok(Stop::Spp);
        }
        if let Some(target) = run.target_error
            && progressive.estimated_relative_error() < target
        {
            return Ok(Stop::Target);
        }
        if run.stop.load(Ordering::Relaxed) {
            return Ok(Stop::User);
        }
        let now = Instant::now();
        if now >= run.deadline {
            return Ok(Stop::Deadline);
        }
        if let Some(per_spp) = per_spp {
            // Pass sizes double, so a pass costs about all before it.
            let predicted = per_spp * progressive.next_pass_size() as f64;
            if seconds + predicted > run.share {
                return Ok(Stop::Share);
            }
            if now + std::time::Duration::from_secs_f64(predicted.min(1e9)) > run.deadline {
                return Ok(Stop::Deadline);
            }
        }
        let cancel = AtomicBool::new(false);
        let tile_done = |_: u64| {
            if run.stop.load(Ordering::Relaxed) || Instant::now() >= run.deadline {
                cancel.store(true, Ordering::Relaxed);
            }
            (run.tick)();
        };
        let observer = RenderObserver { progress: Some(&tile_done), cancel: Some(&cancel) };
        let size = progressive.next_pass_size();
        let start = Instant::now();
        let finished = run.pool.install(|| progressive.pass(run.scene, run.integrator, &observer));
        let took = start.elapsed().as_secs_f64();
        if !finished {
            return Ok(if run.stop.load(Ordering::Relaxed) { Stop::User } else { Stop::Deadline });
        }
        seconds += took;
        per_spp = Some(took / size as f64);
        if !rung(&progressive, seconds)? {
            return Ok(Stop::Caller);
        }
    }
}
