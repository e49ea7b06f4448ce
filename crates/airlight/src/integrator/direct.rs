use super::{Integrator, surface_radiance};
use crate::Rgb;
use crate::geometry::Ray;
use crate::sampling::Sampler;
use crate::scene::Scene;

/// Direct illumination of surfaces with shadows, in vacuum.
pub struct Direct;

impl Integrator for Direct {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        match scene.geometry.intersect(ray, f32::INFINITY) {
            Some(hit) => {
                let surface = scene.geometry.surface(ray, hit);
                surface_radiance(scene, ray, &surface, sampler, None)
            }
            None => scene.settings.background,
        }
    }
}
