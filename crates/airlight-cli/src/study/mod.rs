//! `airlight study SCENE`: every integrator that supports the scene, at a
//! ladder of settings and samples, timed and measured against a path-traced
//! ground truth, in one offline HTML report (with the same table on the
//! terminal and, on request, as JSON).
//!
//! The study is a loop of finished steps (a truth's pass, a series' rung),
//! each followed by a rewrite of the report, so stopping it anywhere leaves
//! a report of what was finished; Ctrl-C stops the pass under way and marks
//! the report as stopped.

mod colour;
mod data;
mod plan;
mod plot;
mod ratio;
mod report;
mod run;
mod steps;
mod table;

use crate::load::load;
use crate::outputs::{self, Output};
use crate::progress::Progress;
use airlight::SceneFile;
use airlight::film::Image;
use airlight::integrator::IntegratorKind;
use airlight::render::{RenderJob, RenderRequest};
use airlight::scene::{MAX_IMAGE_SIDE, MAX_SPP, Scene};
use data::{State, Study};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

#[derive(clap::Args)]
pub struct StudyArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Folder for the report (index.html, its plots and images, and every
    /// rung's linear image in exr/). Default: NAME-study.
    #[arg(short, long = "output", value_name = "DIR")]
    output: Option<PathBuf>,
    /// Seconds the whole study may take: the truths up to half, the series
    /// share the rest.
    #[arg(long, value_name = "S", default_value_t = 300.0, value_parser = parse_seconds)]
    time_budget: f64,
    /// Integrators to study, comma-separated (default: all). The truth is
    /// always path; speed ratios need path in the list.
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    integrators: Vec<IntegratorKind>,
    /// Render the truth until its estimated relative error is below E.
    #[arg(long, value_name = "E", default_value_t = 0.005, value_parser = parse_error)]
    truth_error: f64,
    /// Also write the table, with every figure `airlight compare` gives, as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    width: Option<u32>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    height: Option<u32>,
    /// Seed of the series; the truths take seeds of their own from it.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_THREADS as i64))]
    threads: Option<u32>,
    /// No progress display.
    #[arg(long, short)]
    quiet: bool,
}

/// Added to the scene's seed for the truths (full, single), so that their
/// noise is independent of the series' and of each other's.
const TRUTH_SEEDS: [u64; 2] = [0x7275_7468_0001, 0x7275_7468_0002];

/// The scene with the command line's size and seed, and as many samples as
/// a scene may have: the study's runs stop on time or error, not on spp.
fn scene_file(args: &StudyArgs) -> Result<SceneFile, String> {
    let mut file = load(Some(&args.scene))?;
    let s = file.scene.settings_mut();
    s.film.width = args.width.unwrap_or(s.film.width);
    s.film.height = args.height.unwrap_or(s.film.height);
    s.seed = args.seed.unwrap_or(s.seed);
    s.spp = MAX_SPP;
    s.validate()?;
    Ok(file)
}

/// The files at the report's top level, whatever the scene.
const REPORT_FILES: [&str; 8] = [
    "index.html",
    "plot.svg",
    "plot_single.svg",
    "truth.exr",
    "truth.png",
    "truth_single.exr",
    "truth_single.png",
    "multiple_scattering.png",
];

/// Creates the report's folders, having checked where the study will
/// write (outputs.rs): the report's files and the JSON may replace neither
/// the scene nor a file it was read from, nor each other. Refuses a
/// non-empty folder that holds no earlier report, rather than mixing files
/// into it. Returns whether it made the folder.
fn prepare_dir(dir: &Path, args: &StudyArgs, scene: &Scene) -> Result<bool, String> {
    let shown = dir.display();
    let existed = dir.exists();
    if existed {
        let mut entries = std::fs::read_dir(dir).map_err(|e| format!("cannot read `{shown}`: {e}"))?;
        if entries.next().is_some() && !dir.join("index.html").exists() {
            return Err(format!("`{shown}` is not empty and holds no earlier study: give an empty or new folder"));
        }
    }
    outputs::check_folder("-o", dir)?;
    let files: Vec<PathBuf> = REPORT_FILES.iter().map(|f| dir.join(f)).collect();
    let mut written: Vec<Output> = files.iter().map(|path| Output { option: "-o", path }).collect();
    if let Some(json) = &args.json {
        written.push(Output { option: "--json", path: json });
    }
    let inputs: Vec<&Path> =
        std::iter::once(args.scene.as_path()).chain(scene.files().iter().map(PathBuf::as_path)).collect();
    if let Err(e) = outputs::check(&written, &inputs) {
        if !existed {
            // The folder this call made, empty: nothing is left behind.
            let _ = std::fs::remove_dir(dir);
        }
        return Err(e);
    }
    for sub in ["exr", "images"] {
        std::fs::create_dir_all(dir.join(sub))
            .map_err(|e| format!("cannot create `{}`: {e}", dir.join(sub).display()))?;
    }
    Ok(!existed)
}

/// Removes the report folder this study made when it finished nothing: its
/// two empty subfolders and itself (`remove_dir` leaves anything else).
fn remove_empty_report(dir: &Path) {
    for sub in ["exr", "images"] {
        let _ = std::fs::remove_dir(dir.join(sub));
    }
    let _ = std::fs::remove_dir(dir);
}

/// Refuses a study whose images would not fit in memory: a progressive
/// render's, and the images it keeps beside it (the truths, the first
/// image of each of `series` series, a rung's image and error map).
fn check_memory(scene: &Scene, job: &RenderJob, series: usize) -> Result<(), String> {
    let s = scene.settings();
    let pixels = s.film.pixels();
    let image = pixels.saturating_mul(size_of::<airlight::Rgb>() as u64);
    let kept = (series as u64 + 4).saturating_mul(image);
    let needed = job.mode.bytes(pixels).saturating_add(kept);
    airlight::memory::check(format!("a {}×{} study", s.film.width, s.film.height), needed)
        .map_err(|e| format!("{e}: make the image smaller (--width, --height)"))
}

/// Where the study writes and how it keeps time; shared by its steps.
struct Context<'a> {
    dir: &'a Path,
    json: Option<&'a Path>,
    /// Every run's job: passes that a deadline may cancel.
    job: RenderJob,
    pool: rayon::ThreadPool,
    stop: Arc<AtomicBool>,
    start: Instant,
    deadline: Instant,
    progress: Progress,
    quiet: bool,
}

impl Context<'_> {
    /// A line above the progress display, unless quiet.
    fn say(&self, line: &str) {
        if !self.quiet {
            self.progress.println(line);
        }
    }

    fn tick(&self) {
        self.progress.set(self.start.elapsed().as_millis() as u64);
    }

    /// Rewrites the report with the study as it stands.
    fn report(&self, study: &mut Study) -> Result<(), String> {
        study.elapsed_seconds = self.start.elapsed().as_secs_f64();
        study.load_average_now = data::load_average();
        table::fill_derived(study);
        report::write(self.dir, study, self.json)
    }

    fn save(&self, image: &Image, name: &str, scene: &Scene) -> Result<(), String> {
        let path = self.dir.join(name);
        let s = scene.settings();
        image
            .save_with(&path, s.film.exposure, s.film.tonemap)
            .map_err(|e| format!("cannot write `{}`: {e}", path.display()))
    }
}

pub fn study(args: StudyArgs) -> Result<(), String> {
    let SceneFile { mut scene, integrator: desc } = scene_file(&args)?;
    let mut kinds = if args.integrators.is_empty() { IntegratorKind::ALL.to_vec() } else { args.integrators.clone() };
    kinds.dedup();
    let stem = args.scene.file_stem().unwrap_or_default().to_string_lossy();
    let dir = args.output.clone().unwrap_or_else(|| PathBuf::from(format!("{stem}-study")));
    let request = RenderRequest { cancellable: true, threads: args.threads, ..Default::default() };
    let job = request.check(scene.settings(), desc.kind)?;
    check_memory(&scene, &job, plan::ladder(&scene, &desc, &kinds).0.len())?;
    crate::preflight::warn_if_dark(&scene, true);
    let made_dir = prepare_dir(&dir, &args, &scene)?;
    let pool = job.thread_pool()?;
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // A second Ctrl-C ends the study at once; the first stops it tidily.
        signal_hook::flag::register_conditional_shutdown(signal, 130, Arc::clone(&stop))
            .and_then(|_| signal_hook::flag::register(signal, Arc::clone(&stop)))
            .map_err(|e| format!("cannot listen for Ctrl-C: {e}"))?;
    }
    let start = Instant::now();
    let ctx = Context {
        dir: &dir,
        json: args.json.as_deref(),
        job,
        pool,
        stop,
        start,
        deadline: start + Duration::from_secs_f64(args.time_budget),
        progress: Progress::timed((args.time_budget * 1000.0) as u64, args.quiet),
        quiet: args.quiet,
    };
    let s = scene.settings();
    let mut study = Study {
        scene: args.scene.display().to_string(),
        airlight_version: env!("CARGO_PKG_VERSION").into(),
        width: s.film.width,
        height: s.film.height,
        threads: ctx.pool.current_num_threads(),
        time_budget_seconds: args.time_budget,
        truth_error_target: args.truth_error,
        elapsed_seconds: 0.0,
        state: State::Running,
        load_average_start: data::load_average(),
        load_average_now: None,
        error_map_scale: 1.0,
        truths: Vec::new(),
        series: Vec::new(),
        not_run: Vec::new(),
    };
    // (Where the report goes was checked by prepare_dir: it is written
    // once there is something in it.)
    let outcome = steps::truths(&ctx, &mut scene, &desc, &args, &mut study)
        .and_then(|truths| steps::ladder(&ctx, &scene, &desc, &args, &kinds, &truths, &mut study));
    ctx.progress.finish();
    let stopped = ctx.stop.load(Ordering::Relaxed);
    study.state = if stopped { State::Stopped } else { State::Finished };
    if study.truths.iter().all(|t| t.spp == 0) {
        // Nothing finished (a budget too small for the first pass, Ctrl-C
        // at once): no empty report, and an earlier one is left as it was.
        if made_dir {
            remove_empty_report(&dir);
        }
        outcome?;
        return Err(if stopped {
            "stopped by Ctrl-C before anything was finished".into()
        } else {
            "nothing was finished, so no report was written".into()
        });
    }
    // The report of what was finished, even after an error.
    let written = ctx.report(&mut study);
    outcome?;
    written?;
    print!("{}", table::terminal(&study));
    for n in &study.not_run {
        println!("not run: {}: {}", n.label, n.reason);
    }
    let index = dir.join("index.html");
    if stopped {
        return Err(format!("stopped by Ctrl-C; {} holds what was finished", index.display()));
    }
    if !args.quiet {
        eprintln!("study finished in {:.1} s → {}", study.elapsed_seconds, index.display());
    }
    Ok(())
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 1e7 => Ok(v),
        _ => Err(format!("`{s}` is not a number of seconds above 0 (at most 10,000,000)")),
    }
}

fn parse_error(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(e) if e > 0.0 && e < 1.0 => Ok(e),
        _ => Err(format!("`{s}` is not a relative error between 0 and 1 (e.g. 0.005)")),
    }
}
