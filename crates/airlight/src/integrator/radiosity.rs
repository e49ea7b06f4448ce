//! The `radiosity` integrator: direct light per pixel, indirect light from
//! the patches (the seed's "different frequencies").

use super::raymarch::in_scattered;
use super::{Integrator, surface_radiance};
use crate::Rgb;
use crate::geometry::Ray;
use crate::radiosity::{Radiosity, RadiosityError};
use crate::sampling::Sampler;
use crate::scene::Scene;
use std::f32::consts::FRAC_1_PI;

/// Renders a lit [`Radiosity`] solution. At the surface a camera ray hits,
///
///   L = L_direct + ρ(p)/π · E_ind(p),
///
/// where L_direct is `surface_radiance` (emission plus direct light with
/// shadow rays, per pixel sample), ρ(p) the diffuse albedo at the pixel's
/// point (so a checker stays sharp) and E_ind the indirect irradiance
/// interpolated between patch centres on the side facing the camera. In a
/// medium, L is attenuated along the camera ray and single scattering is
/// added as the `raymarch` integrator does (`steps`, `jitter`); the patches'
/// indirect light is computed in vacuum.
///
/// The solution must have been compiled from, and updated for, the scene it
/// renders ([`Radiosity::update`] after lights move).
pub struct RadiosityIntegrator {
    pub solution: Radiosity,
    pub steps: u32,
    pub jitter: bool,
}

impl RadiosityIntegrator {
    /// Compiles and lights `scene` with its own settings.
    pub fn new(scene: &Scene) -> Result<Self, RadiosityError> {
        Ok(RadiosityIntegrator {
            solution: Radiosity::compile(scene)?,
            steps: scene.settings.steps,
            jitter: scene.settings.jitter,
        })
    }
}

impl Integrator for RadiosityIntegrator {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        let medium = scene.medium.as_ref();
        let tmax = match medium {
            Some(_) => f32::INFINITY,
            None => scene.settings.max_distance,
        };
        let (surface, t_end) = match scene.geometry.intersect(ray, tmax) {
            Some(hit) => {
                let s = scene.geometry.surface(ray, hit);
                let mut l = surface_radiance(scene, ray, &s, sampler, medium);
                let n = if s.n.dot(ray.dir) <= 0.0 { s.n } else { -s.n };
                if let Some(e) = self.solution.irradiance_at(s.p, n) {
                    let albedo = scene.materials[s.material as usize].albedo(s.p, s.n);
                    l += albedo * FRAC_1_PI * e;
                }
                (l, hit.t)
            }
            None => (scene.settings.background, scene.settings.max_distance),
        };
        let Some(medium) = medium else {
            return surface;
        };
        let offset = if self.jitter { sampler.next() } else { 0.5 };
        let through = medium.transmittance(ray.origin, ray.dir, 0.0, t_end);
        let march_end = t_end.min(scene.settings.max_distance);
        surface * through + in_scattered(scene, medium, ray, march_end, self.steps, offset, sampler)
    }
}
