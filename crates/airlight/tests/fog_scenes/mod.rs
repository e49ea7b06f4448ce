//! Helpers shared by the tests that render small scenes in a medium with
//! two integrators and compare them within noise.

use airlight::film::Image;
use airlight::integrator::Integrator;
use airlight::prelude::*;
use airlight::render::accumulate;

/// A `size`² image of one light in `medium`, seen from `camera` with the
/// medium scattering out to `max_distance`; every sample goes through its
/// pixel's centre, so that integrators trace the same camera rays.
pub fn fog_scene(
    (size, seed, max_distance): (u32, u64, f32),
    medium: Medium,
    light: Light,
    camera: Camera,
    spp: u32,
) -> Scene {
    SceneBuilder::new()
        .size(size, size)
        .with_settings(|s| {
            s.spp = spp;
            s.seed = seed;
            s.max_distance = max_distance;
            s.film.filter = airlight::film::PixelFilter::Point;
        })
        .camera(camera)
        .light(light)
        .medium(medium)
        .build()
        .unwrap()
}

/// `integrator`'s image of `scene` at its spp and the variance of each
/// pixel's mean, from the pixels' mean squared samples (s²/n, s² the
/// unbiased variance).
pub fn image_and_variance(scene: &Scene, integrator: &dyn Integrator) -> (Image, Vec<Rgb>) {
    let (spp, height) = (scene.settings().spp, scene.settings().film.height);
    let sums = accumulate(scene, integrator, 0..spp as u64, 0..height, &RenderObserver::none());
    (sums.image(), sums.variance().pixels)
}

/// Σ over pixels and channels of the squared difference of two images.
pub fn squared_difference(a: &Image, b: &Image) -> f64 {
    a.pixels.iter().zip(&b.pixels).map(|(x, y)| (*x - *y).length_squared() as f64).sum()
}

/// Σ over pixels and channels of the variances of pixel means.
pub fn summed_variance(variance: &[Rgb]) -> f64 {
    variance.iter().map(|v| v.element_sum() as f64).sum()
}
