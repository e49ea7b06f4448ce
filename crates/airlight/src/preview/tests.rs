use super::*;
use crate::integrator::{RadiosityIntegrator, RadiosityOptions};
use crate::light::Light;
use crate::material::Material;
use crate::medium::Medium;
use crate::prelude::*;

/// A floor and a back wall lit by a quad light facing down from above.
fn room(medium: Option<Medium>) -> Scene {
    room_lit_by(Light::quad(vec3(-0.5, 2.5, -0.5), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), Rgb::splat(5.0)), medium)
}

fn room_lit_by(light: Light, medium: Option<Medium>) -> Scene {
    let mut b = SceneBuilder::new()
        .size(24, 16)
        .camera(Camera::look_at(vec3(0.0, 1.0, -4.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 60.0))
        .material("white", Material::diffuse(Rgb::splat(0.7)))
        .object(Shape::quad(vec3(-2.0, 0.0, -2.0), vec3(0.0, 0.0, 4.0), vec3(4.0, 0.0, 0.0)), "white")
        .object(Shape::quad(vec3(-2.0, 0.0, 2.0), vec3(0.0, 3.0, 0.0), vec3(4.0, 0.0, 0.0)), "white")
        .light(light);
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
fn in_a_homogeneous_medium_a_point_light_glows_in_closed_form_and_adds_light() {
    let fog = Medium::homogeneous(Rgb::ZERO, Rgb::splat(0.05), 0.0);
    let lamp = Light::point(vec3(0.0, 2.5, 0.0), Rgb::splat(20.0));
    let scene = room_lit_by(lamp, Some(fog));
    let foggy_preview = preview(&scene, None);
    assert_eq!(foggy_preview.glow_name(), "analytic glow");
    let foggy = crate::render::render(&scene, &foggy_preview, &RenderObserver::none());
    let clear = room_lit_by(lamp, None);
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

/// A quad light is a sum of points to the closed form, 256 of them a ray
/// and more near the light: the preview marches its glow instead, which
/// must give the closed form's answer on average (within the march's
/// noise, which is large on rays that pass close to the light).
#[test]
fn an_area_light_in_fog_is_marched_and_agrees_with_the_closed_form() {
    let fog = Medium::homogeneous(Rgb::splat(0.01), Rgb::splat(0.08), 0.3);
    let scene = room(Some(fog.clone()));
    let marched = preview(&scene, None);
    assert_eq!(marched.glow_name(), "marched glow");
    let exact = Analytic::new(&scene, AnalyticOptions::default()).unwrap();
    assert!(!exact.lights_are_points());
    let camera = scene.camera().rays(24, 16);
    let samples = 512;
    let (mut total_marched, mut total_exact, mut total_variance, mut rays) = (0.0f64, 0.0f64, 0.0f64, 0);
    for y in 0..16 {
        for x in 0..24 {
            let ray = camera.ray(glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5), glam::Vec2::ZERO);
            // Rays that meet the floor or the wall: the fog in front of
            // them sees the light unblocked, so the march's shadow rays
            // change nothing (beyond the wall and below the floor they
            // would, and the closed form, without shadows, does not).
            let Some(hit) = scene.geometry().intersect(&ray, f32::INFINITY) else { continue };
            let reference = exact.in_scattered(&scene, &fog, &ray, hit.t).element_sum() as f64;
            let (mut sum, mut sum_squares) = (0.0f64, 0.0f64);
            for k in 0..samples {
                let mut sampler = Sampler::for_pixel(3, (y * 24 + x) as u64, k);
                let v = marched.glow(&scene, &fog, &ray, hit.t, &mut sampler).element_sum() as f64;
                sum += v;
                sum_squares += v * v;
            }
            let mean = sum / samples as f64;
            let variance_of_mean = (sum_squares / samples as f64 - mean * mean) / samples as f64;
            let z = (mean - reference) / variance_of_mean.sqrt();
            assert!(
                z.abs() < 5.0,
                "ray ({x}, {y}): marched {mean} ± {}, closed form {reference}",
                variance_of_mean.sqrt()
            );
            total_marched += mean;
            total_exact += reference;
            total_variance += variance_of_mean;
            rays += 1;
        }
    }
    assert!(rays > 150, "{rays} rays met the room");
    let (difference, error) = (total_marched - total_exact, total_variance.sqrt());
    assert!(
        difference.abs() < 4.0 * error,
        "marched {total_marched} ± {error} against the closed form's {total_exact}"
    );
    assert!(difference.abs() < 0.01 * total_exact, "marched {total_marched} against the closed form's {total_exact}");
}
