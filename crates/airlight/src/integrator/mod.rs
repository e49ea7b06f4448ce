//! Integrators: each turns a camera ray into the radiance arriving along it.
//! They share one trait and are built from their own options by one
//! function ([`IntegratorDesc::build`]); a scene file's `[render]
//! integrator` picks one.

mod ambient_occlusion;
pub mod analytic;
mod direct;
mod direct_batch;
pub mod equiangular;
mod light_lanes;
mod options;
pub mod path;
mod radiosity;
mod raymarch;
mod stochastic;

pub use crate::radiosity::{DEFAULT_LINK_THRESHOLD, RadiosityOptions};
pub use ambient_occlusion::{AmbientOcclusion, AmbientOcclusionOptions};
pub use analytic::{Analytic, AnalyticOptions};
pub use direct::Direct;
pub(crate) use direct_batch::DeferredShadows;
pub use direct_batch::first_surface_batch;
pub use equiangular::Equiangular;
pub use options::{
    INTEGRATOR_KEY, INTEGRATOR_OPTIONS, IntegratorDesc, IntegratorError, IntegratorOption, MAX_BOUNCES, MAX_DEPTH,
    MAX_LIGHT_STEPS, MAX_STEPS, OptionError, PathOptions, RaymarchOptions, StochasticOptions,
};
pub use path::PathTracer;
pub use radiosity::{RadiosityIntegrator, indirect_radiance};
pub use raymarch::{Raymarch, in_scattered, march};
pub use stochastic::{Sampling, Stochastic};

use crate::Rgb;
use crate::geometry::{Ray, SurfaceHit};
use crate::light::LightSample;
use crate::material::Material;
use crate::medium::Medium;
use crate::sampling::{Sampler, keyed2};
use crate::scene::Scene;

/// Estimates radiance along camera rays. Implementations hold settings and
/// what they derive from the scene; all per-ray state lives on the stack, so
/// one instance serves all threads.
pub trait Integrator: Send + Sync {
    /// Radiance arriving at the camera along `ray` (one sample).
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb;

    /// Whether camera rays take their film and lens positions from the
    /// pixel's stratified sequence ([`Sampler::stratified4`] group 0) rather
    /// than from the sample's random stream.
    fn stratified(&self) -> bool {
        false
    }

    /// For the single-scattering integrators (raymarch, analytic,
    /// stochastic): [`Integrator::radiance`] in its two parts, the first
    /// surface's light as it reaches the camera (attenuated by the medium)
    /// and the light the medium scatters toward the camera, drawn with the
    /// same samples, so that their sum is `radiance` for the same sampler.
    /// None for integrators that do not separate them.
    fn radiance_parts(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Option<RadianceParts> {
        let _ = (scene, ray, sampler);
        None
    }

    /// Radiance along many camera rays, each with its own sampler:
    /// `out[i]` is `self.radiance(scene, &rays[i], &mut samplers[i])`, bit
    /// for bit, unless [`Integrator::shares_between_pixels`]. The render
    /// loop hands over the samples of a block of neighbouring pixels, so
    /// that integrators may trace their coherent rays together (see
    /// `Geometry::intersect_packet`); by default, one sample after another.
    fn radiance_batch(&self, scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb]) {
        for ((ray, sampler), out) in rays.iter().zip(samplers.iter_mut()).zip(out.iter_mut()) {
            *out = self.radiance(scene, ray, sampler);
        }
    }

    /// Whether [`Integrator::radiance_batch`] lets the batch's samples share
    /// what they found (the path tracer's path reuse): each `out[i]` is
    /// then still an unbiased estimate of its pixel, but depends on the
    /// batch's other samples and is not `radiance`'s value.
    fn shares_between_pixels(&self) -> bool {
        false
    }

    /// How many blocks of neighbouring pixels' samples one call of
    /// [`Integrator::radiance_batch`] may take (each block's samples
    /// still in order). One by default; more lets rays traced later in a
    /// batch, such as shadow rays from only the lit hits, fill whole
    /// packets.
    fn batch_blocks(&self) -> usize {
        1
    }

    /// The scene's lights changed ([`Scene::set_lights`], [`Scene::at_time`]):
    /// update what was derived from them (radiosity relights its patches
    /// without recompiling; the analytic integrator re-places its emitters).
    /// Nothing by default.
    fn lights_changed(&mut self, scene: &Scene) -> Result<(), IntegratorError> {
        let _ = scene;
        Ok(())
    }
}

/// The integrators a scene or the command line can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
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
    /// A view of the geometry: how open each first surface's hemisphere is.
    AmbientOcclusion,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 7] = [
        IntegratorKind::Direct,
        IntegratorKind::Raymarch,
        IntegratorKind::Analytic,
        IntegratorKind::Stochastic,
        IntegratorKind::Path,
        IntegratorKind::Radiosity,
        IntegratorKind::AmbientOcclusion,
    ];

    /// The integrators' names, in [`IntegratorKind::ALL`]'s order: the
    /// values `[render] integrator` takes.
    pub const NAMES: [&'static str; Self::ALL.len()] = {
        let mut names = [""; Self::ALL.len()];
        let mut i = 0;
        while i < names.len() {
            names[i] = Self::ALL[i].name();
            i += 1;
        }
        names
    };

    /// What the integrator's image is an estimate of.
    pub fn estimate(self) -> Estimate {
        match self {
            IntegratorKind::Direct => Estimate::Direct,
            IntegratorKind::Raymarch | IntegratorKind::Analytic | IntegratorKind::Stochastic => {
                Estimate::SingleScattering
            }
            IntegratorKind::Path | IntegratorKind::Radiosity => Estimate::Full,
            IntegratorKind::AmbientOcclusion => Estimate::DebugView,
        }
    }

    /// Whether the integrator's [`Integrator::radiance_parts`] gives the
    /// surface's light and the medium's apart (the single-scattering
    /// integrators), so that the medium's light can be written alone; known
    /// before the integrator is built (radiosity's build is long).
    pub fn separates_in_scattering(self) -> bool {
        self.estimate() == Estimate::SingleScattering
    }

    pub const fn name(self) -> &'static str {
        match self {
            IntegratorKind::Direct => "direct",
            IntegratorKind::Raymarch => "raymarch",
            IntegratorKind::Analytic => "analytic",
            IntegratorKind::Stochastic => "stochastic",
            IntegratorKind::Path => "path",
            IntegratorKind::Radiosity => "radiosity",
            IntegratorKind::AmbientOcclusion => "ambient_occlusion",
        }
    }
}

/// What an integrator's image estimates, so that tools can treat
/// integrators by what they compute rather than by a list of names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimate {
    /// Direct light on surfaces; any medium is ignored.
    Direct,
    /// Direct light on surfaces seen through the medium, plus the light
    /// the medium scatters once toward the camera; [`Integrator::radiance_parts`]
    /// gives the two apart.
    SingleScattering,
    /// Light that has bounced any number of times (up to the integrator's
    /// own limit).
    Full,
    /// Not radiance: a view of the scene's geometry, for looking at a scene
    /// rather than lighting it.
    DebugView,
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

/// Radiance along a camera ray in two parts (see [`Integrator::radiance_parts`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadianceParts {
    /// The first surface's radiance (or the background) times the
    /// medium's transmittance to it.
    pub surface: Rgb,
    /// The light the medium scatters toward the ray's origin.
    pub in_scattered: Rgb,
}

impl RadianceParts {
    pub fn total(&self) -> Rgb {
        self.surface + self.in_scattered
    }
}

/// Radiance along `ray` as every single-scattering integrator sees it: the
/// first surface (its emission and direct light, plus `extra`, e.g. the
/// indirect light of a radiosity solution), attenuated by the scene's medium
/// all the way to it, plus `in_scattered(medium, length, sampler)`, the
/// light the medium scatters toward the ray's origin over [0, length]. The
/// medium is integrated to the surface or to `max_distance`, whichever is
/// nearer; a ray that hits nothing sees the background from `max_distance`.
/// Without a medium this is the surface alone. The surface is evaluated
/// first, so the samples it draws (and so, in vacuum, the image) are those
/// of the `direct` integrator.
pub fn single_scattering(
    scene: &Scene,
    ray: &Ray,
    sampler: &mut Sampler,
    extra: impl FnOnce(&SurfaceHit) -> Rgb,
    in_scattered: impl FnOnce(&Medium, f32, &mut Sampler) -> Rgb,
) -> Rgb {
    single_scattering_parts(scene, ray, sampler, extra, in_scattered).total()
}

/// [`single_scattering`] in its two parts.
pub fn single_scattering_parts(
    scene: &Scene,
    ray: &Ray,
    sampler: &mut Sampler,
    extra: impl FnOnce(&SurfaceHit) -> Rgb,
    in_scattered: impl FnOnce(&Medium, f32, &mut Sampler) -> Rgb,
) -> RadianceParts {
    let (surface, t_end) = first_surface(scene, ray, sampler, scene.medium(), extra);
    through_medium_parts(scene, ray, surface, t_end, sampler, in_scattered)
}

/// The second half of [`single_scattering`]: `surface` radiance from
/// distance `t_end` along `ray`, attenuated by the scene's medium, plus the
/// light the medium scatters in front of it (up to `max_distance`).
pub fn through_medium(
    scene: &Scene,
    ray: &Ray,
    surface: Rgb,
    t_end: f32,
    sampler: &mut Sampler,
    in_scattered: impl FnOnce(&Medium, f32, &mut Sampler) -> Rgb,
) -> Rgb {
    through_medium_parts(scene, ray, surface, t_end, sampler, in_scattered).total()
}

/// [`through_medium`] in its two parts.
pub fn through_medium_parts(
    scene: &Scene,
    ray: &Ray,
    surface: Rgb,
    t_end: f32,
    sampler: &mut Sampler,
    in_scattered: impl FnOnce(&Medium, f32, &mut Sampler) -> Rgb,
) -> RadianceParts {
    let Some(medium) = scene.medium() else {
        return RadianceParts { surface, in_scattered: Rgb::ZERO };
    };
    let through = medium.transmittance(ray.origin, ray.dir, 0.0, t_end);
    let length = t_end.min(scene.settings().max_distance);
    RadianceParts { surface: surface * through, in_scattered: in_scattered(medium, length, sampler) }
}

/// The radiance leaving the first surface along `ray` toward its origin
/// (emission, direct light attenuated by `medium` on its way, plus
/// `extra`), and its distance; the background and `max_distance` when
/// nothing is hit.
pub fn first_surface(
    scene: &Scene,
    ray: &Ray,
    sampler: &mut Sampler,
    medium: Option<&Medium>,
    extra: impl FnOnce(&SurfaceHit) -> Rgb,
) -> (Rgb, f32) {
    match scene.geometry().intersect(ray, f32::INFINITY) {
        Some(hit) => {
            let s = scene.geometry().surface(ray, hit);
            (surface_radiance(scene, ray, &s, sampler, medium) + extra(&s), hit.t)
        }
        None => (scene.escaped_radiance(ray.dir), scene.settings().max_distance),
    }
}

/// No extra surface term.
pub fn no_extra(_: &SurfaceHit) -> Rgb {
    Rgb::ZERO
}

/// Radiance leaving a surface toward `-ray.dir`: its emission plus direct
/// light from every light, one sample per area light, with shadow rays. In a
/// medium, light arriving from each light is attenuated on its way.
/// (`batch.rs` computes the same without a medium for many rays at once,
/// from the same `emitted` and `for_each_light_term`.)
pub fn surface_radiance(
    scene: &Scene,
    ray: &Ray,
    surface: &SurfaceHit,
    sampler: &mut Sampler,
    medium: Option<&Medium>,
) -> Rgb {
    let mut radiance = emitted(scene, ray, surface);
    for_each_light_term(scene, ray, surface, sampler, |_, sample, mut contribution| {
        if !scene.unoccluded(surface.p, Some(surface.n), sample) {
            return;
        }
        if let Some(m) = medium {
            let origin = crate::geometry::offset_origin(surface.p, surface.n, sample.wi);
            contribution *= m.transmittance(origin, sample.wi, 0.0, scene.light_distance(sample.distance));
        }
        radiance += contribution;
    });
    radiance
}

/// What a surface emits toward `-ray.dir` (zero unless it is a light's).
pub(crate) fn emitted(scene: &Scene, ray: &Ray, surface: &SurfaceHit) -> Rgb {
    match surface.emitter {
        Some(light) => scene.emitted(light as usize, surface.p, surface.n, ray.dir),
        None => Rgb::ZERO,
    }
}

/// Calls `term(light, sample, f · weight · |cos|)` for one sample of each
/// emitter that may reach the surface (a light, or an emitting mesh's
/// triangles together: [`Scene::for_each_emitter_at`]), in the lights'
/// order, before any shadow ray: the terms that direct light adds where the
/// light is seen.
/// Takes one key from `sampler`, whatever the number of lights.
pub(crate) fn for_each_light_term(
    scene: &Scene,
    ray: &Ray,
    surface: &SurfaceHit,
    sampler: &mut Sampler,
    mut term: impl FnMut(usize, &LightSample, Rgb),
) {
    let wo = -ray.dir;
    let material = scene.material_at(surface);
    let shading = scene.shading_normal(surface);
    let key = sampler.next_key();
    scene.for_each_emitter_at(surface.p, |index, _| {
        if let Some((sample, contribution)) = light_term(scene, index, surface, shading, wo, &material, key) {
            term(index, &sample, contribution);
        }
    });
}

/// One term of [`for_each_light_term`]: the sample of emitter `index` drawn
/// with `key` at `surface` (whose material is `material`, shaded by the
/// normal `shading`, [`Scene::shading_normal`], found once per point by the
/// caller), seen along `wo`, and its contribution f · weight · |cos|; None
/// where it adds nothing.
#[inline]
pub(crate) fn light_term(
    scene: &Scene,
    index: usize,
    surface: &SurfaceHit,
    shading: Option<glam::Vec3>,
    wo: glam::Vec3,
    material: &Material,
    key: u64,
) -> Option<(LightSample, Rgb)> {
    let u = keyed2(key, index as u64);
    let sample = scene.sample_emitter(index, surface.p, u)?;
    let cos = sample.wi.dot(surface.n).abs();
    if cos == 0.0 {
        return None;
    }
    let f = material.brdf_at(surface.p, surface.n, shading, wo, sample.wi);
    if f == Rgb::ZERO {
        return None;
    }
    let contribution = f * sample.weight * cos;
    Some((sample, contribution))
}
