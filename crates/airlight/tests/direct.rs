//! The `direct` integrator against closed forms, and rendering's determinism.

use airlight::geometry::Ray;
use airlight::integrator::{Direct, Integrator};
use airlight::prelude::*;
use airlight::render::render_with;
use airlight::sampling::Sampler;

#[test]
fn diffuse_plane_under_point_light_matches_inverse_square_law() {
    let albedo = Rgb::new(0.6, 0.3, 0.9);
    let light_pos = vec3(1.0, 3.0, 0.5);
    let intensity = Rgb::new(7.0, 5.0, 2.0);
    let eye = vec3(0.0, 2.0, -6.0);
    let scene = SceneBuilder::new()
        .size(8, 8)
        .camera(Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 40.0))
        .material("m", Material::diffuse(albedo))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .light(Light::point(light_pos, intensity))
        .build()
        .unwrap();
    let mut sampler = Sampler::for_pixel(0, 0, 0);
    for target in [vec3(0.0, 0.0, 0.0), vec3(2.5, 0.0, 3.0), vec3(-3.0, 0.0, 1.0), vec3(0.7, 0.0, -2.0)] {
        let ray = Ray::new(eye, (target - eye).normalize());
        let got = Direct.radiance(&scene, &ray, &mut sampler);
        let to_light = light_pos.as_dvec3() - target.as_dvec3();
        let d2 = to_light.length_squared();
        let cos = to_light.y / d2.sqrt();
        for c in 0..3 {
            let expected = intensity[c] as f64 * cos / d2 * albedo[c] as f64 / std::f64::consts::PI;
            let rel = (got[c] as f64 / expected - 1.0).abs();
            assert!(rel < 1e-4, "at {target}: channel {c}: {} vs {expected} ({rel:e})", got[c]);
        }
    }
}

#[test]
fn shadowed_points_are_black_and_two_sided_surfaces_reflect() {
    // A quad between the light and the floor shades the floor under it; the
    // quad's underside, lit from below by a second light, is two-sided diffuse.
    let scene = SceneBuilder::new()
        .material("m", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .object(Shape::quad(vec3(-1.0, 1.0, -1.0), vec3(0.0, 0.0, 2.0), vec3(2.0, 0.0, 0.0)), "m")
        .light(Light::point(vec3(0.0, 3.0, 0.0), Rgb::splat(10.0)))
        .build()
        .unwrap();
    let mut sampler = Sampler::for_pixel(0, 0, 0);
    let down = Ray::new(vec3(0.0, 0.5, 0.0), -Vec3::Y);
    assert_eq!(Direct.radiance(&scene, &down, &mut sampler), Rgb::ZERO);
    let beside = Ray::new(vec3(3.0, 0.5, 0.0), -Vec3::Y);
    assert!(Direct.radiance(&scene, &beside, &mut sampler).x > 0.0);
    // The quad's top, seen from above, is lit although its normal is −y.
    let top = Ray::new(vec3(0.2, 2.0, 0.1), -Vec3::Y);
    let l = Direct.radiance(&scene, &top, &mut sampler).x as f64;
    // The hit (0.2, 1, 0.1) sees the light at (0, 3, 0): d² = 4.05, cos = 2/√4.05.
    let d2 = 4.05f64;
    let expected = 10.0 * (2.0 / d2.sqrt()) / d2 * 0.5 / std::f64::consts::PI;
    assert!((l / expected - 1.0).abs() < 1e-3, "{l} vs {expected}");
}

fn busy_scene() -> Scene {
    SceneBuilder::new()
        .size(37, 23)
        .with_settings(|s| s.spp = 3)
        .camera(Camera::look_at(vec3(0.0, 2.0, -6.0), vec3(0.0, 0.5, 0.0), Vec3::Y, 50.0).with_lens(0.05, 6.0))
        .material("floor", Material::checker(Rgb::splat(0.8), Rgb::splat(0.1), 0.5))
        .material("shiny", Material::phong(Rgb::new(0.2, 0.3, 0.8), Rgb::splat(0.3), 30.0))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
        .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 1.0), "shiny")
        .light(Light::quad(vec3(-1.0, 4.0, -1.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 0.0, 2.0), Rgb::splat(5.0)))
        .light(Light::sphere(vec3(2.0, 2.0, -1.0), 0.3, Rgb::splat(20.0)))
        .light(Light::spot(vec3(-2.0, 3.0, -1.0), Vec3::ZERO, Rgb::splat(30.0), 30.0, 20.0))
        .build()
        .unwrap()
}

#[test]
fn image_does_not_depend_on_thread_count() {
    let scene = busy_scene();
    let render_on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render_with(&scene, &Direct, &RenderObserver::none()))
    };
    let one = render_on(1);
    assert!(one == render_on(2), "1 and 2 threads differ");
    assert!(one == render_on(3), "1 and 3 threads differ");
    assert!(one.mean().x > 0.0);
}

#[test]
fn area_lights_are_seen_by_the_camera_on_their_emitting_side() {
    let scene = busy_scene();
    let mut sampler = Sampler::for_pixel(0, 0, 0);
    // Looking up at the quad light (it emits downward): its radiance.
    let up = Ray::new(vec3(0.0, 1.0, 0.0) + vec3(0.0, 1.5, 0.0), Vec3::Y);
    assert_eq!(Direct.radiance(&scene, &up, &mut sampler), Rgb::splat(5.0));
    // From above, its back is black.
    let down = Ray::new(vec3(0.0, 6.0, 0.0), -Vec3::Y);
    assert_eq!(Direct.radiance(&scene, &down, &mut sampler), Rgb::ZERO);
}
