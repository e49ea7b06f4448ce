//! Integrators: each turns a camera ray into the radiance arriving along it.
//! They share one trait; the scene's `[render] integrator` picks one.

pub mod analytic;
mod direct;
pub mod equiangular;
pub mod path;
mod radiosity;
mod raymarch;
mod stochastic;

pub use analytic::Analytic;
pub use direct::Direct;
pub use equiangular::Equiangular;
pub use path::PathTracer;
pub use radiosity::RadiosityIntegrator;
pub use raymarch::{Raymarch, in_scattered};
pub use stochastic::{Sampling, Stochastic};

use crate::Rgb;
use crate::geometry::{Ray, SurfaceHit, offset_origin};
use crate::medium::Medium;
use crate::sampling::{Sampler, keyed2};
use crate::scene::Scene;
use serde::Deserialize;

/// Estimates radiance along camera rays. Implementations hold only settings;
/// all per-ray state lives on the stack, so one instance serves all threads.
pub trait Integrator: Send + Sync {
    /// Radiance arriving at the camera along `ray` (one sample).
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb;

    /// Whether camera rays take their film and lens positions from the
    /// pixel's stratified sequence ([`Sampler::stratified4`] group 0) rather
    /// than from the sample's random stream.
    fn stratified(&self) -> bool {
        false
    }
}

/// The integrators a scene or the command line can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorKind {
    /// Direct light on surfaces with shadows; any medium is ignored.
    Direct,
    /// Ray marching of the medium with a shadow ray per sample.
    Raymarch,
    /// Closed-form single-scatter airlight.
    Analytic,
    /// Monte Carlo single scattering on signed distance fields.
    Stochastic,
    /// Volumetric path tracing, the reference.
    Path,
    /// Radiosity with a patch hierarchy.
    Radiosity,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 6] = [
        IntegratorKind::Direct,
        IntegratorKind::Raymarch,
        IntegratorKind::Analytic,
        IntegratorKind::Stochastic,
        IntegratorKind::Path,
        IntegratorKind::Radiosity,
    ];

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Direct => "direct",
            IntegratorKind::Raymarch => "raymarch",
            IntegratorKind::Analytic => "analytic",
            IntegratorKind::Stochastic => "stochastic",
            IntegratorKind::Path => "path",
            IntegratorKind::Radiosity => "radiosity",
        }
    }
}

impl std::str::FromStr for IntegratorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        IntegratorKind::ALL.into_iter().find(|k| k.name() == s).ok_or_else(|| {
            let names: Vec<&str> = IntegratorKind::ALL.iter().map(|k| k.name()).collect();
            format!("unknown integrator `{s}`; expected one of {}", names.join(", "))
        })
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The integrator a scene asks for, or why it cannot be had.
pub fn for_scene(scene: &Scene) -> Result<Box<dyn Integrator>, String> {
    let s = &scene.settings;
    match s.integrator {
        IntegratorKind::Direct => Ok(Box::new(Direct)),
        IntegratorKind::Raymarch => Ok(Box::new(Raymarch { steps: s.steps, jitter: s.jitter })),
        IntegratorKind::Path => Ok(Box::new(PathTracer::new(s.max_depth))),
        IntegratorKind::Radiosity => Ok(Box::new(RadiosityIntegrator::new(scene).map_err(|e| e.to_string())?)),
        IntegratorKind::Analytic => Ok(Box::new(Analytic::new(scene, analytic::AnalyticOptions::from_settings(s))?)),
        IntegratorKind::Stochastic => Ok(Box::new(Stochastic { sampling: s.sampling, stratify: s.stratify })),
    }
}

/// Radiance leaving a surface toward `-ray.dir`: its emission plus direct
/// light from every light, one sample per area light, with shadow rays. In a
/// medium, light arriving from each light is attenuated on its way.
pub fn surface_radiance(
    scene: &Scene,
    ray: &Ray,
    surface: &SurfaceHit,
    sampler: &mut Sampler,
    medium: Option<&Medium>,
) -> Rgb {
    let wo = -ray.dir;
    let mut radiance = match surface.emitter {
        Some(light) => scene.lights[light as usize].emitted(surface.n, ray.dir),
        None => Rgb::ZERO,
    };
    let material = &scene.materials[surface.material as usize];
    let key = sampler.next_key();
    scene.for_each_light_at(surface.p, |index, light| {
        let Some(sample) = light.sample(surface.p, keyed2(key, index as u64)) else { return };
        let cos = sample.wi.dot(surface.n).abs();
        if cos == 0.0 || sample.weight == Rgb::ZERO {
            return;
        }
        let f = material.brdf(surface.p, surface.n, wo, sample.wi);
        if f == Rgb::ZERO {
            return;
        }
        let origin = offset_origin(surface.p, surface.n, sample.wi);
        let distance = scene.light_distance(sample.distance);
        if !scene.light_visible(surface.p, origin, sample.wi, sample.distance) {
            return;
        }
        let mut contribution = f * sample.weight * cos;
        if let Some(m) = medium {
            contribution *= m.transmittance(origin, sample.wi, 0.0, distance);
        }
        radiance += contribution;
    });
    radiance
}
