use super::*;
use crate::integrator::{RadiosityIntegrator, RadiosityOptions};
use crate::light::Light;
use crate::material::Material;
use crate::medium::Medium;
use crate::prelude::*;

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

fn preview<'a>(scene: &Scene, solution: Option<&'a Radiosity>) -> Preview<'a> {
    Preview::new(scene, solution, AnalyticOptions::default(), RaymarchOptions::default())
}

#[test]
fn without_a_medium_the_preview_is_the_radiosity_integrator() {
    let scene = room(None);
    let full = RadiosityIntegrator::new(&scene, RadiosityOptions::default(), RaymarchOptions::default()).unwrap();
    let preview = preview(&scene, Some(&full.solution));
    assert_eq!(preview.glow_name(), "none");
    let a = crate::render::render(&scene, &preview, &RenderObserver::none());
    let b = crate::render::render(&scene, &full, &RenderObserver::none());
    assert_eq!(a, b);
    assert!(a.mean().max_element() > 0.0);
}

#[test]
fn in_a_homogeneous_medium_the_glow_is_analytic_and_adds_light() {
    let fog = Medium::homogeneous(Rgb::ZERO, Rgb::splat(0.05), 0.0);
    let scene = room(Some(fog));
    let foggy_preview = preview(&scene, None);
    assert_eq!(foggy_preview.glow_name(), "analytic glow");
    let foggy = crate::render::render(&scene, &foggy_preview, &RenderObserver::none());
    let clear = room(None);
    let plain = crate::render::render(&clear, &preview(&clear, None), &RenderObserver::none());
    // Rays that hit nothing see only the glow: light where there was none.
    let (x, y) = (12, 0);
    assert_eq!(plain.pixel(x, y), Rgb::ZERO);
    assert!(foggy.pixel(x, y).min_element() > 0.0, "{}", foggy.pixel(x, y));
}

#[test]
fn in_a_density_grid_the_glow_is_marched_and_adds_light() {
    // No closed form: the preview falls back to its short march (stated in
    // docs/scene-format.md), which sees the grid's fog where the box is.
    let grid = crate::medium::DensityGrid::new(
        [2, 2, 2],
        vec![0.0, 1.0, 0.5, 0.2, 1.0, 0.0, 0.3, 0.8],
        vec3(-2.0, 0.0, -2.0),
        vec3(2.0, 3.0, 2.0),
        glam::Affine3A::IDENTITY,
    )
    .unwrap();
    let scene = room(Some(Medium::grid(Rgb::ZERO, Rgb::splat(0.2), 0.0, grid)));
    let foggy_preview = preview(&scene, None);
    assert_eq!(foggy_preview.glow_name(), "marched glow");
    let foggy = crate::render::render(&scene, &foggy_preview, &RenderObserver::none());
    let clear = room(None);
    let plain = crate::render::render(&clear, &preview(&clear, None), &RenderObserver::none());
    let (x, y) = (12, 0);
    assert_eq!(plain.pixel(x, y), Rgb::ZERO);
    assert!(foggy.pixel(x, y).min_element() > 0.0, "{}", foggy.pixel(x, y));
    assert!(foggy.pixels.iter().all(|p| p.is_finite()));
}
