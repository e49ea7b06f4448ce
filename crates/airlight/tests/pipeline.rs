//! The render pipeline's shared rules, checked across every integrator: a
//! medium that neither absorbs nor scatters is vacuum, a surface beyond
//! `max_distance` is still seen, moving a light moves its surface and its
//! shadow, and an animation relights radiosity instead of recompiling.

use airlight::film::compare;
use airlight::integrator::{Estimate, IntegratorDesc};
use airlight::light::Keyframes;
use airlight::prelude::*;
use airlight::radiosity::Radiosity;
use airlight::render::{frame_time, render, set_time};

/// A floor 20 units from the camera, a ball, and a point light; with
/// `max_distance` 5 every camera ray's surface lies beyond it.
fn far_floor(medium: Option<Medium>) -> Scene {
    let mut b = SceneBuilder::new()
        .size(24, 16)
        .with_settings(|s| {
            s.spp = 2;
            s.max_distance = 5.0;
        })
        .camera(Camera::look_at(vec3(0.0, 12.0, -16.0), vec3(0.0, 0.0, 0.0), Vec3::Y, 30.0))
        .material("m", Material::diffuse(Rgb::splat(0.6)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 1.0), "m")
        .light(Light::point(vec3(1.0, 5.0, -1.0), Rgb::splat(40.0)));
    if let Some(m) = medium {
        b = b.medium(m);
    }
    b.build().unwrap()
}

#[test]
fn every_integrator_sees_a_vacuum_and_surfaces_beyond_max_distance_as_direct_does() {
    let vacuum = Medium::homogeneous(Rgb::ZERO, Rgb::ZERO, 0.3);
    for medium in [None, Some(vacuum)] {
        let scene = far_floor(medium.clone());
        assert!(scene.medium().is_none(), "a vacuum is no medium");
        let direct = render(&scene, IntegratorDesc::default().build(&scene).unwrap().as_ref(), &Default::default());
        assert!(direct.mean().min_element() > 0.01, "the far floor is lit and seen");
        // Every integrator that estimates light (a debug view has its own image).
        for kind in IntegratorKind::ALL.into_iter().filter(|k| k.estimate() != Estimate::DebugView) {
            let mut desc = IntegratorDesc::new(kind);
            desc.path.max_depth = 1;
            // Stratified camera samples would place the rays elsewhere.
            desc.stochastic.stratify = false;
            desc.path.stratify = false;
            let integrator = desc.build(&scene).unwrap();
            let image = render(&scene, integrator.as_ref(), &Default::default());
            let e = compare(&image, &direct).unwrap();
            // The same camera rays and light samples: the single-scattering
            // integrators give direct's image bit for bit; radiosity adds
            // the floor's and ball's bounce light (a few percent), the path
            // tracer draws its own numbers (delta light: the same sums).
            let bound = match kind {
                IntegratorKind::Radiosity => 0.1,
                IntegratorKind::Path => 1e-5,
                _ => 0.0,
            };
            assert!(e.rel_rmse <= bound, "{kind} (medium {medium:?}): {e:?}");
        }
    }
}

/// A floor under a sun, a quad light that faces up (its black underside
/// shadows the floor) and slides from x = −2 to x = 2 along its keyframes.
fn sliding_quad() -> Scene {
    let quad = Light::quad(vec3(-2.5, 2.0, 0.5), Vec3::X, -Vec3::Z, Rgb::splat(3.0));
    let path = Keyframes::new(vec![(0.0, vec3(-2.0, 2.0, 0.0)), (1.0, vec3(2.0, 2.0, 0.0))]).unwrap();
    SceneBuilder::new()
        .size(48, 32)
        .with_settings(|s| {
            s.spp = 1;
            s.background = Rgb::splat(0.2);
        })
        .camera(Camera::look_at(vec3(0.0, 0.3, -4.0), vec3(0.0, 1.2, 0.0), Vec3::Y, 60.0))
        .material("floor", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
        .light(Light::distant(vec3(0.0, -1.0, 0.0), Rgb::splat(2.0)))
        .moving_light(quad, path)
        .build()
        .unwrap()
}

/// The pixel whose centre ray passes nearest `p`.
fn pixel_of(scene: &Scene, p: Vec3) -> (u32, u32) {
    let s = scene.settings();
    let mut best = (f32::INFINITY, (0, 0));
    for y in 0..s.film.height {
        for x in 0..s.film.width {
            let ray = scene.camera().ray(
                glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5),
                s.film.width,
                s.film.height,
                glam::Vec2::splat(0.5),
            );
            let to = p - ray.origin;
            let miss = (to - ray.dir * to.dot(ray.dir)).length();
            if miss < best.0 {
                best = (miss, (x, y));
            }
        }
    }
    best.1
}

#[test]
fn a_keyframed_quad_lights_surface_and_shadow_are_where_its_frame_puts_them() {
    let mut scene = sliding_quad();
    let mut integrator = IntegratorDesc::default().build(&scene).unwrap();
    set_time(&mut scene, integrator.as_mut(), frame_time(1, 2)).unwrap();
    let image = render(&scene, integrator.as_ref(), &Default::default());
    let seen = |p: Vec3| {
        let (x, y) = pixel_of(&scene, p);
        image.pixel(x, y).x
    };
    // The camera looks up at the quad's black underside where it now is, and
    // at the background where it was.
    assert!(seen(vec3(2.0, 2.0, 0.0)) < 0.01, "the light's surface is at x = 2");
    assert!((seen(vec3(-2.0, 2.0, 0.0)) - 0.2).abs() < 1e-6, "and no longer at x = −2");
    // The sun's shadow of the quad falls under its new place, not its old:
    // the radiance of floor points seen from just above them.
    let floor = |x: f32| {
        let ray = airlight::geometry::Ray::new(vec3(x, 1.0, -1.0), vec3(0.0, -1.0, 1.0).normalize());
        integrator.radiance(&scene, &ray, &mut airlight::sampling::Sampler::for_pixel(0, 0, 0)).x
    };
    let (new, old) = (floor(2.0), floor(-2.0));
    let lit = 0.5 / std::f32::consts::PI * 2.0;
    assert!((old - lit).abs() < 1e-5 * lit, "floor under the old place: {old} vs {lit}");
    assert_eq!(new, 0.0, "floor under the new place is in the quad's shadow");
}

#[test]
fn frames_relight_radiosity_without_recompiling_and_match_a_fresh_compile() {
    let file = SceneFile::from_toml_str(include_str!("../../../scenes/room_moving_lights.toml"), None).unwrap();
    let SceneFile { mut scene, integrator: mut desc } = file;
    let s = scene.settings_mut();
    (s.film.width, s.film.height, s.spp) = (24, 16, 1);
    desc.radiosity.patch_size = Some(0.5);
    let compiled = Radiosity::compile_count();
    let mut integrator = desc.build(&scene).unwrap();
    assert_eq!(Radiosity::compile_count(), compiled + 1);
    let mut last = None;
    for frame in 0..3 {
        set_time(&mut scene, integrator.as_mut(), frame_time(frame, 3)).unwrap();
        last = Some(render(&scene, integrator.as_ref(), &Default::default()));
    }
    assert_eq!(Radiosity::compile_count(), compiled + 1, "three frames, one compile");
    // Relit in place, the last frame is what a solution compiled for it
    // gives (the room's lights are point lights: the links are the same).
    let fresh = desc.build(&scene).unwrap();
    assert_eq!(last.unwrap(), render(&scene, fresh.as_ref(), &Default::default()));
}
