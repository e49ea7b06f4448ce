//! The path tracer in exponential height fog, where free flights and
//! transmittance come from the inverted closed-form optical depth: flight
//! distances against the closed-form CDF, and single scattering against the
//! ray marcher.

mod fog_scenes;

use airlight::film::compare;
use airlight::geometry::Ray;
use airlight::integrator::path::tracking::free_flight;
use airlight::integrator::{PathOptions, PathTracer, Raymarch, RaymarchOptions};
use airlight::prelude::*;
use airlight::render::render as render_with;
use airlight::sampling::Sampler;

/// The chance that a flight from o along d collides within t, per unit σt:
/// F(t) = 1 − exp(−σt X(t)) with X(t) = ∫0^t e^{−k(y(s) − base)} ds
/// = ρ0 (1 − e^{−a t})/a, a = k d.y, written out here in f64 (the test's
/// own formula, not the library's).
fn collision_cdf(sigma_t: f64, base: f64, k: f64, o: Vec3, d: Vec3, t: f64) -> f64 {
    let rho0 = (-k * (o.y as f64 - base)).exp();
    let a = k * d.y as f64;
    let x = if a == 0.0 { rho0 * t } else { rho0 * (1.0 - (-a * t).exp()) / a };
    1.0 - (-sigma_t * x).exp()
}

#[test]
fn height_fog_free_flights_follow_the_closed_form_distribution() {
    // First-collision distances by inversion, in each channel as hero, for
    // rays up (a quarter never collide), down into the dense part, level,
    // slanted, and from 2.5 units below the base; a Kolmogorov–Smirnov
    // test against F, whose missing mass 1 − F(t_max) is the fraction that
    // passes the whole segment.
    let (base, k) = (-1.0, 0.8);
    let m = Medium::height(Rgb::new(0.05, 0.02, 0.3), Rgb::new(0.3, 0.5, 0.1), 0.0, base as f32, k as f32);
    let cases = [
        (vec3(0.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)),
        (vec3(0.0, 0.5, 0.0), vec3(0.2, -1.0, 0.3)),
        (vec3(0.0, 0.5, 0.0), vec3(1.0, 0.0, 0.0)),
        (vec3(1.0, 2.0, -1.0), vec3(0.6, -0.3, 0.5)),
        (vec3(0.0, -3.5, 0.0), vec3(0.3, 0.4, -0.2)),
        (vec3(0.0, -3.5, 0.0), vec3(0.0, -1.0, 0.1)),
    ];
    let t_max = 30.0f32;
    let n = 20_000;
    for (i, (o, d)) in cases.into_iter().enumerate() {
        let ray = Ray::new(o, d.normalize());
        for hero in 0..3 {
            let sigma_t = m.sigma_t()[hero] as f64;
            let mut s = Sampler::for_pixel(11, (3 * i + hero) as u64, 0);
            let mut flights: Vec<f64> = (0..n)
                .filter_map(|_| {
                    let mut first = None;
                    free_flight(&m, &ray, t_max, hero, true, &mut s, |c, _| {
                        first = Some(c.t as f64);
                        false
                    });
                    first
                })
                .collect();
            flights.sort_by(f64::total_cmp);
            let cdf = |t: f64| collision_cdf(sigma_t, base, k, ray.origin, ray.dir, t);
            // D = sup |F_n − F| over the sample, counting passes as +∞.
            let mut d_max = 1.0 - flights.len() as f64 / n as f64 - (1.0 - cdf(t_max as f64));
            d_max = d_max.abs();
            for (j, &t) in flights.iter().enumerate() {
                assert!((0.0..=t_max as f64).contains(&t), "case {i}: collision at {t}");
                let f = cdf(t);
                d_max = d_max.max((f - j as f64 / n as f64).abs()).max(((j + 1) as f64 / n as f64 - f).abs());
            }
            // The 99.9% point of the KS statistic is 1.95/√n.
            let critical = 1.95 / (n as f64).sqrt();
            assert!(d_max < critical, "case {i} channel {hero}: D {d_max:.4} (critical {critical:.4})");
        }
    }
}

/// A light in open height fog (base −1, falloff 0.8, as the height-fog
/// benchmark) seen from `camera`, 24×24 pixels through their centres.
fn open_fog(medium: Medium, light: Light, camera: Camera, spp: u32) -> Scene {
    fog_scenes::fog_scene((24, 3, 20.0), medium, light, camera, spp)
}

#[test]
fn single_scattering_in_height_fog_agrees_with_marching_within_noise() {
    let fog = Medium::height(Rgb::splat(0.05), Rgb::splat(0.3), 0.0, -1.0, 0.8);
    let coloured = Medium::height(Rgb::new(0.05, 0.02, 0.1), Rgb::new(0.3, 0.5, 0.15), 0.4, -1.0, 0.8);
    let above = Camera::look_at(vec3(0.0, 1.0, -6.0), vec3(0.0, 0.5, 0.0), Vec3::Y, 50.0);
    let below = Camera::look_at(vec3(0.5, -2.5, -5.0), vec3(0.0, 0.0, 0.0), Vec3::Y, 60.0);
    let point = Light::point(vec3(0.0, 0.5, 0.0), Rgb::splat(10.0));
    // Pointing down and sideways into the dense fog, its cone in view.
    let spot = Light::spot(vec3(-1.0, 2.5, 0.0), vec3(0.6, -2.0, 0.5), Rgb::splat(40.0), 25.0, 18.0);
    // The spot's cone crosses few rays over a short stretch: noisier, more
    // samples.
    let cases = [
        ("point, grey fog", fog.clone(), point, above, 4096),
        ("point, coloured fog, g 0.4", coloured.clone(), point, above, 4096),
        ("point, camera below the base", fog.clone(), point, below, 4096),
        ("spot, grey fog", fog, spot, above, 16_384),
        ("spot, coloured fog, camera below the base", coloured, spot, below, 16_384),
    ];
    for (name, medium, light, camera, spp) in cases {
        let marched = render_with(
            &open_fog(medium.clone(), light, camera, 1),
            &Raymarch::new(RaymarchOptions { steps: 2048, jitter: false }),
            &RenderObserver::none(),
        );
        let (path, variance) = fog_scenes::image_and_variance(
            &open_fog(medium, light, camera, spp),
            &PathTracer::new(PathOptions { max_depth: 1, ..PathOptions::default() }),
        );
        let e = compare(&path, &marched).unwrap();
        // The squared differences against the path tracer's own variance of
        // each pixel mean: near 1 when they differ by noise alone (0.8–1.6
        // here; the variance estimate itself is noisy near the light).
        // Leaving the density out of the equiangular MIS weight gives
        // hundreds, with the image 20% dark.
        let ratio = fog_scenes::squared_difference(&path, &marched) / fog_scenes::summed_variance(&variance);
        eprintln!("{name}: relative RMSE {:.4}, squared error over variance {ratio:.2}", e.rel_rmse);
        assert!(ratio < 2.0, "{name}: squared error {ratio:.2} × the variance (relative RMSE {:.4})", e.rel_rmse);
        assert!(e.rel_rmse < 0.02, "{name}: relative RMSE {:.4}", e.rel_rmse);
        // The light is in the picture: the image is far from uniform.
        let lum: Vec<f32> = marched.pixels.iter().map(|p| p.element_sum()).collect();
        let (lo, hi) = lum.iter().fold((f32::MAX, 0.0f32), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(lo < 0.3 * hi, "{name}: no visible glow: {lo} vs {hi}");
    }
}

#[test]
fn extreme_height_fog_gives_finite_images() {
    // Far below the base (ρ = e^{160}, beyond f32), far above it looking
    // down, a level fog (falloff 0), a steep one, and huge coefficients:
    // every pixel finite and non-negative, with multiple scattering. (The
    // overflows themselves are tested on the density profile, medium
    // tests; this is the integrator's smoke test on such input.)
    let camera_at = |y: f32| Camera::look_at(vec3(0.0, y, -6.0), vec3(0.0, y - 2.0, 0.0), Vec3::Y, 60.0);
    let grey = |sa: f32, ss: f32, falloff: f32| Medium::height(Rgb::splat(sa), Rgb::splat(ss), 0.2, -1.0, falloff);
    let cases = [
        (grey(0.05, 0.3, 0.8), camera_at(-201.0)),
        (grey(0.05, 0.3, 0.8), camera_at(400.0)),
        (grey(0.05, 0.3, 0.0), camera_at(1.0)),
        (grey(0.05, 0.3, 20.0), camera_at(0.0)),
        (Medium::height(Rgb::new(0.0, 1e6, 0.1), Rgb::new(1e6, 0.0, 0.0), 0.9, -1.0, 0.8), camera_at(1.0)),
    ];
    for (medium, camera) in cases {
        let mut scene = open_fog(medium.clone(), Light::point(vec3(0.0, 0.5, 0.0), Rgb::splat(10.0)), camera, 16);
        (scene.settings_mut().film.width, scene.settings_mut().film.height) = (8, 8);
        let image = render_with(
            &scene,
            &PathTracer::new(PathOptions { max_depth: 8, ..PathOptions::default() }),
            &RenderObserver::none(),
        );
        for p in &image.pixels {
            assert!(p.is_finite() && p.min_element() >= 0.0, "{medium:?}: pixel {p}");
        }
    }
}
