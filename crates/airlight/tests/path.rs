//! The path tracer against closed forms and against the ray marcher.

use airlight::film::compare;
use airlight::geometry::Ray;
use airlight::integrator::PathOptions;
use airlight::integrator::RaymarchOptions;
use airlight::integrator::path::tracking::{delta_tracking_passes, ratio_tracking, track};
use airlight::integrator::{PathTracer, Raymarch};
use airlight::prelude::*;
use airlight::render::render;
use airlight::sampling::Sampler;

/// Inside a sphere that emits radiance 1 inward, filled with a medium that
/// scatters but does not absorb, around a diffuse ball of albedo 1, every
/// path ends on the wall: the radiance is 1 everywhere, on the ball and in
/// the fog, whatever the scattering (a white furnace).
fn furnace(medium: Medium) -> Scene {
    SceneBuilder::new()
        .material("white", Material::diffuse(Rgb::ONE))
        .object(Shape::sphere(vec3(1.2, 0.0, 0.8), 0.8), "white")
        .size(16, 12)
        .with_settings(|s| {
            s.spp = 64;
            s.max_distance = 100.0;
        })
        .camera(Camera::look_at(vec3(0.3, -0.5, 0.2), vec3(1.0, 0.0, 0.5), Vec3::Y, 90.0))
        .light(Light::sphere(Vec3::ZERO, 3.0, Rgb::ONE))
        .medium(medium)
        .build()
        .unwrap()
}

#[test]
fn white_furnace_gives_the_wall_radiance_everywhere() {
    for medium in [
        Medium::homogeneous(Rgb::ZERO, Rgb::new(0.5, 1.0, 2.0), 0.0),
        Medium::homogeneous(Rgb::ZERO, Rgb::splat(1.5), 0.7),
        Medium::height(Rgb::ZERO, Rgb::new(0.8, 0.4, 1.2), -0.3, -1.0, 0.9),
    ] {
        let image = render(
            &furnace(medium.clone()),
            &PathTracer::new(PathOptions { max_depth: 10_000, ..PathOptions::default() }),
            &RenderObserver::none(),
        );
        // The image mean against 1, within four standard errors (measured
        // from the spread of the pixels, which are independent).
        let mean = image.mean();
        let n = image.pixels.len() as f32;
        for c in 0..3 {
            let var = image.pixels.iter().map(|p| (p[c] - mean[c]).powi(2)).sum::<f32>() / (n - 1.0);
            let se = (var / n).sqrt();
            assert!((mean[c] - 1.0).abs() < 4.0 * se + 1e-3, "{medium:?}: mean {mean}, standard error {se}");
            // Everywhere: under the furnace every pixel has the same
            // distribution, so none may stray beyond six pixel deviations.
            let sigma = var.sqrt();
            for p in &image.pixels {
                assert!((p[c] - 1.0).abs() < 6.0 * sigma + 1e-3, "{medium:?}: pixel {p} (σ {sigma})");
            }
        }
    }
}

#[test]
fn free_flights_in_a_homogeneous_medium_are_exponential() {
    // Histogram of the first collision distance against σ e^{−σ t}.
    let m = Medium::homogeneous(Rgb::ZERO, Rgb::splat(0.7), 0.0);
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let mut s = Sampler::for_pixel(6, 0, 0);
    let (n, bins, width) = (200_000, 10, 0.5f64);
    let mut counts = vec![0usize; bins];
    for _ in 0..n {
        let mut first = None;
        track(&m, &ray, 1e6, 0, &mut s, |c, _| {
            first = Some(c.t);
            false
        });
        let t = first.unwrap() as f64;
        if t < bins as f64 * width {
            counts[(t / width) as usize] += 1;
        }
    }
    for (b, &count) in counts.iter().enumerate() {
        let expected = n as f64 * ((-0.7 * b as f64 * width).exp() - (-0.7 * (b + 1) as f64 * width).exp());
        assert!((count as f64 - expected).abs() < 4.0 * expected.sqrt(), "bin {b}: {count} vs {expected:.0}");
    }
}

#[test]
fn delta_and_ratio_tracking_match_closed_form_height_fog_transmittance() {
    let m = Medium::height(Rgb::splat(0.1), Rgb::new(0.3, 0.6, 0.9), 0.0, 0.5, 0.8);
    let mut s = Sampler::for_pixel(7, 0, 0);
    for (o, d, t) in [
        (vec3(0.0, 0.0, 0.0), vec3(1.0, 0.2, 0.0), 5.0f32),
        (vec3(0.0, 3.0, 0.0), vec3(0.3, -1.0, 0.1), 3.5),
        (vec3(-1.0, 1.0, 2.0), vec3(0.0, 1.0, 0.0), 8.0),
    ] {
        let ray = Ray::new(o, d.normalize());
        let exact = m.transmittance(ray.origin, ray.dir, 0.0, t);
        for channel in 0..3 {
            let n = 100_000;
            let passes = (0..n).filter(|_| delta_tracking_passes(&m, &ray, t, channel, &mut s)).count();
            let p = exact[channel] as f64;
            let sigma = (p * (1.0 - p) / n as f64).sqrt();
            let got = passes as f64 / n as f64;
            assert!((got - p).abs() < 4.0 * sigma + 1e-4, "delta tracking: {got} vs {p}");
            let estimates: Vec<f64> = (0..n).map(|_| ratio_tracking(&m, &ray, t, channel, &mut s) as f64).collect();
            let mean = estimates.iter().sum::<f64>() / n as f64;
            let var = estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
            let sigma = (var / n as f64).sqrt();
            assert!((mean - p).abs() < 4.0 * sigma, "ratio tracking: {mean} vs {p} (σ {sigma})");
            assert!(sigma < 0.05 * p, "ratio tracking too noisy to mean much: σ {sigma}");
        }
    }
}

/// A floor in fog under a point and a spot light; a sphere above the frame
/// casts a shadow through the fog and onto the floor. Every sample goes
/// through its pixel's centre, so that the two integrators, at different
/// sample counts, see the same camera rays.
fn fog_scene(medium: Medium, spp: u32, seed: u64) -> Scene {
    SceneBuilder::new()
        .size(16, 12)
        .with_settings(|s| {
            s.spp = spp;
            s.seed = seed;
            s.max_distance = 12.0;
            s.film.filter = airlight::film::PixelFilter::Point;
        })
        .camera(Camera::look_at(vec3(0.0, 3.0, -6.0), vec3(0.0, 0.0, 1.0), Vec3::Y, 40.0))
        .material("floor", Material::diffuse(Rgb::splat(0.5)))
        .material("ball", Material::diffuse(Rgb::new(0.6, 0.3, 0.2)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
        .object(Shape::sphere(vec3(0.3, 3.6, 1.0), 0.6), "ball")
        .light(Light::point(vec3(0.5, 6.0, 1.0), Rgb::splat(60.0)))
        .light(Light::spot(vec3(-3.0, 5.0, -1.0), vec3(0.0, 0.0, 1.0), Rgb::splat(80.0), 30.0, 25.0))
        .medium(medium)
        .build()
        .unwrap()
}

#[test]
fn single_scattering_path_tracing_agrees_with_marching() {
    // Height fog twice: free flights and transmittance from the inverted
    // optical depth, and by delta and ratio tracking (the path for media
    // without a closed form).
    let height = Medium::height(Rgb::splat(0.02), Rgb::splat(0.15), 0.0, 0.0, 0.4);
    let tracking =
        PathTracer { closed_form: false, ..PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() }) };
    for (medium, tracer) in [
        (
            Medium::homogeneous(Rgb::new(0.02, 0.03, 0.04), Rgb::new(0.10, 0.07, 0.05), 0.3),
            PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() }),
        ),
        (height.clone(), PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() })),
        (height, tracking),
    ] {
        let path = render(&fog_scene(medium.clone(), 32_768, 0), &tracer, &RenderObserver::none());
        let marched = render(
            &fog_scene(medium.clone(), 16, 0),
            &Raymarch::new(RaymarchOptions { steps: 4096, jitter: true }),
            &RenderObserver::none(),
        );
        let e = compare(&path, &marched).unwrap();
        assert!(e.rel_rmse < 0.01, "{medium:?}: relative RMSE {}", e.rel_rmse);
        // The shadow is in the picture: the darkest floor pixel is well
        // below the brightest.
        let lum: Vec<f32> = marched.pixels.iter().map(|p| p.element_sum()).collect();
        let (lo, hi) = lum.iter().fold((f32::MAX, 0.0f32), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(lo < 0.6 * hi, "no visible shadow or falloff: {lo} vs {hi}");
    }
}

/// [`fog_scene`] with its point light moved into view.
fn light_in_view(medium: Medium, spp: u32, seed: u64) -> Scene {
    let mut scene = fog_scene(medium, spp, seed);
    let mut lights = scene.lights().to_vec();
    lights[0] = Light::point(vec3(0.5, 1.5, 1.0), Rgb::splat(60.0));
    scene.set_lights(&lights);
    scene
}

#[test]
fn equiangular_light_sampling_lowers_the_error_near_lights() {
    // The same scene with the point light in view (its 1/r² glow on the
    // image), single scattering, 64 spp: free flights alone against free
    // flights plus equiangular points with MIS, each against a 4096-step
    // march. Both estimate the same integral (the test above); the second
    // has finite variance near the light. The first's error over one seed
    // is heavy-tailed (0.17 to 0.61 over 12 seeds, against 0.06 to 0.12
    // with equiangular points), so each is the root mean square over four.
    let medium = Medium::homogeneous(Rgb::new(0.02, 0.03, 0.04), Rgb::new(0.10, 0.07, 0.05), 0.3);
    let in_view = |spp, seed| light_in_view(medium.clone(), spp, seed);
    let marched =
        render(&in_view(16, 5), &Raymarch::new(RaymarchOptions { steps: 4096, jitter: true }), &RenderObserver::none());
    let error = |equiangular| {
        let tracer =
            PathTracer { equiangular, ..PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() }) };
        let squares: f64 = (0..4)
            .map(|seed| compare(&render(&in_view(64, seed), &tracer, &RenderObserver::none()), &marched).unwrap())
            .map(|e| e.rel_rmse * e.rel_rmse)
            .sum();
        (squares / 4.0).sqrt()
    };
    let (free_flight, with_equiangular) = (error(false), error(true));
    eprintln!("64 spp, 4 seeds: free flights {free_flight:.4}, with equiangular {with_equiangular:.4}");
    assert!(with_equiangular < 0.5 * free_flight, "{with_equiangular} vs {free_flight}");
}

#[test]
fn directions_drawn_toward_the_light_change_the_noise_not_the_light() {
    // Multiple scattering (8 events, Russian roulette from the 5th) in
    // denser fog around the point light in view, eight seeds each, with
    // new directions drawn toward the light as well and without: the image means agree within four standard errors of
    // their difference (taken from the seeds' spread), and the seeds'
    // pixel-by-pixel spread, which rare, bright pixels dominate without,
    // is smaller with.
    let medium = Medium::homogeneous(Rgb::new(0.02, 0.03, 0.05), Rgb::new(0.25, 0.2, 0.15), 0.4);
    let seeds = 8;
    let renders = |guide| -> Vec<Image> {
        let tracer = PathTracer { guide, ..PathTracer::new(PathOptions { max_depth: 8, ..PathOptions::default() }) };
        (0..seeds)
            .map(|seed| render(&light_in_view(medium.clone(), 256, seed), &tracer, &RenderObserver::none()))
            .collect()
    };
    let (without, with) = (renders(false), renders(true));
    // Per channel: the mean over seeds of the image means, and its
    // standard error.
    let mean_and_error = |images: &[Image]| {
        let means: Vec<Rgb> = images.iter().map(|i| i.mean()).collect();
        let mean = means.iter().fold(Rgb::ZERO, |a, &m| a + m) / seeds as f32;
        let var = means.iter().fold(Rgb::ZERO, |a, &m| a + (m - mean) * (m - mean)) / (seeds - 1) as f32;
        (mean, (var / seeds as f32).powf(0.5))
    };
    // The seeds' squared spread about their pixel means, summed over pixels.
    let spread = |images: &[Image]| -> f32 {
        let n = images[0].pixels.len();
        (0..n)
            .map(|k| {
                let mean = images.iter().fold(Rgb::ZERO, |a, i| a + i.pixels[k]) / seeds as f32;
                images.iter().map(|i| (i.pixels[k] - mean).length_squared()).sum::<f32>()
            })
            .sum()
    };
    let ((m0, e0), (m1, e1)) = (mean_and_error(&without), mean_and_error(&with));
    let (s0, s1) = (spread(&without), spread(&with));
    eprintln!("means {m0} ± {e0} without, {m1} ± {e1} with; spread {s0} without, {s1} with");
    for c in 0..3 {
        let bound = 4.0 * (e0[c] * e0[c] + e1[c] * e1[c]).sqrt();
        assert!((m0[c] - m1[c]).abs() < bound, "channel {c}: {} against {} (4σ {bound})", m0[c], m1[c]);
    }
    assert!(s1 < 0.7 * s0, "spread {s1} with, {s0} without");
}
