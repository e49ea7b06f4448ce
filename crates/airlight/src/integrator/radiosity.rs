//! The `radiosity` integrator: direct light per pixel, indirect light from
//! the patches (direct and indirect light "at different frequencies").

use super::raymarch::march;
use super::{Integrator, IntegratorDesc, IntegratorError, RadiosityOptions, RaymarchOptions, single_scattering};
use crate::Rgb;
use crate::geometry::{Ray, SurfaceHit};
use crate::radiosity::{CompileParams, FrameTimes, Radiosity};
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
/// added as the `raymarch` integrator does (its `steps`, `jitter`); the
/// patches' indirect light is computed in vacuum.
///
/// The solution is compiled once; when the scene's lights change,
/// [`Integrator::lights_changed`] relights it ([`Radiosity::update`])
/// without recompiling.
pub struct RadiosityIntegrator {
    pub solution: Radiosity,
    pub options: RadiosityOptions,
    pub march: RaymarchOptions,
    /// Time spent in the last relighting.
    pub last_update: FrameTimes,
}

impl RadiosityIntegrator {
    /// Compiles and lights `scene`.
    pub fn new(scene: &Scene, options: RadiosityOptions, march: RaymarchOptions) -> Result<Self, IntegratorError> {
        IntegratorDesc { radiosity: options, raymarch: march, ..IntegratorDesc::default() }.validate()?;
        let mut solution = Radiosity::compile_with(scene, CompileParams::for_scene(scene, &options))?;
        let last_update = solution.update(scene, options.bounces);
        Ok(RadiosityIntegrator { solution, options, march, last_update })
    }
}

/// The light a radiosity solution reflects at `s` toward a ray arriving
/// along `dir`: ρ/π times the indirect irradiance on the side facing it,
/// interpolated from the patches `s` sees (with `seen`, a shadow ray per
/// nearby patch) or from all nearby patches.
pub fn indirect_radiance(scene: &Scene, solution: &Radiosity, dir: glam::Vec3, s: &SurfaceHit, seen: bool) -> Rgb {
    let n = s.facing(dir);
    let e = if seen { solution.irradiance_seen_at(s.p, n, scene.geometry()) } else { solution.irradiance_at(s.p, n) };
    match e {
        Some(e) => scene.material_at(s).albedo(s.p, s.n) * FRAC_1_PI * e,
        None => Rgb::ZERO,
    }
}

impl Integrator for RadiosityIntegrator {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        single_scattering(
            scene,
            ray,
            sampler,
            |s| indirect_radiance(scene, &self.solution, ray.dir, s, true),
            |medium, length, sampler| march(scene, medium, ray, length, self.march, sampler),
        )
    }

    fn lights_changed(&mut self, scene: &Scene) -> Result<(), IntegratorError> {
        self.last_update = self.solution.update(scene, self.options.bounces);
        Ok(())
    }
}
