//! The study's two phases: the ground truths, then the ladder of series.
//! Every finished pass is saved and the report rewritten before the next.

use super::data::{Errors, NotRun, Row, Series, Study, Transport, Truth};
use super::plan::{self, SeriesPlan};
use super::run::{self, Run, Stop};
use super::{Context, StudyArgs, TRUTH_SEEDS, colour, scene_file};
use airlight::film::{self, Image};
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::scene::Scene;
use std::sync::atomic::Ordering;
use std::time::Instant;

/// Renders the truths (full transport, and single scattering when the
/// scene asks for more than one event) into the report; returns their
/// images.
pub fn truths(
    ctx: &Context,
    scene: &mut Scene,
    desc: &IntegratorDesc,
    args: &StudyArgs,
    study: &mut Study,
) -> Result<Vec<(Transport, Image)>, String> {
    let depth = desc.path.max_depth;
    // Single scattering first: it is the cheaper, and full transport, the
    // one that matters most, then has what it left of the truths' half.
    let mut wanted = vec![(Transport::Full, depth, "truth", TRUTH_SEEDS[0])];
    if depth > 1 {
        wanted.insert(0, (Transport::Single, 1, "truth_single", TRUTH_SEEDS[1]));
    }
    let base_seed = scene.settings().seed;
    let share = ctx.deadline.duration_since(ctx.start).as_secs_f64() / 2.0;
    let mut spent = 0.0;
    let mut images = Vec::new();
    for (i, &(transport, max_depth, name, offset)) in wanted.iter().enumerate() {
        let seed = base_seed.wrapping_add(offset);
        scene.settings_mut().seed = seed;
        let mut d = desc.with_kind(IntegratorKind::Path);
        d.path.max_depth = max_depth;
        let begun = Instant::now();
        let integrator = ctx.pool.install(|| d.build(scene)).map_err(|e| format!("path: {e}"))?;
        let built = begun.elapsed().as_secs_f64();
        study.truths.push(Truth {
            transport,
            max_depth,
            seed,
            spp: 0,
            seconds: 0.0,
            estimated_error: f64::INFINITY,
            reached_target: false,
            exr: format!("{name}.exr"),
            png: format!("{name}.png"),
        });
        let what = if transport == Transport::Single { "single scattering" } else { "full transport" };
        let tick = || ctx.tick();
        let run = Run {
            scene,
            integrator: integrator.as_ref(),
            job: &ctx.job,
            pool: &ctx.pool,
            stop: &ctx.stop,
            deadline: ctx.deadline,
            share: (share - spent) / (wanted.len() - i) as f64,
            built,
            target_error: Some(args.truth_error),
            tick: &tick,
        };
        let mut last = None;
        let stop = run::passes(&run, &mut |p, seconds| {
            let image = p.image();
            ctx.save(&image, &format!("{name}.exr"), scene)?;
            ctx.save(&image, &format!("{name}.png"), scene)?;
            let truth = study.truths.last_mut().expect("pushed above");
            (truth.spp, truth.seconds, truth.estimated_error) = (p.samples(), seconds, p.estimated_relative_error());
            ctx.progress.set_message(format!(
                "truth ({what}): {} spp, estimated error {:.4}",
                p.samples(),
                truth.estimated_error
            ));
            last = Some(image);
            ctx.report(study)?;
            Ok(true)
        })?;
        let truth = study.truths.last_mut().expect("pushed above");
        truth.reached_target = stop == Stop::Target;
        spent += truth.seconds;
        let summary = format!(
            "truth ({what}): {} spp in {:.1} s, estimated relative error {:.4} ({})",
            truth.spp,
            truth.seconds,
            truth.estimated_error,
            stop.describe()
        );
        ctx.say(&summary);
        match (last, stop) {
            (_, Stop::User) => return Err("stopped by Ctrl-C while rendering the truth".into()),
            (None, _) => {
                return Err(format!(
                    "the truth's first pass did not fit in the time budget ({}): give a larger --time-budget \
                     or a smaller --width/--height",
                    stop.describe()
                ));
            }
            (Some(image), _) => images.push((transport, image)),
        }
    }
    scene.settings_mut().seed = base_seed;
    // Full transport first: the truth of the scene, whatever else there is.
    study.truths.sort_by_key(|t| t.transport != Transport::Full);
    images.sort_by_key(|(t, _)| *t != Transport::Full);
    let full = &images[0].1;
    let mean = full.mean();
    study.error_map_scale = ((mean.x + mean.y + mean.z) as f64 / 3.0).max(1e-12);
    if let [(_, full), (_, single)] = images.as_slice() {
        ctx.save(&colour::error_map(single, full, study.error_map_scale), "multiple_scattering.png", scene)?;
    }
    Ok(images)
}

/// The image a series is measured against, and full transport's when
/// that is another.
fn truth_images(truths: &[(Transport, Image)], transport: Transport) -> (&Image, Option<&Image>) {
    let full = &truths[0].1;
    match truths.iter().find(|(t, _)| *t == transport) {
        Some((Transport::Single, single)) => (single, Some(full)),
        _ => (full, None),
    }
}

fn errors(image: &Image, truth: &Image) -> Result<Errors, String> {
    film::compare(image, truth).map(Errors::from).ok_or_else(|| "an image and its truth differ in size".into())
}

/// Runs every series of the ladder in turn, each with an even share of the
/// time left.
pub fn ladder(
    ctx: &Context,
    scene: &Scene,
    desc: &IntegratorDesc,
    args: &StudyArgs,
    kinds: &[IntegratorKind],
    truths: &[(Transport, Image)],
    study: &mut Study,
) -> Result<(), String> {
    let (plans, refused) = plan::ladder(scene, desc, kinds);
    study.not_run.extend(refused);
    // Each run's first image, to notice a series that computes the same.
    let mut firsts: Vec<(String, Image)> = Vec::new();
    for (k, plan) in plans.iter().enumerate() {
        let now = Instant::now();
        let not_run = |reason: &str| NotRun { label: plan.label.clone(), reason: reason.into() };
        if ctx.stop.load(Ordering::Relaxed) {
            study.not_run.push(not_run("stopped by Ctrl-C before it ran"));
            continue;
        }
        if now >= ctx.deadline {
            study.not_run.push(not_run("the time budget was spent before it ran"));
            continue;
        }
        let share = ctx.deadline.duration_since(now).as_secs_f64() / (plans.len() - k) as f64;
        let variant;
        let scene = match plan.attenuation {
            None => scene,
            Some(model) => {
                variant = attenuated(args, model)?;
                &variant
            }
        };
        let begun = Instant::now();
        let integrator = match ctx.pool.install(|| plan.desc.build(scene)) {
            Ok(integrator) => integrator,
            Err(e) => {
                study.not_run.push(not_run(&e.to_string()));
                continue;
            }
        };
        let built = begun.elapsed().as_secs_f64();
        let stop = series(ctx, scene, plan, integrator.as_ref(), built, share, truths, &mut firsts, study)?;
        let s = study.series.last_mut().expect("series pushes its record");
        s.stopped_by = Some(stop.describe().into());
        if let Some(last) = s.rows.last() {
            let summary = format!(
                "{}: {} rungs to {} spp in {:.2} s, relative RMSE {:.4} ({})",
                s.label,
                s.rows.len(),
                last.spp,
                last.seconds,
                last.error.rel_rmse,
                stop.describe()
            );
            ctx.say(&summary);
        }
        // A series with nothing to show leaves the table for the list.
        let reason = match (&stop, s.rows.is_empty()) {
            (Stop::Caller, _) => Some(format!(
                "the same image as {} at 1 spp, bit for bit: not continued",
                firsts.iter().find(|(_, f)| *f == firsts[firsts.len() - 1].1).map_or("another", |(l, _)| l)
            )),
            (Stop::Probe, true) => Some(format!("not started: {}", stop.describe())),
            (_, true) => Some(format!("no pass finished: {}", stop.describe())),
            _ => None,
        };
        if let Some(reason) = reason {
            let s = study.series.pop().expect("checked above");
            for row in &s.rows {
                let _ = std::fs::remove_file(ctx.dir.join(&row.exr));
            }
            let _ = std::fs::remove_file(ctx.dir.join(&s.png));
            let _ = std::fs::remove_file(ctx.dir.join(&s.error_png));
            study.not_run.push(not_run(&reason));
        }
        ctx.report(study)?;
    }
    Ok(())
}

/// The scene again, with every point, spot and sphere light's falloff
/// switched to `model`.
fn attenuated(args: &StudyArgs, model: airlight::light::AttenuationModel) -> Result<Scene, String> {
    let mut scene = scene_file(args)?.scene;
    scene.set_attenuation_model(model)?;
    Ok(scene)
}

/// One series: its record in the study, then its rungs.
#[allow(clippy::too_many_arguments)]
fn series(
    ctx: &Context,
    scene: &Scene,
    plan: &SeriesPlan,
    integrator: &dyn airlight::integrator::Integrator,
    built: f64,
    share: f64,
    truths: &[(Transport, Image)],
    firsts: &mut Vec<(String, Image)>,
    study: &mut Study,
) -> Result<Stop, String> {
    study.series.push(Series {
        id: plan.id.clone(),
        label: plan.label.clone(),
        integrator: plan.kind.name().into(),
        setting: plan.setting.clone(),
        transport: plan.transport,
        build_seconds: built,
        rows: Vec::new(),
        png: format!("images/{}.png", plan.id),
        error_png: format!("images/{}_error.png", plan.id),
        stopped_by: None,
    });
    let (truth, full) = truth_images(truths, plan.transport);
    let tick = || ctx.tick();
    let run = Run {
        scene,
        integrator,
        job: &ctx.job,
        pool: &ctx.pool,
        stop: &ctx.stop,
        deadline: ctx.deadline,
        share,
        built,
        target_error: None,
        tick: &tick,
    };
    run::passes(&run, &mut |p, seconds| {
        let image = p.image();
        if p.samples() == 1 {
            if firsts.iter().any(|(_, f)| *f == image) {
                firsts.push((plan.label.clone(), image));
                return Ok(false);
            }
            firsts.push((plan.label.clone(), image.clone()));
        }
        let exr = format!("exr/{}_spp{}.exr", plan.id, p.samples());
        ctx.save(&image, &exr, scene)?;
        let s = study.series.last_mut().expect("pushed above");
        ctx.save(&image, &s.png, scene)?;
        ctx.save(&super::colour::error_map(&image, truth, study.error_map_scale), &s.error_png, scene)?;
        let row = Row {
            spp: p.samples(),
            seconds,
            exr,
            error: errors(&image, truth)?,
            error_full: full.map(|f| errors(&image, f)).transpose()?,
            speed_ratio: None,
            ratio_extrapolated: false,
            near_truth_noise: false,
        };
        ctx.progress.set_message(format!("{}: {} spp, relative RMSE {:.4}", plan.label, row.spp, row.error.rel_rmse));
        study.series.last_mut().expect("pushed above").rows.push(row);
        ctx.report(study)?;
        Ok(true)
    })
}
