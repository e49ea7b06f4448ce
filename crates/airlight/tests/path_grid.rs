//! Density grids (a `.vol` file's voxels, trilinear): transmittance and
//! free flights by delta and ratio tracking against the majorant grid,
//! checked against answers computed here independently (by hand, by a
//! fine quadrature of the density, by the homogeneous medium's closed form,
//! and by the ray marcher).

mod fog_scenes;

use airlight::film::compare;
use airlight::geometry::Ray;
use airlight::integrator::path::tracking::{delta_tracking_passes, ratio_tracking};
use airlight::integrator::{PathOptions, PathTracer, Raymarch, RaymarchOptions, Stochastic, StochasticOptions};
use airlight::medium::DensityGrid;
use airlight::prelude::*;
use airlight::render::render as render_with;
use airlight::sampling::Sampler;
use glam::Affine3A;

/// A smooth random grid: a sum of random sinusoids at voxel centres, ≥ 0.
fn smooth_grid(n: usize, seed: u64, min: Vec3, max: Vec3, scale: f32) -> DensityGrid {
    let mut s = Sampler::for_pixel(seed, 0, 0);
    let waves: Vec<(Vec3, f32)> =
        (0..5).map(|_| (Vec3::new(s.next(), s.next(), s.next()) * 0.7, s.next() * 6.0)).collect();
    let mut values = Vec::with_capacity(n * n * n);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = Vec3::new(x as f32, y as f32, z as f32);
                let v: f32 = waves.iter().map(|(k, phase)| (k.dot(p) + phase).sin()).sum();
                values.push(scale * (0.2 + 0.3 * v).max(0.0));
            }
        }
    }
    DensityGrid::new([n; 3], values, min, max, Affine3A::IDENTITY).unwrap()
}

/// Composite Simpson over [a, b] with n (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut sum = f(a) + f(b);
    for i in 1..n {
        sum += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

#[test]
fn two_constant_halves_transmit_as_computed_by_hand() {
    // 10 voxels of 0.2 along x, the first 5 of density 1, the rest 3: along
    // x through the whole box, ∫ρ = 1·0.9 + 2·0.2 + 3·0.9 = 4.0 (the
    // interpolation ramps over the 0.2 between the two middle centres).
    let values = (0..10).map(|i| if i < 5 { 1.0 } else { 3.0 }).collect();
    let grid = DensityGrid::new([10, 1, 1], values, Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0), Affine3A::IDENTITY).unwrap();
    let sigma_t = 0.3f32;
    let m = Medium::grid(Rgb::splat(0.1), Rgb::splat(0.2), 0.0, grid);
    let ray = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
    let hand = (-(sigma_t as f64) * 4.0).exp();
    let deterministic = m.transmittance(ray.origin, ray.dir, 0.0, 10.0).x as f64;
    assert!((deterministic - hand).abs() < 1e-6, "{deterministic} vs {hand}");
    // Through the dense half only, along y: e^{−σt·3·1}.
    let up = Ray::new(Vec3::new(1.7, -2.0, 0.5), Vec3::Y);
    let dense = (-(sigma_t as f64) * 3.0).exp();
    assert!((m.transmittance(up.origin, up.dir, 0.0, 5.0).x as f64 - dense).abs() < 1e-6);
    let n = 40_000;
    let mut s = Sampler::for_pixel(1, 0, 0);
    for (ray, t_max, expected) in [(ray, 10.0, hand), (up, 5.0, dense)] {
        let ratio: f64 = (0..n).map(|_| ratio_tracking(&m, &ray, t_max, 0, &mut s) as f64).sum::<f64>() / n as f64;
        let passes = (0..n).filter(|_| delta_tracking_passes(&m, &ray, t_max, 1, &mut s)).count() as f64 / n as f64;
        let sd = (expected * (1.0 - expected) / n as f64).sqrt();
        assert!((passes - expected).abs() < 4.0 * sd, "delta tracking {passes} vs {expected}");
        // Ratio tracking's variance is below delta tracking's.
        assert!((ratio - expected).abs() < 4.0 * sd, "ratio tracking {ratio} vs {expected}");
    }
}

#[test]
fn delta_and_ratio_tracking_match_a_fine_quadrature_through_a_random_grid() {
    let grid = smooth_grid(24, 7, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0), 2.0);
    let density = |p: Vec3| grid.density(p) as f64;
    let m = Medium::grid(Rgb::new(0.2, 0.5, 1.0), Rgb::new(0.8, 0.5, 1.0), 0.0, grid.clone());
    let mut s = Sampler::for_pixel(3, 0, 0);
    let n = 20_000;
    for case in 0..8 {
        let o = Vec3::new(s.next() - 0.5, s.next() - 0.5, -3.0);
        let d = (Vec3::new(s.next() - 0.5, s.next() - 0.5, 0.0) * 1.5 - o).normalize();
        let ray = Ray::new(o, d);
        let t_max = 2.5 + 2.0 * s.next();
        // The optical depth by Simpson on 100 000 intervals: knows nothing
        // of voxels, majorants or tracking.
        let x = simpson(|t| density(o + d * t as f32), 0.0, t_max as f64, 100_000);
        for channel in 0..3 {
            let expected = (-(m.sigma_t()[channel] as f64) * x).exp();
            let ratio: f64 =
                (0..n).map(|_| ratio_tracking(&m, &ray, t_max, channel, &mut s) as f64).sum::<f64>() / n as f64;
            let passes =
                (0..n).filter(|_| delta_tracking_passes(&m, &ray, t_max, channel, &mut s)).count() as f64 / n as f64;
            let sd = (expected * (1.0 - expected) / n as f64).sqrt().max(1e-4);
            assert!(
                (passes - expected).abs() < 4.5 * sd,
                "case {case} channel {channel}: delta {passes} vs {expected}"
            );
            assert!((ratio - expected).abs() < 4.5 * sd, "case {case} channel {channel}: ratio {ratio} vs {expected}");
        }
    }
}

/// A light and a camera in a medium, 16×16 pixels through their centres.
fn fog_scene(medium: Medium, light: Light, camera: Camera, spp: u32) -> Scene {
    fog_scenes::fog_scene((16, 5, 12.0), medium, light, camera, spp)
}

/// The squared difference of two noisy images over the sum of their
/// pixel means' variances: near 1 when they differ by noise alone. Pooled
/// over four pairs of renders, each image with a seed of its own (the
/// expectation of 1 assumes independent noise): one pair's ratio is
/// heavy-tailed, 0.28 to 2.11 over 12 seeds, since a few pixels by the
/// light hold most of the variance. Also the first pair's relative RMSE.
fn error_over_noise(
    mut a: Scene,
    ia: &dyn airlight::integrator::Integrator,
    mut b: Scene,
    ib: &dyn airlight::integrator::Integrator,
) -> (f64, f64) {
    let (mut squared, mut expected, mut first_rel_rmse) = (0.0, 0.0, None);
    for pair in 0..4 {
        a.settings_mut().seed = 2 * pair;
        b.settings_mut().seed = 2 * pair + 1;
        let (image_a, var_a) = fog_scenes::image_and_variance(&a, ia);
        let (image_b, var_b) = fog_scenes::image_and_variance(&b, ib);
        squared += fog_scenes::squared_difference(&image_a, &image_b);
        expected += fog_scenes::summed_variance(&var_a) + fog_scenes::summed_variance(&var_b);
        first_rel_rmse.get_or_insert_with(|| compare(&image_a, &image_b).unwrap().rel_rmse);
    }
    (squared / expected, first_rel_rmse.unwrap_or(0.0))
}

/// The squared difference of an integrator's image of `scene` from a
/// noiseless `reference` over the sum of its pixel means' variances, near 1
/// when they differ by noise alone; pooled over four seeds, as in
/// [`error_over_noise`]. Also the first seed's relative RMSE.
fn error_over_variance(
    mut scene: Scene,
    integrator: &dyn airlight::integrator::Integrator,
    reference: &Image,
) -> (f64, f64) {
    let (mut squared, mut expected, mut first_rel_rmse) = (0.0, 0.0, None);
    for seed in 0..4 {
        scene.settings_mut().seed = seed;
        let (image, variance) = fog_scenes::image_and_variance(&scene, integrator);
        squared += fog_scenes::squared_difference(&image, reference);
        expected += fog_scenes::summed_variance(&variance);
        first_rel_rmse.get_or_insert_with(|| compare(&image, reference).unwrap().rel_rmse);
    }
    (squared / expected, first_rel_rmse.unwrap_or(0.0))
}

#[test]
fn a_constant_grid_renders_like_the_homogeneous_medium_of_its_density() {
    // A 3³ grid of density 0.5 in a box holding all the camera sees (the
    // camera inside it, max_distance 12): the path tracer tracks it against
    // its majorant grid; the homogeneous medium of σ·0.5 has its
    // transmittance and free flights in closed form.
    let (sigma_a, sigma_s) = (Rgb::new(0.04, 0.08, 0.1), Rgb::new(0.3, 0.4, 0.2));
    let grid =
        DensityGrid::new([3; 3], vec![0.5; 27], Vec3::splat(-20.0), Vec3::splat(20.0), Affine3A::IDENTITY).unwrap();
    let camera = Camera::look_at(vec3(0.0, 0.5, -4.0), vec3(0.0, 0.3, 0.0), Vec3::Y, 50.0);
    // A sphere light: a point light's 1/r² in the medium would give the
    // free-flight estimator infinite variance.
    let lamp = Light::sphere(vec3(0.3, 0.4, 0.2), 0.4, Rgb::splat(4.0));
    for depth in [1, 6] {
        let tracer = PathTracer::new(PathOptions { max_depth: depth, ..PathOptions::default() });
        let gridded = fog_scene(Medium::grid(sigma_a, sigma_s, 0.3, grid.clone()), lamp, camera, 1024);
        let homogeneous = fog_scene(Medium::homogeneous(sigma_a * 0.5, sigma_s * 0.5, 0.3), lamp, camera, 1024);
        let (ratio, rel) = error_over_noise(gridded, &tracer, homogeneous, &tracer);
        eprintln!("max_depth {depth}: squared error over variance {ratio:.2}, relative RMSE {rel:.4}");
        assert!(ratio < 1.6, "max_depth {depth}: squared error {ratio:.2} × the variance");
    }
    // The ray marcher, deterministic with midpoints: the grid's integrated
    // transmittance is the closed form's.
    let march = Raymarch::new(RaymarchOptions { steps: 256, jitter: false });
    let a = render_with(
        &fog_scene(Medium::grid(sigma_a, sigma_s, 0.3, grid), lamp, camera, 1),
        &march,
        &RenderObserver::none(),
    );
    let b = render_with(
        &fog_scene(Medium::homogeneous(sigma_a * 0.5, sigma_s * 0.5, 0.3), lamp, camera, 1),
        &march,
        &RenderObserver::none(),
    );
    let e = compare(&a, &b).unwrap();
    assert!(e.rel_rmse < 1e-4, "raymarch: relative RMSE {}", e.rel_rmse);
}

#[test]
fn single_scattering_in_a_random_grid_agrees_between_path_raymarch_and_stochastic() {
    // A cloud in the box [−1, 1]³, the light beside it, the camera outside
    // (rays enter the box part-way: the march starts there).
    let grid = smooth_grid(16, 11, Vec3::splat(-1.0), Vec3::splat(1.0), 3.0);
    let m = Medium::grid(Rgb::splat(0.1), Rgb::new(0.9, 0.7, 0.5), 0.2, grid);
    let camera = Camera::look_at(vec3(0.5, 0.8, -4.0), vec3(0.0, 0.0, 0.0), Vec3::Y, 40.0);
    // Outside the box: no medium near the point light's 1/r².
    let lamp = Light::point(vec3(2.0, 1.5, -0.5), Rgb::splat(8.0));
    let marched = render_with(
        &fog_scene(m.clone(), lamp, camera, 1),
        &Raymarch::new(RaymarchOptions { steps: 1024, jitter: false }),
        &RenderObserver::none(),
    );
    let path = PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() });
    let (ratio, rel) = error_over_variance(fog_scene(m.clone(), lamp, camera, 2048), &path, &marched);
    eprintln!("path vs raymarch: squared error over variance {ratio:.2}, relative RMSE {rel:.4}");
    assert!(ratio < 1.6, "path vs raymarch: {ratio:.2} × the variance");
    // Independent samples: the variance of stratified ones is not s²/n.
    let stochastic = Stochastic::new(StochasticOptions { stratify: false, ..StochasticOptions::default() });
    let (ratio, _) = error_over_variance(fog_scene(m, lamp, camera, 2048), &stochastic, &marched);
    eprintln!("stochastic vs raymarch: squared error over variance {ratio:.2}");
    assert!(ratio < 1.6, "stochastic vs raymarch: {ratio:.2} × the variance");
    // The cloud is in the picture: some pixels see it lit, corners do not.
    let lum: Vec<f32> = marched.pixels.iter().map(|p| p.element_sum()).collect();
    let hi = lum.iter().copied().fold(0.0f32, f32::max);
    assert!(hi > 0.0 && lum[0] < 0.05 * hi, "no cloud: corner {} vs brightest {hi}", lum[0]);
}

#[test]
fn noise_fog_tracks_to_its_quadrature_and_renders_alike_by_path_and_raymarch() {
    use airlight::medium::NoiseFog;
    let fog = NoiseFog {
        scale: Vec3::new(1.5, 0.8, 1.5),
        octaves: 3,
        gain: 0.5,
        offset: 0.2,
        seed: 4,
        bounds: Some((Vec3::new(-2.0, -1.0, -2.0), Vec3::new(2.0, 1.0, 2.0))),
        height: Some((-1.0, 0.7)),
    };
    let m = Medium::noise(Rgb::splat(0.2), Rgb::new(1.2, 0.9, 0.6), 0.0, fog.clone());
    let mut s = Sampler::for_pixel(8, 0, 0);
    let n = 20_000;
    for case in 0..4 {
        let o = Vec3::new(s.next() - 0.5, s.next() - 0.5, -3.0);
        let d = (Vec3::new(s.next() - 0.5, s.next() - 0.5, 2.0) - o).normalize();
        let ray = Ray::new(o, d);
        let x = simpson(|t| fog.density(o + d * t as f32) as f64, 0.0, 6.0, 200_000);
        let expected = (-(m.sigma_t().x as f64) * x).exp();
        let ratio: f64 = (0..n).map(|_| ratio_tracking(&m, &ray, 6.0, 0, &mut s) as f64).sum::<f64>() / n as f64;
        let sd = (expected * (1.0 - expected) / n as f64).sqrt().max(1e-4);
        assert!((ratio - expected).abs() < 4.5 * sd, "case {case}: ratio {ratio} vs {expected}");
    }
    let camera = Camera::look_at(vec3(0.5, 0.5, -5.0), vec3(0.0, 0.0, 0.0), Vec3::Y, 45.0);
    let lamp = Light::point(vec3(2.5, 1.8, -0.5), Rgb::splat(10.0));
    let marched = render_with(
        &fog_scene(m.clone(), lamp, camera, 1),
        &Raymarch::new(RaymarchOptions { steps: 512, jitter: false }),
        &RenderObserver::none(),
    );
    let path = PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() });
    let (ratio, _) = error_over_variance(fog_scene(m, lamp, camera, 2048), &path, &marched);
    eprintln!("noise, path vs raymarch: squared error over variance {ratio:.2}");
    assert!(ratio < 1.6, "noise, path vs raymarch: {ratio:.2} × the variance");
}
