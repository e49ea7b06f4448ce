//! One render from Python: the work runs on its own thread (with a rayon
//! pool of the requested size) while the calling thread, GIL released,
//! waits for it; every 50 ms it takes the GIL back to check for Ctrl-C and,
//! at most every 0.1 s, to report progress.

use crate::errors::{integrator_error, internal_error, panic_message};
use crate::shared::{Pose, Shared};
use airlight::Rgb;
use airlight::aov::{SurfaceAovs, surface_aovs};
use airlight::film::PixelSum;
use airlight::integrator::IntegratorDesc;
use airlight::render::{RenderJob, RenderObserver, Rendered};
use airlight::scene::RenderSettings;
use pyo3::exceptions::{PyImportError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, TryLockError};
use std::time::{Duration, Instant};

/// How often the waiting thread looks for Ctrl-C.
const POLL: Duration = Duration::from_millis(50);
/// Least time between two progress reports.
const REPORT: Duration = Duration::from_millis(100);
/// How long a cancelled render may take to stop before the exception is
/// raised anyway (a radiosity compile cannot be cut short; it then ends on
/// its own thread).
const STOP_WAIT: Duration = Duration::from_millis(800);

/// What to render.
pub struct Job {
    pub shared: Arc<Mutex<Shared>>,
    pub settings: RenderSettings,
    pub desc: IntegratorDesc,
    pub pose: Pose,
    /// The render's samples, rows, AOVs and threads, checked by the
    /// library's rules.
    pub render: RenderJob,
    /// Also the first hits' albedo, normal and depth.
    pub surface: bool,
}

/// A render's pixels, H·W RGB triples each: the mean of each pixel's
/// samples and, on request, its estimated variance and the first-hit
/// outputs over the same camera rays.
pub struct Output {
    pub color: Vec<f32>,
    pub variance: Option<Vec<f32>>,
    pub surface: Option<SurfaceAovs>,
}

enum Failure {
    Integrator(String),
    Pool(String),
    Cancelled,
    Panic(String),
}

/// What the render thread and the waiting thread share.
#[derive(Default)]
struct State {
    cancel: AtomicBool,
    /// Pixel samples finished.
    done: AtomicU64,
    result: Mutex<Option<Result<Output, Failure>>>,
    finished: Condvar,
}

impl State {
    /// The result, once there, waiting at most `timeout` for it.
    fn wait(&self, timeout: Duration) -> Option<Result<Output, Failure>> {
        let slot = self.result.lock().unwrap_or_else(|p| p.into_inner());
        let (mut slot, _) =
            self.finished.wait_timeout_while(slot, timeout, |r| r.is_none()).unwrap_or_else(|p| p.into_inner());
        slot.take()
    }
}

/// Runs `job`, reporting to `progress`; the accumulated samples, or the
/// exception to raise (KeyboardInterrupt on Ctrl-C).
pub fn run(py: Python<'_>, job: Job, progress: Option<Progress>) -> PyResult<Output> {
    let s = &job.settings;
    let samples = &job.render.samples;
    let total = s.film.pixels() * (samples.end - samples.start);
    let mut progress = progress.map(|p| Reporter::start(py, p, total)).transpose()?;
    let state = Arc::new(State::default());
    let worker = Arc::clone(&state);
    let spawned = std::thread::Builder::new().name("airlight-render".into()).spawn(move || {
        let result = catch_unwind(AssertUnwindSafe(|| work(&job, &worker)))
            .unwrap_or_else(|payload| Err(Failure::Panic(panic_message(payload.as_ref()))));
        *worker.result.lock().unwrap_or_else(|p| p.into_inner()) = Some(result);
        worker.finished.notify_all();
    });
    if let Err(e) = spawned {
        return Err(PyRuntimeError::new_err(format!("cannot start the render thread: {e}")));
    }
    let outcome = loop {
        if let Some(result) = py.detach(|| state.wait(POLL)) {
            break result.map_err(failure);
        }
        // Ctrl-C (on the main thread; elsewhere this does nothing), or a
        // progress callback that raised: stop the render and raise.
        let interrupted = py.check_signals().and_then(|()| match progress.as_mut() {
            Some(p) => p.report(py, state.done.load(Ordering::Relaxed), false),
            None => Ok(()),
        });
        if let Err(e) = interrupted {
            state.cancel.store(true, Ordering::Relaxed);
            let _ = py.detach(|| state.wait(STOP_WAIT));
            break Err(e);
        }
    };
    if let Some(p) = progress.as_mut() {
        let reported = match &outcome {
            Ok(_) => p.report(py, total, true),
            Err(_) => Ok(()),
        };
        p.close(py)?;
        reported?;
    }
    outcome
}

fn failure(f: Failure) -> PyErr {
    match f {
        Failure::Integrator(message) => integrator_error(message),
        Failure::Pool(message) => PyRuntimeError::new_err(message),
        // Only a cancel the waiting thread asked for stops a render, and it
        // raises its own exception.
        Failure::Cancelled => PyRuntimeError::new_err("the render was cancelled"),
        Failure::Panic(message) => internal_error(&message),
    }
}

/// The render thread: takes the scene, brings it and its integrator to the
/// job's pose and settings, and renders.
fn work(job: &Job, state: &State) -> Result<Output, Failure> {
    let pool = job.render.thread_pool().map_err(Failure::Pool)?;
    let mut guard = lock(&job.shared, &state.cancel)?;
    // The guard itself may not cross threads; what it guards may.
    let shared: &mut Shared = &mut guard;
    *shared.scene.settings_mut() = job.settings.clone();
    pool.install(|| shared.prepare(job.desc, job.pose)).map_err(|e| Failure::Integrator(e.to_string()))?;
    let shared: &Shared = shared;
    let integrator = shared.integrator();
    let count = |n: u64| {
        state.done.fetch_add(n, Ordering::Relaxed);
    };
    let observer = RenderObserver { progress: Some(&count), cancel: Some(&state.cancel) };
    // Built here, off the GIL, into the buffers the arrays will own.
    fn flat(pixels: impl Iterator<Item = Rgb>) -> Vec<f32> {
        pixels.flat_map(|p| p.to_array()).collect()
    }
    let samples = &job.render.samples;
    // A variance needs every pixel's sums kept to the end, as does a shard
    // (whose sums give its mean here).
    let (color, variance) = match job.render.run(&pool, &shared.scene, integrator, &observer) {
        Rendered::Image(image) => (flat(image.pixels.into_iter()), None),
        Rendered::Sums(sums) => {
            let variance =
                job.render.variance.then(|| flat(sums.pixels().iter().map(|p| p.variance_of_mean().as_vec3())));
            (flat(sums.pixels().iter().map(PixelSum::mean)), variance)
        }
    };
    if state.cancel.load(Ordering::Relaxed) {
        return Err(Failure::Cancelled);
    }
    // As `airlight render --aov` computes them: over the camera rays of the
    // render's own samples.
    let surface =
        job.surface.then(|| pool.install(|| surface_aovs(&shared.scene, integrator.stratified(), samples.clone())));
    Ok(Output { color, variance, surface })
}

/// The shared scene, once no other render holds it (scenes made by
/// `at_time` share one), or nothing if the render is cancelled meanwhile.
fn lock<'a>(shared: &'a Mutex<Shared>, cancel: &AtomicBool) -> Result<MutexGuard<'a, Shared>, Failure> {
    loop {
        match shared.try_lock() {
            Ok(guard) => return Ok(guard),
            Err(TryLockError::Poisoned(p)) => {
                // A render panicked while it held the scene: what it was
                // changing is rebuilt before use.
                let mut guard = p.into_inner();
                guard.forget();
                shared.clear_poison();
                return Ok(guard);
            }
            Err(TryLockError::WouldBlock) if cancel.load(Ordering::Relaxed) => return Err(Failure::Cancelled),
            Err(TryLockError::WouldBlock) => std::thread::sleep(Duration::from_millis(5)),
        }
    }
}

/// Where progress goes: a callable `f(done, total)`, or a tqdm-like object
/// (`update(n)`, `total`); `owned` bars were made here and are closed here.
pub enum Progress {
    Callback(Py<PyAny>),
    Bar { bar: Py<PyAny>, owned: bool },
}

impl Progress {
    /// `progress=` as given: None/False, True (a tqdm bar made here), an
    /// object with `update` (tqdm), or a callable.
    pub fn from_arg(py: Python<'_>, arg: Option<&Bound<'_, PyAny>>, label: &str) -> PyResult<Option<Progress>> {
        let Some(arg) = arg.filter(|a| !a.is_none()) else { return Ok(None) };
        if let Ok(flag) = arg.cast::<pyo3::types::PyBool>() {
            if !flag.is_true() {
                return Ok(None);
            }
            let tqdm = py
                .import("tqdm.auto")
                .map_err(|_| PyImportError::new_err("progress=True shows a tqdm bar: pip install tqdm"))?;
            let kwargs = PyDict::new(py);
            kwargs.set_item("desc", label)?;
            kwargs.set_item("unit", " samples")?;
            kwargs.set_item("unit_scale", true)?;
            let bar = tqdm.getattr("tqdm")?.call((), Some(&kwargs))?;
            return Ok(Some(Progress::Bar { bar: bar.unbind(), owned: true }));
        }
        if arg.hasattr("update")? {
            return Ok(Some(Progress::Bar { bar: arg.clone().unbind(), owned: false }));
        }
        if arg.is_callable() {
            return Ok(Some(Progress::Callback(arg.clone().unbind())));
        }
        Err(pyo3::exceptions::PyTypeError::new_err(
            "progress must be a callable f(done, total), a tqdm bar, True or None",
        ))
    }
}

struct Reporter {
    to: Progress,
    total: u64,
    reported: u64,
    last: Instant,
}

impl Reporter {
    fn start(py: Python<'_>, to: Progress, total: u64) -> PyResult<Reporter> {
        if let Progress::Bar { bar, .. } = &to {
            let bar = bar.bind(py);
            // A bar made without a total learns it; its count starts at 0.
            if bar.getattr("total")?.is_none() || matches!(to, Progress::Bar { owned: true, .. }) {
                bar.setattr("total", total)?;
                bar.call_method0("refresh")?;
            }
        }
        Ok(Reporter { to, total, reported: 0, last: Instant::now() })
    }

    /// Reports `done` pixel samples if 0.1 s have passed (or `force`).
    fn report(&mut self, py: Python<'_>, done: u64, force: bool) -> PyResult<()> {
        if done == self.reported || !force && self.last.elapsed() < REPORT {
            return Ok(());
        }
        let done = done.min(self.total);
        match &self.to {
            Progress::Callback(f) => {
                f.call1(py, (done, self.total))?;
            }
            Progress::Bar { bar, .. } => {
                bar.call_method1(py, "update", (done - self.reported,))?;
            }
        }
        self.reported = done;
        self.last = Instant::now();
        Ok(())
    }

    fn close(&self, py: Python<'_>) -> PyResult<()> {
        if let Progress::Bar { bar, owned: true } = &self.to {
            bar.call_method0(py, "close")?;
        }
        Ok(())
    }
}
