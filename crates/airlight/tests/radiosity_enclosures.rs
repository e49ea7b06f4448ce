//! Radiosity inside closed shapes (a sphere, a room made of one box, a
//! closed mesh), against a closed form and against the path tracer.

use airlight::film;
use airlight::integrator::{PathOptions, PathTracer, RadiosityIntegrator, RadiosityOptions, RaymarchOptions};
use airlight::prelude::*;
use airlight::radiosity::Radiosity;
use airlight::render::render;
use glam::{Affine3A, Quat};
use std::f32::consts::PI;

/// pbrt-v4's integrator test (integrators_test.cpp): a point light of
/// intensity π at the centre of a unit sphere of albedo ½, seen from the
/// centre. Direct irradiance π everywhere gives radiance ρ·π/π = ½; every
/// point sees the whole sphere, so each bounce multiplies by ρ:
/// L = ½ Σ_{k=0}^{n} ½^k = 1 − ½^{n+1} after n bounces, 1 in the limit.
fn pbrt_sphere(transform: Option<Affine3A>) -> Scene {
    let sphere = Shape::sphere(Vec3::ZERO, 1.0);
    let builder = SceneBuilder::new()
        .size(16, 16)
        .camera(Camera::look_at(Vec3::ZERO, vec3(0.3, 0.2, 1.0), Vec3::Y, 90.0))
        .material("m", Material::diffuse(Rgb::splat(0.5)))
        .light(Light::point(Vec3::ZERO, Rgb::splat(PI)))
        .with_settings(|s| s.spp = 1);
    let builder = match transform {
        Some(m) => builder.object_transformed(sphere, m, "m"),
        None => builder.object(sphere, "m"),
    };
    builder.build().unwrap()
}

/// Radiosity with `bounces` and, if given, patches of `patch_size`.
fn options(bounces: u32, patch_size: Option<f32>) -> RadiosityOptions {
    RadiosityOptions { bounces, patch_size, ..RadiosityOptions::default() }
}

fn radiosity(scene: &Scene, bounces: u32, patch_size: Option<f32>) -> RadiosityIntegrator {
    RadiosityIntegrator::new(scene, options(bounces, patch_size), RaymarchOptions::default()).unwrap()
}

#[test]
fn pbrt_sphere_reads_one_with_enough_bounces() {
    let exact = |n: u32| 1.0 - 0.5f32.powi(n as i32 + 1);
    for bounces in [1, 8] {
        let scene = pbrt_sphere(None);
        let radiosity = radiosity(&scene, bounces, None);
        let stats = radiosity.solution.stats();
        let image = render(&scene, &radiosity, &RenderObserver::none());
        let (lo, hi) = image.pixels.iter().fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.x), b.max(p.x)));
        println!(
            "pbrt sphere, {bounces} bounces: {} patches, {} links; radiance {lo:.4}..{hi:.4}, mean {:.4}, exact {:.4}",
            stats.patches,
            stats.links,
            image.mean().x,
            exact(bounces)
        );
        for p in &image.pixels {
            assert!((p.x - exact(bounces)).abs() < 0.01, "{bounces} bounces: {} vs {}", p.x, exact(bounces));
        }
        if bounces == 8 {
            // pbrt's own tolerance.
            assert!(image.pixels.iter().all(|p| (p.x - 1.0).abs() < 0.025));
        }
    }
}

#[test]
fn inside_a_sphere_every_patch_gathers_the_whole_sphere() {
    // The form factors from each inner patch sum to the fraction of the
    // sphere it sees: all of it but itself, 1 − A_i/(4π). What they miss
    // or add is the patches' discretisation error.
    let scene = pbrt_sphere(None);
    let r = Radiosity::compile(&scene, &options(1, None)).unwrap();
    let (mut worst, mut sum_err, mut count) = (0.0f64, 0.0f64, 0);
    for (i, p) in r.patches().iter().enumerate() {
        if p.normal.dot(p.center) >= 0.0 {
            continue;
        }
        let total: f64 = r.links().of(i).map(|l| l.factor as f64).sum();
        let exact = 1.0 - p.area as f64 / (4.0 * std::f64::consts::PI);
        let err = total / exact - 1.0;
        worst = worst.max(err.abs());
        sum_err += err;
        count += 1;
    }
    println!("Σ F over {count} inner patches: mean error {:.2e}, worst {worst:.2e}", sum_err / count as f64);
    assert!(count > 1000);
    assert!((sum_err / count as f64).abs() < 0.005 && worst < 0.03);
}

#[test]
fn closed_shapes_conserve_the_light_inside_them() {
    // A closed surface of one albedo ρ around a point light of intensity I
    // catches all of its power Φ = 4πI, and each bounce passes on a
    // fraction ρ of what it caught, all of it caught again: the patches'
    // Σ A·E_direct = Φ and, after n bounces, Σ A·E_indirect = Φ (ρ + … +
    // ρⁿ), whatever the shape. An ellipsoid (a turned, stretched sphere), a
    // turned box and a closed mesh, the light off centre.
    let turn = Quat::from_rotation_y(0.4) * Quat::from_rotation_x(0.2);
    let shapes = [
        (
            "ellipsoid",
            Shape::sphere(Vec3::ZERO, 1.0).transformed(Affine3A::from_scale_rotation_translation(
                vec3(1.5, 1.0, 1.2),
                turn,
                Vec3::ZERO,
            )),
        ),
        ("turned box", Shape::cuboid(Vec3::splat(-1.0), Vec3::ONE).transformed(Affine3A::from_quat(turn))),
        ("mesh box", mesh_box(Vec3::splat(-1.0), Vec3::ONE)),
    ];
    let (albedo, intensity, bounces) = (0.5f32, 3.0f32, 4);
    for (name, shape) in shapes {
        let scene = SceneBuilder::new()
            .material("m", Material::diffuse(Rgb::splat(albedo)))
            .object(shape, "m")
            .light(Light::point(vec3(0.2, -0.1, 0.15), Rgb::splat(intensity)))
            .build()
            .unwrap();
        let r = Radiosity::compile(&scene, &options(bounces, Some(0.15))).unwrap();
        let power = 4.0 * std::f64::consts::PI * intensity as f64;
        let caught = |e: &[Rgb]| -> f64 { r.patches().iter().zip(e).map(|(p, e)| p.area as f64 * e.x as f64).sum() };
        let direct = caught(r.direct_irradiance()) / power;
        let indirect = caught(r.indirect_irradiance()) / power;
        let exact: f64 = (1..=bounces).map(|k| (albedo as f64).powi(k as i32)).sum();
        println!(
            "{name}: {} patches; Σ A E_direct / Φ = {direct:.4} (1), Σ A E_indirect / Φ = {indirect:.4} ({exact:.4})",
            r.patches().len()
        );
        assert!((direct - 1.0).abs() < 0.01, "{name}: direct {direct}");
        assert!((indirect / exact - 1.0).abs() < 0.01, "{name}: indirect {indirect} vs {exact}");
    }
}

/// What the room is made of.
#[derive(Clone, Copy, Debug)]
enum Room {
    Box,
    /// A closed mesh of twelve triangles.
    Mesh,
    /// A box turned about the vertical through its centre (an instance).
    Turned,
}

/// A room (white walls, seen from inside) 4 × 3 × 4, a ball on its floor
/// and a point light, rendered with `spp` samples per pixel.
fn box_room(kind: Room, spp: u32, seed: u64) -> Scene {
    let (min, max) = (Vec3::ZERO, vec3(4.0, 3.0, 4.0));
    let room = match kind {
        Room::Box => Shape::cuboid(min, max),
        Room::Mesh => mesh_box(min, max),
        Room::Turned => Shape::cuboid(min - 0.5 * max, 0.5 * max)
            .transformed(Affine3A::from_rotation_translation(Quat::from_rotation_y(0.3), 0.5 * max)),
    };
    SceneBuilder::new()
        .size(24, 24)
        .camera(Camera::look_at(vec3(2.0, 1.6, 0.3), vec3(2.0, 1.2, 4.0), Vec3::Y, 75.0))
        .material("wall", Material::diffuse(Rgb::splat(0.6)))
        .material("ball", Material::diffuse(Rgb::new(0.7, 0.3, 0.2)))
        .object(room, "wall")
        .object(Shape::sphere(vec3(2.6, 0.7, 2.6), 0.7), "ball")
        .light(Light::point(vec3(1.5, 2.4, 1.8), Rgb::splat(8.0)))
        .with_settings(|s| {
            s.spp = spp;
            s.seed = seed;
        })
        .build()
        .unwrap()
}

/// The box [min, max] as twelve triangles wound outward.
fn mesh_box(min: Vec3, max: Vec3) -> Shape {
    let positions: Vec<Vec3> = (0..8)
        .map(|i| {
            vec3(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        })
        .collect();
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let triangles = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
    Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }
}

/// Compares the room rendered with radiosity (n bounces, 4 spp) and with
/// the path tracer (max_depth n + 1, two renders of `spp` with different
/// seeds, averaged): returns the relative difference of the image means and
/// the radiosity image's relative RMSE with the path tracer's noise taken
/// out (the noise of one render is |p₁ − p₂|/√2, of their mean half that
/// in square: e² = rel_rmse² − noise²), its per-pixel bias.
fn room_against_path(name: &str, kind: Room, bounces: u32, spp: u32) -> (f64, f64) {
    let scene = box_room(kind, 4, 0);
    let radiosity = radiosity(&scene, bounces, Some(0.2));
    let stats = radiosity.solution.stats();
    let rad = render(&scene, &radiosity, &RenderObserver::none());
    let path = |seed: u64| {
        let scene = box_room(kind, spp, seed);
        render(
            &scene,
            &PathTracer::new(PathOptions { max_depth: bounces + 1, ..PathOptions::default() }),
            &RenderObserver::none(),
        )
    };
    let (p1, p2) = (path(1), path(2));
    let mut reference = p1.clone();
    for (r, q) in reference.pixels.iter_mut().zip(&p2.pixels) {
        *r = 0.5 * (*r + *q);
    }
    let noise_one = film::compare(&p1, &p2).unwrap().rel_rmse / 2f64.sqrt();
    let noise = noise_one / 2f64.sqrt();
    let total = film::compare(&rad, &reference).unwrap().rel_rmse;
    let bias = (total * total - noise * noise).max(0.0).sqrt();
    let mean = |i: &film::Image| i.mean().element_sum() as f64 / 3.0;
    let (a, b) = (mean(&rad), mean(&reference));
    println!(
        "{name}: {} patches ({} dropped), {} links; image mean radiosity {a:.4}, path {b:.4} ({:+.2}%); \
         rel_rmse {total:.4}, path noise {noise:.4}, radiosity bias {bias:.4}",
        stats.patches,
        stats.dropped,
        stats.links,
        100.0 * (a / b - 1.0),
    );
    (a / b - 1.0, bias)
}

#[test]
fn a_room_made_of_one_box_matches_the_path_tracer() {
    for kind in [Room::Box, Room::Mesh, Room::Turned] {
        let name = format!("{kind:?} room");
        let (mean, bias) = room_against_path(&name, kind, 8, 256);
        assert!(mean.abs() < 0.02 && bias < 0.05, "{name}: mean {mean:+.4}, bias {bias:.4}");
    }
}
