//! Adaptive sampling (`render::adaptive`): unbiased against uniform renders
//! of many more samples (and against Lambert's closed form in
//! tests/direct.rs), lower error than a uniform render of the same budget
//! where the noise lies in a few pixels, the budget kept, a pixel's count
//! independent of its own samples, and the image independent of the
//! thread count.

use airlight::integrator::{Direct, PathOptions, PathTracer};
use airlight::prelude::*;
use airlight::render::adaptive::{pilot, pilot_samples, plan};
use airlight::render::render;
use std::sync::atomic::{AtomicU64, Ordering};

/// A quad light seen straight on against a black background, its edges
/// across pixels: the noise of a uniform render lies in the pixels its
/// edges cross, whose values are the fractions of them it covers.
fn light_in_view(spp: u32, adaptive: bool) -> Scene {
    SceneBuilder::new()
        .size(24, 16)
        .with_settings(|s| {
            s.spp = spp;
            s.adaptive = adaptive;
        })
        .camera(Camera::look_at(vec3(0.0, 0.0, -3.0), Vec3::ZERO, Vec3::Y, 40.0))
        // Faces the camera: edge_u × edge_v points to −z.
        .light(Light::quad(vec3(-0.71, 0.33, 0.0), vec3(1.13, 0.0, 0.0), vec3(0.0, -0.61, 0.0), Rgb::splat(4.0)))
        .build()
        .unwrap()
}

/// The mean squared difference of two images, over pixels and channels.
fn squared_error(a: &Image, b: &Image) -> f64 {
    let sum: f64 = a.pixels.iter().zip(&b.pixels).map(|(p, q)| (*p - *q).as_dvec3().length_squared()).sum();
    sum / (3 * a.pixels.len()) as f64
}

#[test]
fn the_same_budget_spread_by_noise_lowers_the_error_without_bias() {
    let reference = render(&light_in_view(4096, false), &Direct, &RenderObserver::none());
    let with_seed = |adaptive: bool, seed: u64| {
        let mut scene = light_in_view(64, adaptive);
        scene.settings_mut().seed = seed;
        render(&scene, &Direct, &RenderObserver::none())
    };
    let seeds = 8;
    let (mut e_uniform, mut e_adaptive, mut means) = (0.0, 0.0, Vec::new());
    for seed in 0..seeds {
        let (uniform, adaptive) = (with_seed(false, seed), with_seed(true, seed));
        e_uniform += squared_error(&uniform, &reference) / seeds as f64;
        e_adaptive += squared_error(&adaptive, &reference) / seeds as f64;
        means.push(adaptive.mean().x as f64);
    }
    // The edge pixels take the samples that the flat ones (inside or
    // outside the light, where every sample is the same) do not need:
    // measured 0.56× the squared error (their counts are not powers of
    // two, so their Sobol' points are not whole nets, which gives back
    // part of the gain).
    assert!(e_adaptive < 0.7 * e_uniform, "adaptive {e_adaptive} against uniform {e_uniform}");
    // Each pixel's estimate stays unbiased: the image means of renders
    // with different seeds scatter about the reference's, within four
    // standard errors of their own scatter (and the reference's error,
    // 64 times fewer samples' worth, below a tenth of that).
    let mean = means.iter().sum::<f64>() / seeds as f64;
    let spread = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64).sqrt();
    let want = reference.mean().x as f64;
    let bound = 4.0 * spread / (seeds as f64).sqrt();
    assert!((mean - want).abs() < bound, "image mean {mean} against {want} (bound {bound})");
    assert!(spread > 0.0 && want > 0.1, "noise {spread}; the light fills part of the view: {want}");
}

#[test]
fn the_pilot_gives_the_edges_more_samples_and_the_budget_is_kept() {
    let scene = light_in_view(64, true);
    let pilot_sums = pilot(&scene, &Direct, &RenderObserver::none());
    let pixels = 24 * 16;
    let more = 64 - pilot_samples(64);
    let counts = plan(&pilot_sums, more, scene.settings().seed);
    let planned: u32 = counts.iter().sum();
    // On average the budget; the random rounding of 384 shares is within
    // a few samples of it.
    assert!(planned.abs_diff(pixels * more) < 40, "{planned} against {}", pixels * more);
    // Flat pixels (every pilot sample the same, around them too) keep the
    // floor, a quarter of the second stage's mean; the edges take the rest.
    let (least, most) = (*counts.iter().min().unwrap(), *counts.iter().max().unwrap());
    assert_eq!(least, more / 4);
    assert!(most > 4 * 64, "the most samples a pixel took: {most}");
    // The whole render traces the pilot's samples and the planned ones.
    let traced = AtomicU64::new(0);
    let count = |n: u64| {
        traced.fetch_add(n, Ordering::Relaxed);
    };
    render(&scene, &Direct, &RenderObserver { progress: Some(&count), cancel: None });
    assert_eq!(traced.load(Ordering::Relaxed), (pixels * pilot_samples(64) + planned) as u64);
}

#[test]
fn a_pixels_count_follows_its_neighbours_noise_not_its_own() {
    // The pilot's samples are in the image, so a pixel's count must not
    // depend on them: the image would be biased toward whatever asked for
    // more samples.
    let scene = light_in_view(64, true);
    let quiet = pilot(&scene, &Direct, &RenderObserver::none());
    let (x, y) = (2, 2); // in the black background, its neighbours too
    let mut loud = quiet.clone();
    let pixel = loud.pixel_mut(x, y).unwrap();
    for k in 0..4 {
        pixel.add(Rgb::splat(if k % 2 == 0 { 0.0 } else { 50.0 }));
    }
    let (more, seed, at) = (64 - pilot_samples(64), scene.settings().seed, |x: u32, y: u32| (y * 24 + x) as usize);
    let (before, after) = (plan(&quiet, more, seed), plan(&loud, more, seed));
    assert_eq!(before[at(x, y)], more / 4, "a flat pixel takes the floor");
    // Its own count moves only through the image-wide scaling of shares
    // (the image's noise rose): by at most the one sample of rounding.
    assert!(after[at(x, y)].abs_diff(before[at(x, y)]) <= 1, "{} → {}", before[at(x, y)], after[at(x, y)]);
    // Its eight neighbours' counts rise.
    for (nx, ny) in [(1, 1), (2, 1), (3, 1), (1, 2), (3, 2), (1, 3), (2, 3), (3, 3)] {
        assert!(
            after[at(nx, ny)] > 2 * before[at(nx, ny)],
            "({nx}, {ny}): {} → {}",
            before[at(nx, ny)],
            after[at(nx, ny)]
        );
    }
}

#[test]
fn an_adaptive_image_does_not_depend_on_the_thread_count() {
    let scene = light_in_view(32, true);
    let path = PathTracer::new(PathOptions::default());
    let render_on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render(&scene, &path, &RenderObserver::none()))
    };
    let one = render_on(1);
    assert!(one == render_on(2), "1 and 2 threads differ");
    assert!(one == render_on(3), "1 and 3 threads differ");
}
