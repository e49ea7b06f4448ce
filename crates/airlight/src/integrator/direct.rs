use super::{Integrator, first_surface, first_surface_batch, no_extra};
use crate::Rgb;
use crate::geometry::Ray;
use crate::sampling::Sampler;
use crate::scene::Scene;

/// Direct illumination of surfaces with shadows; any medium is ignored.
pub struct Direct;

impl Integrator for Direct {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        first_surface(scene, ray, sampler, None, no_extra).0
    }

    fn radiance_batch(&self, scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb]) {
        first_surface_batch(scene, rays, samplers, out)
    }
}
