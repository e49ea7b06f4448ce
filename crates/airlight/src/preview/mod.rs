//! A fast preview for interactive viewers: one primary ray per pixel
//! sample, direct light with one shadow ray per light, the indirect light
//! of a [`Radiosity`] solution that the viewer relights each frame, and, in
//! a medium, the closed-form airlight glow of the analytic integrator
//! instead of a march. It is the radiosity integrator with its costly part,
//! the march, swapped for a closed form, so that a light can move at
//! interactive rates.

use crate::Rgb;
use crate::geometry::Ray;
use crate::integrator::{
    Analytic, AnalyticOptions, Integrator, IntegratorError, RaymarchOptions, indirect_radiance, march,
    single_scattering,
};
use crate::medium::Medium;
use crate::radiosity::Radiosity;
use crate::sampling::Sampler;
use crate::scene::Scene;

mod cache;
mod sparse;
pub use cache::{Fill, FirstSample};

/// March steps per ray when the medium has no closed form (height fog, a
/// density grid, noise fog).
pub const FALLBACK_STEPS: u32 = 16;

/// How the preview lights the medium.
enum Glow {
    /// No medium, or one that does not scatter.
    None,
    /// Closed-form single scattering (homogeneous media).
    Analytic(Box<Analytic>),
    /// A short jittered march (media without a closed form).
    March(RaymarchOptions),
}

/// The preview integrator: see the module documentation. It borrows the
/// solution, which must have been updated for the scene's current lights.
pub struct Preview<'a> {
    solution: Option<&'a Radiosity>,
    glow: Glow,
    options: AnalyticOptions,
    march: RaymarchOptions,
}

impl<'a> Preview<'a> {
    /// The preview of `scene` with its current lights; `analytic` and
    /// `march` are the options of the glow (volumetric shadows are left
    /// out: they cost a boundary search per ray) and of the fallback march
    /// (at most [`FALLBACK_STEPS`] steps). Without a solution the indirect
    /// light is left out.
    pub fn new(
        scene: &Scene,
        solution: Option<&'a Radiosity>,
        analytic: AnalyticOptions,
        march: RaymarchOptions,
    ) -> Self {
        let options = AnalyticOptions { shadows: false, ..analytic };
        let march = RaymarchOptions { steps: march.steps.min(FALLBACK_STEPS), jitter: true };
        Preview { solution, glow: glow(scene, options, march), options, march }
    }

    /// What lights the medium: "none", "analytic glow" or "marched glow".
    pub fn glow_name(&self) -> &'static str {
        match self.glow {
            Glow::None => "none",
            Glow::Analytic(_) => "analytic glow",
            Glow::March { .. } => "marched glow",
        }
    }

    /// The light the medium scatters toward the ray's origin over [0, length].
    fn glow(&self, scene: &Scene, medium: &Medium, ray: &Ray, length: f32, sampler: &mut Sampler) -> Rgb {
        match &self.glow {
            Glow::None => Rgb::ZERO,
            Glow::Analytic(a) => a.in_scattered(scene, medium, ray, length),
            Glow::March(options) => march(scene, medium, ray, length, *options, sampler),
        }
    }
}

/// The glow of `scene`'s medium: in closed form where each light is one
/// point to it (point, spot and sphere lights in homogeneous fog), else
/// marched. A line, quad or mesh light is a sum of `light_steps` or its
/// square of closed forms a ray, more where a ray passes close: a frame of
/// a room lit by an emitting quad in fog took minutes so, where the march
/// takes a fraction of a second, its noise averaging away as the view
/// refines.
fn glow(scene: &Scene, options: AnalyticOptions, march: RaymarchOptions) -> Glow {
    match scene.medium() {
        Some(m) if m.sigma_s != Rgb::ZERO => match Analytic::new(scene, options) {
            Ok(a) if a.lights_are_points() => Glow::Analytic(Box::new(a)),
            _ => Glow::March(march),
        },
        _ => Glow::None,
    }
}

impl Integrator for Preview<'_> {
    /// L = T·(L_direct + ρ/π·E_ind) + L_glow, as
    /// [`crate::integrator::RadiosityIntegrator`] but with the glow in closed
    /// form where the medium allows it.
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        single_scattering(
            scene,
            ray,
            sampler,
            |s| self.solution.map_or(Rgb::ZERO, |solution| indirect_radiance(scene, solution, ray.dir, s, false)),
            |medium, length, sampler| self.glow(scene, medium, ray, length, sampler),
        )
    }

    /// The analytic glow's emitters stand where the lights were: rebuilt.
    /// (The borrowed solution is the caller's to relight.)
    fn lights_changed(&mut self, scene: &Scene) -> Result<(), IntegratorError> {
        self.glow = glow(scene, self.options, self.march);
        Ok(())
    }
}

#[cfg(test)]
mod tests;
