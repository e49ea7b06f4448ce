//! The stochastic integrator against the ray-marching one: both estimate the
//! same single-scatter integral, so with 4096 march steps and many Monte
//! Carlo samples their images must agree. Each pixel is the ray through its
//! centre, so the comparison is of the integrals alone (not of anti-aliasing).

use airlight::film::{Image, compare};
use airlight::geometry::{Ray, Sdf};
use airlight::integrator::RaymarchOptions;
use airlight::integrator::{Integrator, Raymarch, Sampling, Stochastic, StochasticOptions};
use airlight::prelude::*;
use airlight::sampling::Sampler;
use glam::Vec2;

const W: u32 = 32;
const H: u32 = 24;

/// An image whose pixel is the mean of `n` samples of `integrator` along
/// the ray through the pixel's centre.
fn per_ray(scene: &Scene, integrator: &dyn Integrator, n: u32, seed: u64) -> Image {
    let mut image = Image::new(W, H);
    for y in 0..H {
        for x in 0..W {
            let ray: Ray = scene.camera().ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), W, H, Vec2::ZERO);
            let pixel = (y * W + x) as u64;
            let mut sum = glam::DVec3::ZERO;
            for i in 0..n as u64 {
                let mut sampler = Sampler::for_pixel(seed, pixel, i);
                sum += integrator.radiance(scene, &ray, &mut sampler).as_dvec3();
            }
            image.pixels[pixel as usize] = (sum / n as f64).as_vec3();
        }
    }
    image
}

/// SDF shapes (sphere, box, torus, a smooth union) and an analytic sphere
/// on an analytic floor, in fog, under `lights`.
fn shadow_scene(lights: Vec<Light>, albedo: f32) -> Scene {
    let mut b = SceneBuilder::new()
        .size(W, H)
        .camera(Camera::look_at(vec3(0.0, 2.5, -7.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 45.0))
        .with_settings(|s| s.max_distance = 20.0)
        .material("m", Material::diffuse(Rgb::splat(albedo)))
        .medium(Medium::homogeneous(Rgb::splat(0.02), Rgb::new(0.1, 0.12, 0.15), 0.3))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .object(Shape::sdf(Sdf::Sphere { center: vec3(-1.2, 1.0, 0.5), radius: 0.6 }), "m")
        .object(Shape::sdf(Sdf::Box { min: vec3(0.6, 0.0, -0.3), max: vec3(1.4, 1.6, 0.5) }), "m")
        .object(Shape::sdf(Sdf::Torus { center: vec3(0.0, 0.3, -1.0), major_radius: 0.5, minor_radius: 0.15 }), "m")
        .object(
            Shape::sdf(Sdf::SmoothUnion {
                children: vec![
                    Sdf::Capsule { a: vec3(-0.3, 0.0, 1.5), b: vec3(-0.3, 2.0, 1.5), radius: 0.2 },
                    Sdf::Sphere { center: vec3(-0.3, 2.0, 1.5), radius: 0.4 },
                ],
                blend: 0.3,
            }),
            "m",
        )
        .object(Shape::sphere(vec3(1.8, 0.4, -1.2), 0.4), "m");
    for light in lights {
        b = b.light(light);
    }
    b.build().unwrap()
}

/// `samples` per strategy: uniform, equiangular, mis.
fn check_converges(scene: &Scene, reference_samples: u32, samples: [u32; 3]) {
    let reference =
        per_ray(scene, &Raymarch::new(RaymarchOptions { steps: 4096, jitter: false }), reference_samples, 7);
    assert!(reference.mean().min_element() > 0.0);
    for (sampling, samples) in Sampling::ALL.into_iter().zip(samples) {
        let image = per_ray(scene, &Stochastic { sampling, stratify: true }, samples, 1);
        let e = compare(&image, &reference).unwrap();
        eprintln!("{sampling}: relative RMSE {:.4}", e.rel_rmse);
        assert!(e.rel_rmse < 0.01, "{sampling}: relative RMSE {:.4} against raymarch", e.rel_rmse);
    }
}

#[test]
fn stochastic_converges_to_raymarch_with_point_and_spot_lights() {
    let scene = shadow_scene(
        vec![
            Light::point(vec3(0.5, 3.0, 0.0), Rgb::splat(12.0)),
            Light::spot(vec3(-2.0, 4.0, -1.0), vec3(0.0, 0.0, 0.5), Rgb::new(20.0, 15.0, 10.0), 30.0, 20.0),
        ],
        0.6,
    );
    check_converges(&scene, 1, [512, 256, 256]);
}

#[test]
fn stochastic_converges_to_raymarch_with_a_volume_light() {
    // Black surfaces: what is seen is the fog's single scattering alone,
    // with the shapes' volumetric shadows.
    // The light sits just above the view: rays pass near it, not through it.
    let scene =
        shadow_scene(vec![Light::volume_box(vec3(-0.4, 3.9, -0.4), vec3(0.4, 4.7, 0.4), Rgb::splat(15.0))], 0.0);
    // A volume light's samples are noisier than a point's: at 16 reference
    // samples and [4096, 1024, 1024] the errors reached 0.014 on some seeds,
    // about the reference's own noise; at these counts, at most 0.0056 over
    // three reference seeds and three image seeds each.
    check_converges(&scene, 64, [8192, 4096, 4096]);
}

#[test]
fn stratification_and_equiangular_sampling_lower_the_error() {
    // At 16 samples: equiangular beats uniform, and stratified beats
    // independent, on a point light in fog (the glow).
    let scene = shadow_scene(vec![Light::point(vec3(0.5, 2.0, 0.0), Rgb::splat(12.0))], 0.0);
    let reference = per_ray(&scene, &Raymarch::new(RaymarchOptions { steps: 4096, jitter: false }), 1, 7);
    let err = |sampling, stratify| {
        compare(&per_ray(&scene, &Stochastic { sampling, stratify }, 16, 3), &reference).unwrap().rel_rmse
    };
    let uniform = err(Sampling::Uniform, false);
    let equiangular = err(Sampling::Equiangular, false);
    let stratified = err(Sampling::Equiangular, true);
    assert!(equiangular < 0.5 * uniform, "equiangular {equiangular} uniform {uniform}");
    assert!(stratified < 0.8 * equiangular, "stratified {stratified} independent {equiangular}");
}

#[test]
fn rendered_images_are_deterministic_and_match_raymarch_on_smooth_views() {
    // Through the whole render path (stratified film samples included): a
    // view of fog and a plain floor, whose pixels vary smoothly, so the
    // pixel means of both integrators agree at moderate spp.
    let scene = SceneBuilder::new()
        .size(W, H)
        .camera(Camera::look_at(vec3(0.0, 2.0, -6.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 40.0))
        .with_settings(|s| {
            s.max_distance = 15.0;
            s.spp = 256;
        })
        .material("m", Material::diffuse(Rgb::splat(0.5)))
        .medium(Medium::homogeneous(Rgb::splat(0.02), Rgb::splat(0.1), 0.0))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        // Above the view: its glow's peak would make pixel means noisy.
        .light(Light::point(vec3(0.0, 4.0, 1.0), Rgb::splat(10.0)))
        .build()
        .unwrap();
    let stochastic = Stochastic::new(StochasticOptions::default());
    let image = airlight::render(&scene, &stochastic, &RenderObserver::none());
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    assert!(one_thread.install(|| airlight::render(&scene, &stochastic, &RenderObserver::none())) == image);
    let mut marched = scene;
    marched.settings_mut().spp = 64;
    let march = Raymarch::new(RaymarchOptions { steps: 256, jitter: false });
    let reference = airlight::render(&marched, &march, &RenderObserver::none());
    let e = compare(&image, &reference).unwrap();
    assert!(e.rel_rmse < 0.01, "relative RMSE {}", e.rel_rmse);
}

#[test]
fn progressive_passes_add_up_to_the_full_render() {
    let scene = shadow_scene(vec![Light::point(vec3(0.5, 3.0, 0.0), Rgb::splat(12.0))], 0.5);
    let mut scene = scene;
    scene.settings_mut().spp = 13;
    let integrator = IntegratorDesc::new(IntegratorKind::Stochastic).build(&scene).unwrap();
    let mut progressive = airlight::render::Progressive::new(&scene);
    let mut sizes = Vec::new();
    while !progressive.finished() {
        sizes.push(progressive.next_pass_size());
        assert!(progressive.pass(&scene, integrator.as_ref(), &RenderObserver::none()));
    }
    assert_eq!(sizes, [1, 1, 2, 4, 5]);
    let full = airlight::render(&scene, integrator.as_ref(), &RenderObserver::none());
    // The same samples, summed in another grouping: the same bits.
    assert_eq!(progressive.image(), full);
}
