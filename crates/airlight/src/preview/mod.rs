//! A fast preview for interactive viewers (issue 9): one primary ray per
//! pixel sample, direct light with one shadow ray per light, the indirect
//! light of a [`Radiosity`] solution that the viewer relights each frame,
//! and, in a medium, the closed-form airlight glow of the analytic
//! integrator instead of a march. It is the radiosity integrator with its
//! costly part, the march, swapped for a closed form, so that a light can
//! move at interactive rates.
//!
//! [`set_lights`] moves a scene's lights in place between frames, keeping
//! everything that depends on their positions (the light culling grid, the
//! surfaces of area lights in the BVH) in step.

use crate::Rgb;
use crate::geometry::{GeometryBuilder, Ray};
use crate::integrator::analytic::AnalyticOptions;
use crate::integrator::{Analytic, Integrator, in_scattered, surface_radiance};
use crate::light::Light;
use crate::radiosity::Radiosity;
use crate::sampling::Sampler;
use crate::scene::{LightCulling, Scene};
use std::f32::consts::FRAC_1_PI;

mod cache;
pub use cache::FirstSample;

/// March steps per ray when the medium has no closed form (height fog).
pub const FALLBACK_STEPS: u32 = 16;

/// How the preview lights the medium.
enum Glow {
    /// No medium, or one that does not scatter.
    None,
    /// Closed-form single scattering (homogeneous media).
    Analytic(Box<Analytic>),
    /// A short jittered march (media without a closed form).
    March { steps: u32 },
}

/// The preview integrator: see the module documentation. It borrows the
/// solution, which must have been updated for the scene's current lights.
pub struct Preview<'a> {
    solution: Option<&'a Radiosity>,
    glow: Glow,
}

impl<'a> Preview<'a> {
    /// The preview of `scene` with its current lights. The analytic glow is
    /// built from the lights' positions, so a new `Preview` is needed after
    /// lights move (it is cheap: a list of point emitters). Without a
    /// solution the indirect light is left out.
    pub fn new(scene: &Scene, solution: Option<&'a Radiosity>) -> Self {
        let glow = match &scene.medium {
            Some(m) if m.sigma_s != Rgb::ZERO => {
                // Volumetric shadows cost a boundary search per ray: a
                // preview does without them.
                let options = AnalyticOptions { shadows: false, ..AnalyticOptions::from_settings(&scene.settings) };
                match Analytic::new(scene, options) {
                    Ok(a) => Glow::Analytic(Box::new(a)),
                    Err(_) => Glow::March { steps: FALLBACK_STEPS.min(scene.settings.steps) },
                }
            }
            _ => Glow::None,
        };
        Preview { solution, glow }
    }

    /// What lights the medium: "none", "analytic glow" or "marched glow".
    pub fn glow_name(&self) -> &'static str {
        match self.glow {
            Glow::None => "none",
            Glow::Analytic(_) => "analytic glow",
            Glow::March { .. } => "marched glow",
        }
    }
}

impl Integrator for Preview<'_> {
    /// L = T·(L_direct + ρ/π·E_ind) + L_glow, as
    /// [`crate::integrator::RadiosityIntegrator`] but with the glow in closed
    /// form where the medium allows it.
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        let medium = scene.medium.as_ref();
        let tmax = if medium.is_some() { f32::INFINITY } else { scene.settings.max_distance };
        let (surface, t_end) = match scene.geometry.intersect(ray, tmax) {
            Some(hit) => {
                let s = scene.geometry.surface(ray, hit);
                let mut l = surface_radiance(scene, ray, &s, sampler, medium);
                if let Some(solution) = self.solution {
                    let n = if s.n.dot(ray.dir) <= 0.0 { s.n } else { -s.n };
                    if let Some(e) = solution.irradiance_at(s.p, n) {
                        l += scene.materials[s.material as usize].albedo(s.p, s.n) * FRAC_1_PI * e;
                    }
                }
                (l, hit.t)
            }
            None => (scene.settings.background, scene.settings.max_distance),
        };
        self.through_medium(scene, ray, surface, t_end, sampler)
    }
}

impl Preview<'_> {
    /// `surface` radiance from distance `t_end` along `ray`, attenuated by
    /// the medium, plus the glow in front of it.
    fn through_medium(&self, scene: &Scene, ray: &Ray, surface: Rgb, t_end: f32, sampler: &mut Sampler) -> Rgb {
        let Some(medium) = &scene.medium else {
            return surface;
        };
        let through = medium.transmittance(ray.origin, ray.dir, 0.0, t_end);
        let end = t_end.min(scene.settings.max_distance);
        let glow = match &self.glow {
            Glow::None => Rgb::ZERO,
            Glow::Analytic(a) => a.in_scattered(scene, medium, ray, end),
            Glow::March { steps } => {
                let offset = sampler.next();
                in_scattered(scene, medium, ray, end, *steps, offset, sampler)
            }
        };
        surface * through + glow
    }
}

/// Puts `lights` (the scene's lights, moved or dimmed; the same number, in
/// the same order) into `scene`, rebuilding the light culling grid and, when
/// the surface of a sphere or quad light moved, the BVH, so that the camera
/// sees the light where it now is and its old surface casts no shadow.
/// Returns whether the BVH was rebuilt. The scene's bounding sphere is kept:
/// it matters only to distant lights, which do not move.
///
/// Panics when the number of lights differs (a caller's bug).
pub fn set_lights(scene: &mut Scene, lights: &[Light]) -> bool {
    assert_eq!(lights.len(), scene.lights.len(), "set_lights: the scene has {} lights", scene.lights.len());
    let surface = |l: &Light| match *l {
        Light::Sphere { center, radius, .. } => Some((center, glam::Vec3::splat(radius), glam::Vec3::ZERO)),
        Light::Quad { corner, edge_u, edge_v, .. } => Some((corner, edge_u, edge_v)),
        _ => None,
    };
    let moved = scene.lights.iter().zip(lights).any(|(a, b)| surface(a) != surface(b));
    scene.lights.copy_from_slice(lights);
    scene.light_culling = LightCulling::new(&scene.lights);
    if moved {
        rebuild_geometry(scene);
    }
    moved
}

/// The BVH as `SceneBuilder::build` makes it: the objects, then the area
/// lights' surfaces with the black material that the build appends last.
fn rebuild_geometry(scene: &mut Scene) {
    let mut geometry = GeometryBuilder::default();
    for (shape, material) in &scene.objects {
        geometry.add(shape, *material, None);
    }
    let black = scene.materials.len() as u32 - 1;
    for (i, light) in scene.lights.iter().enumerate() {
        let shape = match *light {
            Light::Sphere { center, radius, .. } => crate::geometry::Shape::sphere(center, radius),
            Light::Quad { corner, edge_u, edge_v, .. } => crate::geometry::Shape::quad(corner, edge_u, edge_v),
            _ => continue,
        };
        geometry.add(&shape, black, Some(i as u32));
    }
    scene.geometry = geometry.build();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::medium::Medium;
    use crate::prelude::*;
    use crate::render::render_with;

    fn room(medium: Option<Medium>) -> Scene {
        let mut b = SceneBuilder::new()
            .size(24, 16)
            .camera(Camera::look_at(vec3(0.0, 1.0, -4.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 60.0))
            .material("white", Material::diffuse(Rgb::splat(0.7)))
            .object(Shape::quad(vec3(-2.0, 0.0, -2.0), vec3(0.0, 0.0, 4.0), vec3(4.0, 0.0, 0.0)), "white")
            .object(Shape::quad(vec3(-2.0, 0.0, 2.0), vec3(0.0, 3.0, 0.0), vec3(4.0, 0.0, 0.0)), "white")
            .light(Light::quad(vec3(-0.5, 2.5, -0.5), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), Rgb::splat(5.0)));
        if let Some(m) = medium {
            b = b.medium(m);
        }
        b.build().unwrap()
    }

    #[test]
    fn without_a_medium_the_preview_is_the_radiosity_integrator() {
        let scene = room(None);
        let full = crate::integrator::RadiosityIntegrator::new(&scene).unwrap();
        let preview = Preview::new(&scene, Some(&full.solution));
        assert_eq!(preview.glow_name(), "none");
        let a = render_with(&scene, &preview, &RenderObserver::none());
        let b = render_with(&scene, &full, &RenderObserver::none());
        assert_eq!(a, b);
        assert!(a.mean().max_element() > 0.0);
    }

    #[test]
    fn in_a_homogeneous_medium_the_glow_is_analytic_and_adds_light() {
        let fog = Medium::homogeneous(Rgb::ZERO, Rgb::splat(0.05), 0.0);
        let scene = room(Some(fog));
        let preview = Preview::new(&scene, None);
        assert_eq!(preview.glow_name(), "analytic glow");
        let foggy = render_with(&scene, &preview, &RenderObserver::none());
        let clear = room(None);
        let plain = render_with(&clear, &Preview::new(&clear, None), &RenderObserver::none());
        // Rays that hit nothing see only the glow: light where there was none.
        let (x, y) = (12, 0);
        assert_eq!(plain.pixel(x, y), Rgb::ZERO);
        assert!(foggy.pixel(x, y).min_element() > 0.0, "{}", foggy.pixel(x, y));
    }

    #[test]
    fn moving_an_area_light_moves_its_surface_and_an_unmoved_one_keeps_the_bvh() {
        let mut scene = room(None);
        let before = render_with(&scene, &Preview::new(&scene, None), &RenderObserver::none());
        let same = scene.lights.clone();
        assert!(!set_lights(&mut scene, &same));
        let moved: Vec<Light> = scene.lights.iter().map(|l| l.moved_to(vec3(1.2, 2.5, 0.0))).collect();
        assert!(set_lights(&mut scene, &moved));
        // The camera ray toward the old centre no longer meets the light.
        let old = Ray::new(vec3(0.0, 1.0, -4.0), (vec3(0.0, 2.5, 0.0) - vec3(0.0, 1.0, -4.0)).normalize());
        let hit = scene.geometry.intersect(&old, 100.0).map(|h| scene.geometry.surface(&old, h).emitter);
        assert_ne!(hit, Some(Some(0)));
        let new = Ray::new(vec3(0.0, 1.0, -4.0), (vec3(1.2, 2.5, 0.0) - vec3(0.0, 1.0, -4.0)).normalize());
        let hit = scene.geometry.intersect(&new, 100.0).map(|h| scene.geometry.surface(&new, h).emitter);
        assert_eq!(hit, Some(Some(0)));
        // Moving back restores the image bit for bit.
        assert!(set_lights(&mut scene, &same));
        let after = render_with(&scene, &Preview::new(&scene, None), &RenderObserver::none());
        assert_eq!(before, after);
    }
}
