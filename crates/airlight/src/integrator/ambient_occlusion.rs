//! `ambient_occlusion`: a view of a scene's geometry, not of its light.
//! Each sample is 1 when a cosine-weighted direction from the first surface
//! a camera ray meets leaves without hitting anything within
//! `ao_distance`, else 0; a pixel's mean is the open fraction of its
//! surface's hemisphere (Zhukov, Iones and Kronin, "An ambient light
//! illumination model", 1998). Lights and media are ignored; a ray that
//! meets nothing is black.
//!
//! It is also the worked example of adding an integrator
//! (docs/developing.md): this file, its kind in `integrator/mod.rs`, and
//! its option and build arm in `integrator/options.rs`.

use super::Integrator;
use crate::Rgb;
use crate::geometry::{Ray, offset_origin};
use crate::sampling::{Sampler, cosine_hemisphere, to_world};
use crate::scene::Scene;

/// The ambient occlusion view's options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusionOptions {
    /// How far a direction must be open to count as open, in world units.
    pub distance: f32,
}

impl Default for AmbientOcclusionOptions {
    fn default() -> Self {
        AmbientOcclusionOptions { distance: 1.0 }
    }
}

pub struct AmbientOcclusion {
    options: AmbientOcclusionOptions,
}

impl AmbientOcclusion {
    pub fn new(options: AmbientOcclusionOptions) -> Self {
        AmbientOcclusion { options }
    }
}

impl Integrator for AmbientOcclusion {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        let geometry = scene.geometry();
        let Some(hit) = geometry.intersect(ray, f32::INFINITY) else {
            return Rgb::ZERO;
        };
        let surface = geometry.surface(ray, hit);
        let n = surface.facing(ray.dir);
        let dir = to_world(cosine_hemisphere(sampler.next2()), n);
        let origin = offset_origin(surface.p, n, dir);
        let open = !geometry.occluded(origin, dir, self.options.distance);
        Rgb::splat(if open { 1.0 } else { 0.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{Estimate, IntegratorDesc, IntegratorKind};
    use crate::prelude::*;

    /// A floor under a ceiling `height` above it, seen from between them.
    fn between_planes(height: f32, distance: f32) -> (Scene, IntegratorDesc) {
        let scene = SceneBuilder::new()
            .size(4, 4)
            .with_settings(|s| s.spp = 4096)
            .camera(Camera::look_at(vec3(0.0, height / 2.0, 0.0), Vec3::ZERO, Vec3::Z, 20.0))
            .material("grey", Material::diffuse(Rgb::splat(0.5)))
            .object(Shape::plane(Vec3::ZERO, Vec3::Y), "grey")
            .object(Shape::plane(vec3(0.0, height, 0.0), -Vec3::Y), "grey")
            .build()
            .unwrap();
        let mut desc = IntegratorDesc::new(IntegratorKind::AmbientOcclusion);
        desc.ambient_occlusion.distance = distance;
        (scene, desc)
    }

    #[test]
    fn under_a_ceiling_the_open_fraction_is_the_closed_form() {
        // A cosine-weighted direction at cos θ = μ meets the ceiling at
        // h/μ; it is open within d when μ < h/d, which the cosine-weighted
        // hemisphere gives with probability (h/d)² (for d ≥ h; 1 below).
        for (height, distance) in [(1.0f32, 2.0f32), (1.0, 1.25), (1.0, 0.9)] {
            let (scene, desc) = between_planes(height, distance);
            let integrator = desc.build(&scene).unwrap();
            let image = crate::render(&scene, integrator.as_ref(), &RenderObserver::none());
            let expected = ((height / distance) as f64).powi(2).min(1.0);
            let mean = image.mean().x as f64;
            let samples = 16.0 * 4096.0;
            let sigma = (expected * (1.0 - expected) / samples).sqrt().max(1e-6);
            assert!((mean - expected).abs() < 5.0 * sigma, "h {height}, d {distance}: {mean} against {expected}");
        }
    }

    #[test]
    fn it_is_a_debug_view() {
        assert_eq!(IntegratorKind::AmbientOcclusion.estimate(), Estimate::DebugView);
        assert_eq!(IntegratorKind::AmbientOcclusion.name(), "ambient_occlusion");
    }
}
