//! What a study has measured so far: the truths, each series' rungs with
//! their errors, and what did not run and why. The report, the terminal
//! table and the JSON are all written from this one record.

use airlight::film::ImageError;
use serde::Serialize;

/// Which ground truth a series is measured against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Transport {
    /// Single scattering: path at max_depth 1 (the scene's truth when its
    /// max_depth is 1).
    Single,
    /// The scene's own max_depth.
    Full,
}

/// Where the study stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum State {
    Running,
    Finished,
    /// Stopped by Ctrl-C (or SIGTERM): what is here was finished before.
    Stopped,
}

#[derive(Clone, Debug, Serialize)]
pub struct Study {
    pub scene: String,
    pub airlight_version: String,
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub time_budget_seconds: f64,
    pub truth_error_target: f64,
    pub elapsed_seconds: f64,
    pub state: State,
    /// /proc/loadavg's 1, 5 and 15 minute loads at the start and at the
    /// latest rewrite: times on a shared machine depend on them.
    pub load_average_start: Option<[f64; 3]>,
    pub load_average_now: Option<[f64; 3]>,
    /// The error maps' colour scale runs over [scale/1000, scale], log.
    pub error_map_scale: f64,
    pub truths: Vec<Truth>,
    pub series: Vec<Series>,
    /// Series that did not run, and integrators that refused the scene.
    pub not_run: Vec<NotRun>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Truth {
    pub transport: Transport,
    pub max_depth: u32,
    pub seed: u64,
    pub spp: u32,
    pub seconds: f64,
    /// The accumulator's √(Σ Var(pixel mean)/Σ mean²).
    pub estimated_error: f64,
    /// False when the time budget stopped it before the target.
    pub reached_target: bool,
    pub exr: String,
    pub png: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct Series {
    pub id: String,
    pub label: String,
    pub integrator: String,
    pub setting: String,
    pub transport: Transport,
    /// Building the integrator (radiosity's solution, analytic tables),
    /// counted in every rung's time.
    pub build_seconds: f64,
    pub rows: Vec<Row>,
    /// The last rung's image and its error map against its truth.
    pub png: String,
    pub error_png: String,
    /// Why the ladder stopped where it did (once it has).
    pub stopped_by: Option<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub spp: u32,
    /// Wall-clock seconds: the build plus every pass up to this one.
    pub seconds: f64,
    pub exr: String,
    /// Against the series' own truth (see [`Series::transport`]).
    pub error: Errors,
    /// Against full transport, for single-scattering series when the
    /// scene asks for more than one scattering event.
    pub error_full: Option<Errors>,
    /// See `ratio.rs`: how much faster than the reference path tracer at
    /// this row's error; None without a reference.
    pub speed_ratio: Option<f64>,
    /// The reference's time came from beyond its measured rungs.
    pub ratio_extrapolated: bool,
    /// The error is below twice the truth's estimated error: much of it
    /// may be the truth's own noise.
    pub near_truth_noise: bool,
}

/// The figures `airlight compare` prints.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Errors {
    pub rmse: f64,
    pub rel_mse: f64,
    pub mae: f64,
    pub max: f64,
    pub rel_rmse: f64,
}

impl From<ImageError> for Errors {
    fn from(e: ImageError) -> Self {
        Errors { rmse: e.rmse, rel_mse: e.rel_mse, mae: e.mae, max: e.max, rel_rmse: e.rel_rmse }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct NotRun {
    pub label: String,
    pub reason: String,
}

impl Study {
    /// The truth a series of `transport` is measured against.
    pub fn truth_for(&self, transport: Transport) -> Option<&Truth> {
        self.truths.iter().find(|t| t.transport == transport).or_else(|| self.truths.first())
    }

    /// Whether single-scattering series have a truth of their own (the
    /// scene asks for more than one scattering event).
    pub fn has_single_truth(&self) -> bool {
        self.truths.iter().any(|t| t.transport == Transport::Single)
    }
}

/// /proc/loadavg's three loads; None where there is no such file.
pub fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = text.split_whitespace().map(|v| v.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}
