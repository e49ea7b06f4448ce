//! The `direct` integrator against closed forms, and rendering's determinism.

use airlight::geometry::Ray;
use airlight::integrator::PathOptions;
use airlight::integrator::RaymarchOptions;
use airlight::integrator::{Direct, Integrator, PathTracer};
use airlight::prelude::*;
use airlight::render::render;
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
        pool.install(|| render(&scene, &Direct, &RenderObserver::none()))
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

/// Irradiance at the origin (normal +y) from a uniformly emitting
/// parallelogram, by Lambert's closed form for polygons.
fn lambert_irradiance(corner: Vec3, u: Vec3, v: Vec3, radiance: f64) -> f64 {
    let verts = [corner, corner + u, corner + u + v, corner + v].map(|p| p.as_dvec3().normalize());
    let mut sum = 0.0;
    for i in 0..4 {
        let (a, b) = (verts[i], verts[(i + 1) % 4]);
        sum += a.dot(b).clamp(-1.0, 1.0).acos() * a.cross(b).normalize().y;
    }
    0.5 * radiance * sum.abs()
}

#[test]
fn quad_and_mesh_lights_on_a_floor_through_the_integrators_match_lambert() {
    // A floor point lit by a quad light, seen through a narrow camera:
    // once found by comparing with Mitsuba 3, shadow rays leaving a point
    // lifted off the floor hit the light itself and a quarter of the light
    // was lost.
    // And the same parallelogram as an emitting mesh, a fan of four
    // triangles of unequal areas, which the integrators sample as one
    // emitter (a triangle drawn by area): the path tracer's weights at a
    // light hit must know the chance of drawing the triangle, or the
    // direct light comes out 7% short here.
    let (corner, u, v) = (vec3(-0.3, 1.0, -0.4), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.2));
    let fan: Vec<Vec3> = [(0.0, 0.0), (1.0, 0.0), (1.0, 0.3), (1.0, 1.0), (0.4, 1.0), (0.0, 1.0)]
        .iter()
        .map(|&(s, t)| corner + s * u + t * v)
        .collect();
    let quad = vec![Light::quad(corner, u, v, Rgb::ONE)];
    let mesh = Light::triangles_of(&fan, &[[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]], Rgb::ONE);
    assert_eq!(mesh.len(), 4);
    let expected = lambert_irradiance(corner, u, v, 1.0) / std::f64::consts::PI;
    for (light, lights) in [("quad", quad), ("mesh", mesh)] {
        let mut builder = SceneBuilder::new()
            .size(4, 4)
            .with_settings(|s| s.spp = 4096)
            .camera(Camera::look_at(vec3(0.0, 0.5, 0.0), Vec3::ZERO, Vec3::Z, 0.5))
            .material("white", Material::diffuse(Rgb::ONE))
            .object(Shape::plane(Vec3::ZERO, Vec3::Y), "white");
        for l in lights {
            builder = builder.light(l);
        }
        let scene = builder.build().unwrap();
        for (name, integrator) in [
            ("direct", &Direct as &dyn Integrator),
            ("path", &airlight::integrator::PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() })),
            ("raymarch", &airlight::integrator::Raymarch::new(RaymarchOptions { steps: 4, jitter: true })),
        ] {
            let got = render(&scene, integrator, &RenderObserver::none()).mean().x as f64;
            assert!((got / expected - 1.0).abs() < 0.01, "{name}, {light} light: {got} vs {expected}");
        }
    }
}

#[test]
fn an_adaptive_render_of_a_lit_floor_matches_lambert() {
    // The floor point of the test above, rendered with adaptive sampling
    // (render::adaptive): its pixels keep the closed form.
    let (corner, u, v) = (vec3(-0.3, 1.0, -0.4), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.2));
    let expected = lambert_irradiance(corner, u, v, 1.0) / std::f64::consts::PI;
    let scene = SceneBuilder::new()
        .size(4, 4)
        .with_settings(|s| {
            s.spp = 4096;
            s.adaptive = true;
        })
        .camera(Camera::look_at(vec3(0.0, 0.5, 0.0), Vec3::ZERO, Vec3::Z, 0.5))
        .material("white", Material::diffuse(Rgb::ONE))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "white")
        .light(Light::quad(corner, u, v, Rgb::ONE))
        .build()
        .unwrap();
    let path = PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() });
    for (name, integrator) in [("direct", &Direct as &dyn Integrator), ("path", &path)] {
        let got = render(&scene, integrator, &RenderObserver::none()).mean().x as f64;
        assert!((got / expected - 1.0).abs() < 0.01, "{name}: {got} vs {expected}");
    }
}

#[test]
fn surfaces_see_an_area_light_at_a_slant_but_not_through_a_blocker() {
    // Floor points lifted off the floor see points of a ceiling quad light
    // (which is geometry too) from every angle up to grazing; a shadow ray
    // that kept the direction from the unlifted point would meet the
    // light's surface before its end at slants beyond about 50°.
    let scene = SceneBuilder::new()
        .material("m", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .light(Light::quad(vec3(-0.5, 2.0, -0.5), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), Rgb::ONE))
        .build()
        .unwrap();
    let y = vec3(0.2, 2.0, 0.1);
    for x in [0.0f32, 1.0, 2.0, 3.0, 5.0, 10.0, 30.0] {
        let p = vec3(x, 0.0, 0.3 * x);
        let (wi, distance) = ((y - p).normalize(), (y - p).length());
        let origin = airlight::geometry::offset_origin(p, Vec3::Y, wi);
        assert!(scene.light_visible(p, origin, wi, distance), "floor point {p} sees the light at {y}");
    }
    // A box between them blocks it.
    let blocked = SceneBuilder::new()
        .material("m", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .object(Shape::cuboid(vec3(1.0, 0.5, 0.0), vec3(2.0, 1.5, 1.0)), "m")
        .light(Light::quad(vec3(-0.5, 2.0, -0.5), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), Rgb::ONE))
        .build()
        .unwrap();
    let p = vec3(3.0, 0.0, 0.5);
    let (wi, distance) = ((y - p).normalize(), (y - p).length());
    let origin = airlight::geometry::offset_origin(p, Vec3::Y, wi);
    assert!(!blocked.light_visible(p, origin, wi, distance));
}

/// The render loop hands blocks of samples to `radiance_batch`, which the
/// direct integrator traces as packets (and the path tracer its camera
/// rays): every pixel's sum must be the one that tracing its samples one by
/// one (`pixel_sum`) gives, bit for bit.
fn batched_render_matches_samples_one_by_one(scene: &Scene, integrator: &dyn Integrator) {
    let s = scene.settings();
    let acc =
        airlight::render::accumulate(scene, integrator, 0..s.spp as u64, 0..s.film.height, &RenderObserver::none());
    let mut lit = 0;
    for y in 0..s.film.height {
        for x in 0..s.film.width {
            let one_by_one = airlight::render::pixel_sum(scene, integrator, x, y, 0..s.spp as u64);
            assert_eq!(acc.pixel(x, y), Some(&one_by_one), "pixel ({x}, {y})");
            lit += (one_by_one.mean().max_element() > 0.0) as u32;
        }
    }
    assert!(lit > s.film.width * s.film.height / 4, "{lit} lit pixels");
}

#[test]
fn packets_of_samples_give_the_one_by_one_image() {
    // Four lights of three kinds (quad, sphere, spot) and partial blocks
    // (37×23 is no multiple of 8).
    batched_render_matches_samples_one_by_one(&busy_scene(), &Direct);
    // Meshes, boxes and quads that share edges and faces; area lights; the
    // lamp room's fog for the path tracer.
    let path_tracer = PathTracer::new(PathOptions { max_depth: 3, stratify: true, reuse: false });
    for name in ["gltf_lamp_room_fog.toml", "compare_cornell.toml"] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
        let mut scene = airlight::SceneFile::load(&path).expect("scene loads").scene;
        scene.settings_mut().film.width = 61;
        scene.settings_mut().film.height = 45;
        scene.settings_mut().spp = 2;
        batched_render_matches_samples_one_by_one(&scene, &Direct);
        batched_render_matches_samples_one_by_one(&scene, &path_tracer);
    }
}
