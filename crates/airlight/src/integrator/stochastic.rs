//! Monte Carlo single scattering, after Anders Hoff's "Volumetric Light"
//! (inconvergent.net, "Hoff" below): per pixel sample, a point x on the
//! camera segment [eye, hit] and a point y in the light; if the path between
//! them is clear, add the light scattered at x toward the eye.
//!
//! The integral is the raymarch integrator's (single scattering plus the
//! attenuated surface):
//!
//!   L = T(0, t_end)·L_surface + ∫₀^t_end T(0, t)·σs(x_t)·∫_light p(wo, wi)·Le·V·T(x_t, y)/r² dy dt,
//!
//! and one sample per light estimates the inner part as
//! f(t, y)/(pdf(t | y)·pdf(y)), with y from the light's own sampling and t from
//! one of three strategies:
//!
//! - `uniform`: pdf(t) = 1/t_end, Hoff's `line_sample`. With a volume
//!   light Hoff's sum d/(1 + dist)² is this estimator with its fudge
//!   factors (the "+1", the unknown scale) replaced by the physical ones.
//! - `equiangular`: pdf(t) ∝ 1/r² toward the light's anchor point (the point
//!   light itself, or the centre of an extended light with its size as the
//!   least distance, `Light::anchor`), Kulla and Fajardo 2012 (equiangular.rs).
//! - `mis`: one-sample multiple importance sampling of the two with the
//!   balance heuristic (Veach 1997, section 9.2.4): the strategy is chosen with
//!   probability 1/2 and the sample weighted by 1/(½pdf_uniform + ½pdf_equiangular).
//!
//! With `stratify`, each sample's numbers (film, lens, t and light point) are
//! its point of the pixel's Owen-scrambled Sobol' sequence (sampling/sobol.rs),
//! one independent 4D group for the camera and one per light; without, they are
//! independent random numbers, as in Hoff.
//!
//! Rays that hit nothing end at `max_distance`, on Hoff's "very large
//! plane" facing the camera, whose radiance is `background`.

use super::equiangular::Equiangular;
use super::{Integrator, RadianceParts, StochasticOptions, no_extra, single_scattering_parts};
use crate::Rgb;
use crate::geometry::Ray;
use crate::medium::Medium;
use crate::sampling::Sampler;
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// How the point on the camera segment is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Sampling {
    /// Uniform in distance (Hoff's estimator).
    Uniform,
    /// In proportion to 1/r² toward the light (Kulla and Fajardo 2012).
    #[default]
    Equiangular,
    /// Both, combined by one-sample MIS with the balance heuristic.
    Mis,
}

impl Sampling {
    pub const ALL: [Sampling; 3] = [Sampling::Uniform, Sampling::Equiangular, Sampling::Mis];

    pub fn name(self) -> &'static str {
        match self {
            Sampling::Uniform => "uniform",
            Sampling::Equiangular => "equiangular",
            Sampling::Mis => "mis",
        }
    }
}

impl std::str::FromStr for Sampling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Sampling::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown sampling `{s}`; expected uniform, equiangular or mis"))
    }
}

impl std::fmt::Display for Sampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The `stochastic` integrator (see the module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stochastic {
    pub sampling: Sampling,
    pub stratify: bool,
}

impl Stochastic {
    pub fn new(options: StochasticOptions) -> Self {
        Stochastic { sampling: options.sampling, stratify: options.stratify }
    }
}

impl Integrator for Stochastic {
    fn stratified(&self) -> bool {
        self.stratify
    }

    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        self.parts(scene, ray, sampler).total()
    }

    fn radiance_parts(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Option<RadianceParts> {
        Some(self.parts(scene, ray, sampler))
    }
}

impl Stochastic {
    fn parts(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> RadianceParts {
        single_scattering_parts(scene, ray, sampler, no_extra, |medium, length, sampler| {
            self.in_scattered(scene, medium, ray, length, sampler)
        })
    }
}

impl Stochastic {
    /// One sample per light (an emitting mesh's triangles as one light:
    /// [`Scene::for_each_emitter_at`]) of the light scattered toward the
    /// ray's origin over [0, length].
    fn in_scattered(&self, scene: &Scene, medium: &Medium, ray: &Ray, length: f32, sampler: &mut Sampler) -> Rgb {
        let mut total = Rgb::ZERO;
        if medium.sigma_s == Rgb::ZERO || length <= 0.0 {
            return total;
        }
        // Points are drawn where the medium may have density (a grid's box).
        let Some(span) = medium.extent(ray.origin, ray.dir, 0.0, length) else { return total };
        let wo = -ray.dir;
        for &first in scene.emitter_firsts() {
            let u = if self.stratify {
                sampler.stratified4(1 + first)
            } else {
                [sampler.next(), sampler.next(), sampler.next(), sampler.next()]
            };
            // The emitter's light first (itself, or a triangle of a mesh),
            // whose anchor the distance is drawn about.
            let (index, chance, u_light) = scene.draw_emitter(first as usize, Vec2::new(u[1], u[2]));
            let light = &scene.lights()[index];
            let u_light = u_light.extend(u[3]);
            let Some((t, pdf)) = self.distance(ray, span, light.anchor(), u[0]) else { continue };
            let x = ray.at(t);
            let Some(sample) = scene.sample_light3(index, x, u_light) else { continue };
            if !scene.unoccluded(x, None, &sample) {
                continue;
            }
            let distance = scene.light_distance(sample.distance);
            let to_eye = medium.transmittance(ray.origin, ray.dir, 0.0, t);
            let to_light = medium.transmittance(x, sample.wi, 0.0, distance);
            let phase = medium.phase(wo, sample.wi);
            let sigma_s = medium.sigma_s * medium.density_at(x);
            total += to_eye * sigma_s * phase * sample.weight * to_light / (pdf * chance);
        }
        total
    }
}

impl Stochastic {
    /// A distance t in [start, end] along the ray and its pdf, by the chosen
    /// strategy, given the light's anchor point (uniform without one).
    fn distance(&self, ray: &Ray, (start, end): (f32, f32), anchor: Option<(Vec3, f32)>, u: f32) -> Option<(f32, f32)> {
        let length = end - start;
        let uniform_pdf = 1.0 / length;
        let equiangular = match (self.sampling, anchor) {
            (Sampling::Uniform, _) | (_, None) => return Some((start + u * length, uniform_pdf)),
            (_, Some((y, spread))) => Equiangular::new(ray.origin, ray.dir, y, spread, start, end),
        };
        let (t, pdf) = match self.sampling {
            Sampling::Equiangular => {
                let t = equiangular.sample(u);
                (t, equiangular.pdf(t))
            }
            _ => {
                // Choose by the first half of u, reuse the rest stretched.
                let t = if u < 0.5 { start + 2.0 * u * length } else { equiangular.sample(2.0 * u - 1.0) };
                (t, 0.5 * uniform_pdf + 0.5 * equiangular.pdf(t))
            }
        };
        (pdf > 0.0 && pdf.is_finite()).then_some((t, pdf))
    }
}
