//! Progressive rendering's error estimate against the error it estimates:
//! the relative RMSE of the image against an independent, much longer
//! render of the same scene (another seed).

use airlight::film::compare;
use airlight::prelude::*;
use airlight::render::Progressive;

/// A floor and a sphere in fog under a quad light: no point light, whose
/// 1/r² in the fog around it gives the path tracer heavy-tailed samples,
/// for which s² is typically low (with 16 samples a point light beside the
/// sphere gave an estimate of 0.34 against a true error of 0.41).
fn scene(spp: u32, seed: u64) -> Scene {
    SceneBuilder::new()
        .size(32, 24)
        .camera(Camera::look_at(vec3(0.0, 1.5, -5.0), vec3(0.0, 0.8, 0.0), Vec3::Y, 45.0))
        .with_settings(|s| {
            (s.spp, s.seed, s.max_distance) = (spp, seed, 12.0);
        })
        .material("m", Material::diffuse(Rgb::splat(0.6)))
        .medium(Medium::homogeneous(Rgb::splat(0.02), Rgb::splat(0.08), 0.0))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .object(Shape::sphere(vec3(0.3, 0.7, 0.5), 0.7), "m")
        .light(Light::quad(vec3(-1.0, 3.0, -0.5), vec3(2.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), Rgb::splat(4.0)))
        .build()
        .unwrap()
}

/// The integrator `kind`; the path tracer at two scattering events, with
/// independent samples (the error estimate's assumption).
fn integrator(kind: IntegratorKind, scene: &Scene) -> Box<dyn airlight::integrator::Integrator> {
    let mut desc = IntegratorDesc::new(kind);
    desc.path.max_depth = 2;
    desc.path.stratify = false;
    desc.build(scene).unwrap()
}

fn render(kind: IntegratorKind, spp: u32, seed: u64) -> Image {
    let scene = scene(spp, seed);
    airlight::render(&scene, integrator(kind, &scene).as_ref(), &RenderObserver::none())
}

/// The progressive render of `scene` and its estimated relative error.
fn progressive(kind: IntegratorKind, scene: &Scene) -> Progressive {
    let integrator = integrator(kind, scene);
    let mut progressive = Progressive::new(scene);
    while !progressive.finished() {
        assert!(progressive.pass(scene, integrator.as_ref(), &RenderObserver::none()));
    }
    progressive
}

#[test]
fn estimated_error_matches_the_true_error_of_independent_samples() {
    // The path tracer's samples are independent, so s²/n is an unbiased
    // estimate of each pixel's variance, and the estimate must be close
    // to the error against a reference of 64× the samples (whose own error,
    // 1/8 of the image's, adds under 1% in quadrature).
    for spp in [16, 64] {
        let image = progressive(IntegratorKind::Path, &scene(spp, 1));
        let reference = render(IntegratorKind::Path, 64 * spp, 99);
        let actual = compare(&image.image(), &reference).unwrap().rel_rmse;
        let estimated = image.estimated_relative_error();
        eprintln!("{spp} spp: estimated {estimated:.4}, actual {actual:.4}");
        assert!((0.85..1.18).contains(&(actual / estimated)), "{spp} spp: estimated {estimated}, actual {actual}");
    }
}

#[test]
fn estimated_error_bounds_the_error_of_stratified_samples() {
    // Stratified samples are not independent: s²/n overestimates the
    // variance of their mean, never underestimates it (in expectation).
    let image = progressive(IntegratorKind::Stochastic, &scene(64, 1));
    let reference = render(IntegratorKind::Stochastic, 4096, 99);
    let actual = compare(&image.image(), &reference).unwrap().rel_rmse;
    let estimated = image.estimated_relative_error();
    eprintln!("stratified, 64 spp: estimated {estimated:.4}, actual {actual:.4}");
    assert!(actual < estimated, "estimated {estimated}, actual {actual}");
}

#[test]
fn variance_image_is_the_per_pixel_share_of_the_estimate() {
    // Σ variance over pixels and channels / Σ mean² = estimate²; before
    // two samples the variance is unknown (infinite), not zero.
    let scene = scene(8, 3);
    let integrator = integrator(IntegratorKind::Path, &scene);
    let mut p = Progressive::new(&scene);
    assert!(p.pass(&scene, integrator.as_ref(), &RenderObserver::none()));
    assert!(p.variance().pixels.iter().all(|v| v.x == f32::INFINITY));
    assert_eq!(p.estimated_relative_error(), f64::INFINITY);
    while !p.finished() {
        assert!(p.pass(&scene, integrator.as_ref(), &RenderObserver::none()));
    }
    let variance: f64 = p.variance().pixels.iter().map(|v| v.as_dvec3().element_sum()).sum();
    let signal: f64 = p.image().pixels.iter().map(|m| m.as_dvec3().length_squared()).sum();
    let e = p.estimated_relative_error();
    assert!(((variance / signal).sqrt() / e - 1.0).abs() < 1e-5, "{} vs {e}", (variance / signal).sqrt());
    assert!(p.variance().pixels.iter().all(|v| v.min_element() >= 0.0));
}
