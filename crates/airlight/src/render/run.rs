//! Running a checked [`RenderJob`]: the one place that knows which
//! render each mode is. Every front end (the command line's `render`,
//! `gi` and `study`, the Python package) calls [`RenderJob::run`], or
//! [`RenderJob::run_passes`] to watch a progressive render pass by pass.
//! Both render on the job's worker threads ([`RenderJob::thread_pool`]),
//! which the caller makes once and keeps, so that an integrator built in
//! them serves many runs (frames).

use super::{Progressive, RenderJob, RenderMode, RenderObserver, accumulate, adaptive, render_samples};
use crate::film::{Accumulator, Image};
use crate::integrator::Integrator;
use crate::scene::Scene;
use std::ops::ControlFlow;

/// What a run gives.
pub enum Rendered {
    /// Each pixel the mean of its samples.
    Image(Image),
    /// Each pixel's sums over the job's samples, for the job's rows: a part
    /// of a render for a merge, or a render whose variance was asked for.
    Sums(Accumulator),
}

impl Rendered {
    /// The mean of each pixel's samples (of the rows rendered).
    pub fn into_image(self) -> Image {
        match self {
            Rendered::Image(image) => image,
            Rendered::Sums(sums) => sums.image(),
        }
    }
}

/// Why [`RenderJob::run_passes`] stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassesEnd {
    /// Every sample of the job is in.
    Finished,
    /// The estimated relative error fell below the target.
    Target,
    /// The observer's cancel flag stopped a pass, which added nothing.
    Cancelled,
    /// The caller's `after_pass` said to stop.
    Caller,
}

impl RenderJob {
    /// Renders the job in one go, in `pool`: a uniform
    /// image ([`RenderMode::Image`]), an adaptive one, a part's sums, or a
    /// progressive job's sums (the same bits its passes would give; see
    /// [`RenderJob::run_passes`] to watch them). A cancelled run leaves
    /// pixels without samples.
    pub fn run(
        &self,
        pool: &rayon::ThreadPool,
        scene: &Scene,
        integrator: &dyn Integrator,
        observer: &RenderObserver,
    ) -> Rendered {
        pool.install(|| self.run_here(scene, integrator, observer))
    }

    fn run_here(&self, scene: &Scene, integrator: &dyn Integrator, observer: &RenderObserver) -> Rendered {
        let samples = self.samples.clone();
        match self.mode {
            RenderMode::Image => {
                // At most the scene's spp, a u32 (checked with the job).
                let count = (samples.end - samples.start) as u32;
                Rendered::Image(render_samples(scene, integrator, samples.start, count, observer))
            }
            RenderMode::Adaptive => Rendered::Image(adaptive::render_adaptive(scene, integrator, observer)),
            RenderMode::Partial | RenderMode::Progressive { .. } => {
                Rendered::Sums(accumulate(scene, integrator, samples, self.rows.clone(), observer))
            }
        }
    }

    /// Renders a progressive job pass by pass into `progressive` (new, or
    /// resumed from a checkpoint), each pass in `pool`, calling
    /// `after_pass` on the calling thread after each, until
    /// every sample is in, the estimated relative error is below
    /// `target_error`, a pass is cancelled, or `after_pass` breaks (with
    /// its error, if it fails). A job of another mode is refused.
    #[allow(clippy::too_many_arguments)]
    pub fn run_passes<E: From<String>>(
        &self,
        pool: &rayon::ThreadPool,
        scene: &Scene,
        integrator: &dyn Integrator,
        progressive: &mut Progressive,
        observer: &RenderObserver,
        target_error: Option<f64>,
        mut after_pass: impl FnMut(&Progressive) -> Result<ControlFlow<()>, E>,
    ) -> Result<PassesEnd, E> {
        if !matches!(self.mode, RenderMode::Progressive { .. }) {
            return Err(format!("a {:?} render does not go in passes", self.mode).into());
        }
        if observer.cancel.is_some() && self.mode != (RenderMode::Progressive { cancellable: true }) {
            // A pass that may stop part way adds into sums of its own first;
            // the job's memory was checked without them.
            return Err("a pass that may be cancelled needs a job checked as cancellable".to_string().into());
        }
        loop {
            if progressive.finished() {
                return Ok(PassesEnd::Finished);
            }
            if target_error.is_some_and(|target| progressive.estimated_relative_error() < target) {
                return Ok(PassesEnd::Target);
            }
            if !pool.install(|| progressive.pass(scene, integrator, observer)) {
                return Ok(PassesEnd::Cancelled);
            }
            if after_pass(progressive)?.is_break() {
                return Ok(PassesEnd::Caller);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{IntegratorDesc, IntegratorKind};
    use crate::prelude::*;
    use crate::render::RenderRequest;
    use crate::scene::RenderSettings;
    use std::sync::atomic::AtomicBool;

    /// A diffuse sphere on a floor in thin fog, lit by a point light: every
    /// pixel's samples differ (stochastic in-scattering).
    fn scene(spp: u32) -> Scene {
        let mut settings = RenderSettings { spp, ..RenderSettings::default() };
        (settings.film.width, settings.film.height) = (12, 8);
        SceneBuilder::new()
            .settings(settings)
            .camera(Camera::look_at(vec3(0.0, 1.0, -4.0), vec3(0.0, 0.5, 0.0), Vec3::Y, 50.0))
            .material("grey", Material::diffuse(Rgb::splat(0.5)))
            .object(crate::geometry::Shape::plane(Vec3::ZERO, Vec3::Y), "grey")
            .object(crate::geometry::Shape::sphere(vec3(0.0, 0.5, 0.0), 0.5), "grey")
            .light(Light::point(vec3(1.0, 2.5, -1.0), Rgb::splat(8.0)))
            .medium(Medium::homogeneous(Rgb::splat(0.02), Rgb::splat(0.1), 0.3))
            .build()
            .unwrap()
    }

    fn job(scene: &Scene, request: RenderRequest) -> RenderJob {
        request.check(scene.settings(), IntegratorKind::Stochastic).unwrap()
    }

    fn pool() -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap()
    }

    #[test]
    fn each_mode_is_the_render_it_names() {
        let scene = scene(6);
        let integrator = IntegratorDesc::new(IntegratorKind::Stochastic).build(&scene).unwrap();
        let (pool, none) = (pool(), RenderObserver::none());
        let whole = render_samples(&scene, integrator.as_ref(), 0, 6, &none);
        let once = job(&scene, RenderRequest::default());
        assert_eq!(once.mode, RenderMode::Image);
        assert_eq!(once.run(&pool, &scene, integrator.as_ref(), &none).into_image(), whole);
        // A variance keeps sums; their means are the image, bit for bit.
        let sums = job(&scene, RenderRequest { variance: true, ..Default::default() });
        let Rendered::Sums(acc) = sums.run(&pool, &scene, integrator.as_ref(), &none) else { panic!("sums") };
        assert_eq!((acc.image(), acc.rows()), (whole.clone(), 0..8));
        // A shard's samples of a tile's rows.
        let part = job(&scene, RenderRequest { shard: Some((1, 2)), tile: Some((1, 2)), ..Default::default() });
        let Rendered::Sums(acc) = part.run(&pool, &scene, integrator.as_ref(), &none) else { panic!("sums") };
        assert_eq!(acc.rows(), 4..8);
        let direct = accumulate(&scene, integrator.as_ref(), 3..6, 4..8, &none);
        assert_eq!(acc.image(), direct.image());
    }

    #[test]
    fn passes_add_up_to_the_render_in_one_go_and_stop_where_asked() {
        let scene = scene(8);
        let integrator = IntegratorDesc::new(IntegratorKind::Stochastic).build(&scene).unwrap();
        let (pool, none) = (pool(), RenderObserver::none());
        let progressive_job = job(&scene, RenderRequest { passes: true, ..Default::default() });
        let mut sizes = Vec::new();
        let mut p = Progressive::new(&scene);
        let end = progressive_job
            .run_passes::<String>(&pool, &scene, integrator.as_ref(), &mut p, &none, None, |p| {
                sizes.push(p.samples());
                Ok(ControlFlow::Continue(()))
            })
            .unwrap();
        assert_eq!((end, sizes), (PassesEnd::Finished, vec![1, 2, 4, 8]));
        assert_eq!(p.image(), render_samples(&scene, integrator.as_ref(), 0, 8, &none));
        // The caller stops after the second pass; an error target of ∞ is
        // met as soon as an error is known (from the second sample on).
        let mut p = Progressive::new(&scene);
        let stop = |p: &Progressive| {
            Ok::<_, String>(if p.samples() == 2 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) })
        };
        let end = progressive_job.run_passes(&pool, &scene, integrator.as_ref(), &mut p, &none, None, stop).unwrap();
        assert_eq!((end, p.samples()), (PassesEnd::Caller, 2));
        let mut p = Progressive::new(&scene);
        let keep_on = |_: &Progressive| Ok::<_, String>(ControlFlow::Continue(()));
        let end =
            progressive_job.run_passes(&pool, &scene, integrator.as_ref(), &mut p, &none, Some(f64::INFINITY), keep_on);
        assert_eq!(end.unwrap(), PassesEnd::Target);
        // The caller's error ends the run with it.
        let fail = |_: &Progressive| Err::<ControlFlow<()>, String>("disk full".into());
        let mut p = Progressive::new(&scene);
        let end = progressive_job.run_passes(&pool, &scene, integrator.as_ref(), &mut p, &none, None, fail);
        assert_eq!(end.unwrap_err(), "disk full");
    }

    #[test]
    fn a_cancelled_pass_adds_nothing_and_only_cancellable_jobs_take_a_cancel_flag() {
        let scene = scene(4);
        let integrator = IntegratorDesc::new(IntegratorKind::Stochastic).build(&scene).unwrap();
        let pool = pool();
        let cancel = AtomicBool::new(true);
        let observer = RenderObserver { progress: None, cancel: Some(&cancel) };
        let keep_on = |_: &Progressive| Ok::<_, String>(ControlFlow::Continue(()));
        let cancellable = job(&scene, RenderRequest { cancellable: true, ..Default::default() });
        let mut p = Progressive::new(&scene);
        let end = cancellable.run_passes(&pool, &scene, integrator.as_ref(), &mut p, &observer, None, keep_on);
        assert_eq!((end.unwrap(), p.samples()), (PassesEnd::Cancelled, 0));
        let plain = job(&scene, RenderRequest { passes: true, ..Default::default() });
        let end = plain.run_passes(&pool, &scene, integrator.as_ref(), &mut p, &observer, None, keep_on);
        assert!(end.unwrap_err().contains("cancellable"));
        let once = job(&scene, RenderRequest::default());
        let end = once.run_passes(&pool, &scene, integrator.as_ref(), &mut p, &RenderObserver::none(), None, keep_on);
        assert!(end.unwrap_err().contains("does not go in passes"));
    }
}
