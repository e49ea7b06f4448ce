//! `airlight gi`: a scene's radiosity solution compiled once and relit
//! frame by frame as its lights move, timed; the frames written on request.

use crate::{load, options, outputs, preflight};
use airlight::SceneFile;
use airlight::integrator::IntegratorKind;
use airlight::render::RenderObserver;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct GiArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Frames; frame k is at time k/(frames − 1) of the animation.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=preflight::MAX_FRAMES as i64))]
    frames: u32,
    /// Write every frame, rendered with the radiosity integrator, as
    /// DIR/frame_0000.png, … (not timed).
    #[arg(long, value_name = "DIR")]
    output_dir: Option<PathBuf>,
    /// Film settings and the radiosity integrator's options (and, in a
    /// medium, the march's), overriding the scene's `[render]`.
    #[command(flatten)]
    options: options::OptionFlags<options::RadiosityFlags>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_THREADS as i64))]
    threads: Option<u32>,
}

pub fn gi(args: GiArgs) -> Result<(), String> {
    use airlight::integrator::{Integrator, RadiosityIntegrator};
    use airlight::render::{RenderRequest, frame_time, set_time};
    let SceneFile { mut scene, integrator: mut desc } = load::load(Some(&args.scene))?;
    let mut settings = scene.settings().clone();
    args.options.apply(&mut settings, &mut desc)?;
    *scene.settings_mut() = settings;
    let job = RenderRequest { threads: args.threads, ..Default::default() }
        .check(scene.settings(), IntegratorKind::Radiosity)?;
    if let Some(dir) = &args.output_dir {
        let names = (0..args.frames).map(|k| format!("frame_{k:04}.png"));
        let inputs: Vec<&std::path::Path> =
            std::iter::once(args.scene.as_path()).chain(scene.files().iter().map(PathBuf::as_path)).collect();
        outputs::check_in_folder("--output-dir", dir, names, &inputs)?;
        preflight::render_memory(&scene, job.mode)?;
    }
    preflight::warn_if_dark(&scene, true);
    let pool = job.thread_pool()?;
    pool.install(|| {
        let mut integrator = RadiosityIntegrator::new(&scene, desc.radiosity, desc.raymarch)
            .map_err(|e| format!("{}: {e}", args.scene.display()))?;
        let solution = &integrator.solution;
        let (params, st) = (solution.params(), solution.stats());
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        println!("scene: {}", args.scene.display());
        println!(
            "threads: {}, patch_size: {}, link_threshold: {}, receiver_share: {}, bounces: {}",
            rayon::current_num_threads(),
            params.patch_size,
            params.link_threshold,
            params.receiver_share,
            desc.radiosity.bounces
        );
        println!("patches: {} ({} sides that see nothing dropped), clusters: {}", st.patches, st.dropped, st.clusters);
        println!(
            "links: {} ({} patch to patch, {} with a cluster; {:.1} per patch)",
            st.links,
            st.links_patch_to_patch,
            st.links - st.links_patch_to_patch,
            st.links as f64 / st.patches.max(1) as f64
        );
        println!("memory: {:.2} MiB", st.bytes as f64 / (1u64 << 20) as f64);
        println!(
            "compile: {:.1} ms (cut {:.1}, cull {:.1}, cluster {:.1}, link {:.1})",
            ms(st.total),
            ms(st.cut),
            ms(st.cull),
            ms(st.cluster),
            ms(st.link)
        );
        let mut frames = Vec::with_capacity(args.frames as usize);
        let forecast = preflight::Forecast::new(args.frames as u64, format!("{} frames", args.frames), false);
        for k in 0..args.frames {
            if let Some(warning) = forecast.advance(1) {
                eprintln!("{warning}");
            }
            set_time(&mut scene, &mut integrator, frame_time(k, args.frames)).map_err(|e| e.to_string())?;
            frames.push(integrator.last_update);
            if let Some(dir) = &args.output_dir {
                let image =
                    job.run(&pool, &scene, &integrator as &dyn Integrator, &RenderObserver::none()).into_image();
                let out = dir.join(format!("frame_{k:04}.png"));
                let s = scene.settings();
                image
                    .save_with(&out, s.film.exposure, s.film.tonemap)
                    .map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
            }
        }
        let stat = |f: &dyn Fn(&airlight::radiosity::FrameTimes) -> std::time::Duration| {
            let mut v: Vec<f64> = frames.iter().map(|t| ms(f(t))).collect();
            v.sort_by(f64::total_cmp);
            let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
            (at(0.5), at(0.95))
        };
        let (med, p95) = stat(&|t| t.total());
        println!("per frame (direct + push + gather), {} frames: median {med:.3} ms, p95 {p95:.3} ms", frames.len());
        let (d, _) = stat(&|t| t.direct);
        let (p, _) = stat(&|t| t.push);
        let (g, _) = stat(&|t| t.gather);
        println!("  median direct {d:.3} ms, push {p:.3} ms, gather {g:.3} ms");
        if let Some(dir) = &args.output_dir {
            println!("frames written to {}", dir.display());
        }
        Ok(())
    })
}
