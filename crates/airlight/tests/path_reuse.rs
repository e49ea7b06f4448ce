//! Path reuse (`integrator/path/reuse.rs`): neighbouring pixels' paths
//! share their second vertices. Each pixel's estimate must stay unbiased:
//! against a closed form (a white furnace) and against the path tracer
//! without reuse, in a room whose materials take every branch (Lambertian,
//! checkered and Phong second vertices, an area light met at the second
//! vertex, occluders between the first vertices and others' second ones).

use airlight::film::Image;
use airlight::integrator::{PathOptions, PathTracer};
use airlight::prelude::*;
use airlight::render::adaptive::render_adaptive;
use airlight::render::render;

fn reusing(max_depth: u32) -> PathTracer {
    PathTracer::new(PathOptions { max_depth, reuse: true, ..PathOptions::default() })
}

/// Inside a sphere light of radiance 1 around a white Lambertian ball, in
/// vacuum, every pixel reads 1.
#[test]
fn a_white_furnace_reads_one_with_paths_shared() {
    let scene = SceneBuilder::new()
        .material("white", Material::diffuse(Rgb::ONE))
        .object(Shape::sphere(vec3(1.2, 0.0, 0.8), 0.8), "white")
        .object(Shape::sphere(vec3(-0.9, 0.4, 1.1), 0.5), "white")
        .size(32, 24)
        .with_settings(|s| s.spp = 32)
        .camera(Camera::look_at(vec3(0.3, -0.5, 0.2), vec3(1.0, 0.0, 0.5), Vec3::Y, 90.0))
        .light(Light::sphere(Vec3::ZERO, 3.0, Rgb::ONE))
        .build()
        .unwrap();
    let image = render(&scene, &reusing(10_000), &RenderObserver::none());
    // Pixels of one group of eight share samples: the standard error of the
    // mean is taken over 4×4 blocks (each block is one batch, and batches
    // share nothing).
    let blocks = block_means(&image, &image_of(&image, Rgb::ZERO));
    let (mean, se) = mean_and_error(&blocks);
    for c in 0..3 {
        assert!((mean[c] - 1.0).abs() < 4.0 * se[c] + 1e-3, "mean {mean}, standard error {se}");
    }
    // Every pixel has the same expected value: none may stray beyond six
    // deviations of the pixels' spread.
    let n = image.pixels.len() as f32;
    let spread = (image.pixels.iter().map(|p| (*p - Rgb::ONE) * (*p - Rgb::ONE)).sum::<Rgb>() / n).map(f32::sqrt);
    for p in &image.pixels {
        assert!(((*p - Rgb::ONE).abs() - 6.0 * spread).max_element() < 1e-3, "pixel {p} (spread {spread})");
    }
}

/// A room of quads: Lambertian, checkered and Phong walls, a ceiling light
/// (one-sided), a box and a ball in it; the camera sees the light.
fn room(spp: u32, seed: u64) -> Scene {
    room_seen_from(Camera::look_at(vec3(2.0, 1.5, 0.2), vec3(2.0, 1.2, 4.0), Vec3::Y, 80.0), spp, seed)
}

fn room_seen_from(camera: Camera, spp: u32, seed: u64) -> Scene {
    let (w, h, d) = (4.0, 3.0, 4.0);
    SceneBuilder::new()
        .size(32, 32)
        .camera(camera)
        .material("white", Material::diffuse(Rgb::splat(0.7)))
        .material("red", Material::diffuse(Rgb::new(0.7, 0.1, 0.1)))
        .material("checker", Material::checker(Rgb::splat(0.8), Rgb::new(0.2, 0.3, 0.6), 0.5))
        .material("glossy", Material::phong(Rgb::splat(0.3), Rgb::splat(0.4), 20.0))
        .object(Shape::quad(Vec3::ZERO, vec3(w, 0.0, 0.0), vec3(0.0, 0.0, d)), "checker")
        .object(Shape::quad(vec3(0.0, h, 0.0), vec3(0.0, 0.0, d), vec3(w, 0.0, 0.0)), "white")
        .object(Shape::quad(vec3(0.0, 0.0, d), vec3(w, 0.0, 0.0), vec3(0.0, h, 0.0)), "glossy")
        .object(Shape::quad(Vec3::ZERO, vec3(0.0, 0.0, d), vec3(0.0, h, 0.0)), "red")
        .object(Shape::quad(vec3(w, 0.0, 0.0), vec3(0.0, h, 0.0), vec3(0.0, 0.0, d)), "white")
        .object(Shape::quad(Vec3::ZERO, vec3(0.0, h, 0.0), vec3(w, 0.0, 0.0)), "white")
        .object(Shape::cuboid(vec3(0.6, 0.0, 2.2), vec3(1.6, 1.4, 3.2)), "white")
        .object(Shape::sphere(vec3(2.9, 0.6, 2.4), 0.6), "glossy")
        .light(Light::quad(vec3(1.5, h - 1e-3, 1.5), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), Rgb::splat(12.0)))
        .with_settings(|s| {
            s.spp = spp;
            s.seed = seed;
        })
        .build()
        .unwrap()
}

#[test]
fn shared_paths_give_the_path_tracers_image_in_a_room() {
    let plain = render(&room(64, 1), &PathTracer::new(PathOptions::default()), &RenderObserver::none());
    for adaptive in [false, true] {
        let scene = room(64, 2);
        let shared = if adaptive {
            render_adaptive(&scene, &reusing(8), &RenderObserver::none())
        } else {
            render(&scene, &reusing(8), &RenderObserver::none())
        };
        // Per 4×4 block, the difference of the two images' means: blocks
        // are independent, so their spread gives the standard error.
        let blocks = block_means(&shared, &plain);
        let (difference, se) = mean_and_error(&blocks);
        let level = plain.mean();
        for c in 0..3 {
            assert!(
                difference[c].abs() < 4.0 * se[c] && difference[c].abs() < 0.02 * level[c],
                "adaptive {adaptive}: shared − plain {difference} (standard error {se}), image mean {level}"
            );
        }
    }
}

#[test]
fn sharing_lowers_the_noise_of_indirect_light() {
    // The light out of view, whose edges' noise sharing leaves as it is.
    // Two seeds each: the spread between renders, with and without reuse.
    let camera = Camera::look_at(vec3(2.0, 1.5, 3.8), vec3(2.0, 0.8, 0.0), Vec3::Y, 60.0);
    let spread = |reuse: bool| {
        let tracer = PathTracer::new(PathOptions { reuse, ..PathOptions::default() });
        let render_seed = |seed| render(&room_seen_from(camera, 16, seed), &tracer, &RenderObserver::none());
        let (a, b) = (render_seed(3), render_seed(4));
        airlight::film::compare(&a, &b).unwrap().rel_rmse
    };
    let (plain, shared) = (spread(false), spread(true));
    println!("relative spread between seeds: plain {plain:.4}, shared {shared:.4}");
    assert!(shared < 0.85 * plain, "relative spread between seeds: plain {plain:.4}, shared {shared:.4}");
}

/// An image of `width`×`height` pixels all `value` (the zero reference).
fn image_of(like: &Image, value: Rgb) -> Image {
    let mut image = like.clone();
    image.pixels.iter_mut().for_each(|p| *p = value);
    image
}

/// The mean of a − b over each 4×4 block of pixels.
fn block_means(a: &Image, b: &Image) -> Vec<Rgb> {
    let (w, h) = (a.width as usize, a.height as usize);
    let mut blocks = Vec::new();
    for by in (0..h).step_by(4) {
        for bx in (0..w).step_by(4) {
            let mut sum = Rgb::ZERO;
            let mut n = 0.0;
            for y in by..(by + 4).min(h) {
                for x in bx..(bx + 4).min(w) {
                    sum += a.pixels[y * w + x] - b.pixels[y * w + x];
                    n += 1.0;
                }
            }
            blocks.push(sum / n);
        }
    }
    blocks
}

/// The mean of `values` and its standard error.
fn mean_and_error(values: &[Rgb]) -> (Rgb, Rgb) {
    let n = values.len() as f32;
    let mean = values.iter().copied().sum::<Rgb>() / n;
    let variance = values.iter().map(|v| (*v - mean) * (*v - mean)).sum::<Rgb>() / (n - 1.0);
    (mean, (variance / n).map(f32::sqrt))
}
