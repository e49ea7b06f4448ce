//! The ray-marching integrator against independent single-scatter integrals.

use airlight::geometry::Ray;
use airlight::integrator::RaymarchOptions;
use airlight::integrator::{Direct, Integrator, Raymarch};
use airlight::prelude::*;
use airlight::render::render;
use airlight::sampling::Sampler;
use glam::DVec3;

/// Adaptive Simpson quadrature in f64 (Lyness 1969), to `tol` absolute.
fn adaptive_simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    fn simpson(fa: f64, fm: f64, fb: f64, a: f64, b: f64) -> f64 {
        (b - a) / 6.0 * (fa + 4.0 * fm + fb)
    }
    #[allow(clippy::too_many_arguments)]
    fn recurse(
        f: &dyn Fn(f64) -> f64,
        a: f64,
        b: f64,
        fa: f64,
        fm: f64,
        fb: f64,
        whole: f64,
        tol: f64,
        depth: u32,
    ) -> f64 {
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let left = simpson(fa, flm, fm, a, m);
        let right = simpson(fm, frm, fb, m, b);
        if depth == 0 || (left + right - whole).abs() <= 15.0 * tol {
            return left + right + (left + right - whole) / 15.0;
        }
        recurse(f, a, m, fa, flm, fm, left, tol / 2.0, depth - 1)
            + recurse(f, m, b, fm, frm, fb, right, tol / 2.0, depth - 1)
    }
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    recurse(f, a, b, fa, fm, fb, simpson(fa, fm, fb, a, b), tol, 50)
}

/// HG phase in f64, pbrt's convention (both directions away from the point).
fn hg(cos: f64, g: f64) -> f64 {
    let denom = 1.0 + g * g + 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * denom * denom.sqrt())
}

struct Fog {
    sigma_a: f64,
    sigma_s: f64,
    g: f64,
    light: DVec3,
    intensity: f64,
}

impl Fog {
    /// The single-scatter integrand at distance t along (o, d): σs·p·I/r²·e^{−σt(t + r)}.
    fn integrand(&self, o: DVec3, d: DVec3, t: f64) -> f64 {
        let x = o + d * t;
        let to_light = self.light - x;
        let r = to_light.length();
        let sigma_t = self.sigma_a + self.sigma_s;
        self.sigma_s * hg((-d).dot(to_light / r), self.g) * self.intensity / (r * r) * (-sigma_t * (t + r)).exp()
    }

    fn scene(&self, max_distance: f32, objects: &[(Shape, &str)]) -> Scene {
        let mut b = SceneBuilder::new()
            .with_settings(|s| s.max_distance = max_distance)
            .material("m", Material::diffuse(Rgb::splat(0.5)))
            .light(Light::point(self.light.as_vec3(), Rgb::splat(self.intensity as f32)))
            .medium(Medium::homogeneous(
                Rgb::splat(self.sigma_a as f32),
                Rgb::splat(self.sigma_s as f32),
                self.g as f32,
            ));
        for (shape, material) in objects {
            b = b.object(shape.clone(), material);
        }
        b.build().unwrap()
    }
}

fn march(scene: &Scene, ray: &Ray, steps: u32, jitter: bool) -> f64 {
    let mut sampler = Sampler::for_pixel(1, 2, 3);
    Raymarch::new(RaymarchOptions { steps, jitter }).radiance(scene, ray, &mut sampler).x as f64
}

#[test]
fn march_with_4096_steps_matches_the_single_scatter_integral() {
    let mut s = Sampler::for_pixel(5, 5, 5);
    for case in 0..12 {
        let fog = Fog {
            sigma_a: 0.02 + 0.1 * s.next() as f64,
            sigma_s: 0.05 + 0.3 * s.next() as f64,
            g: if case % 3 == 0 { 0.0 } else { 0.8 * s.next() as f64 - 0.3 },
            light: DVec3::new(2.0 * s.next() as f64 - 1.0, 0.5 + s.next() as f64, 1.0 + 4.0 * s.next() as f64),
            intensity: 10.0,
        };
        let scene = fog.scene(12.0, &[]);
        let dir = Vec3::new(0.3 * s.next() - 0.15, 0.2 * s.next() - 0.1, 1.0).normalize();
        let ray = Ray::new(Vec3::ZERO, dir);
        let exact = adaptive_simpson(&|t| fog.integrand(DVec3::ZERO, dir.as_dvec3(), t), 0.0, 12.0, 1e-12);
        let marched = march(&scene, &ray, 4096, false);
        let rel = (marched / exact - 1.0).abs();
        assert!(rel < 0.005, "case {case}: march {marched} exact {exact} ({rel:.2e})");
    }
}

#[test]
fn midpoint_march_converges_at_second_order() {
    // Error ∝ Δ² for a smooth integrand (see Raymarch's doc comment): each
    // doubling of the steps divides the error by about 4.
    let fog = Fog { sigma_a: 0.05, sigma_s: 0.2, g: 0.3, light: DVec3::new(1.0, 1.0, 4.0), intensity: 10.0 };
    let scene = fog.scene(10.0, &[]);
    let dir = Vec3::new(0.05, -0.02, 1.0).normalize();
    let exact = adaptive_simpson(&|t| fog.integrand(DVec3::ZERO, dir.as_dvec3(), t), 0.0, 10.0, 1e-13);
    let errors: Vec<f64> = [32, 64, 128, 256]
        .iter()
        .map(|&n| (march(&scene, &Ray::new(Vec3::ZERO, dir), n, false) - exact).abs())
        .collect();
    for pair in errors.windows(2) {
        let ratio = pair[0] / pair[1];
        assert!((3.6..4.4).contains(&ratio), "errors {errors:?}: ratio {ratio}");
    }
}

#[test]
fn jittered_march_is_unbiased_around_the_integral() {
    // With few steps, one jittered sample is noisy, but the mean over many
    // pixel samples converges to the integral.
    let fog = Fog { sigma_a: 0.05, sigma_s: 0.2, g: 0.0, light: DVec3::new(0.1, 0.2, 4.3), intensity: 10.0 };
    let scene = fog.scene(10.0, &[]);
    let dir = Vec3::Z;
    let exact = adaptive_simpson(&|t| fog.integrand(DVec3::ZERO, dir.as_dvec3(), t), 0.0, 10.0, 1e-13);
    let mut sampler = Sampler::for_pixel(11, 0, 0);
    let n = 20_000;
    let mean: f64 = (0..n)
        .map(|_| {
            Raymarch::new(RaymarchOptions { steps: 8, jitter: true })
                .radiance(&scene, &Ray::new(Vec3::ZERO, dir), &mut sampler)
                .x as f64
        })
        .sum::<f64>()
        / n as f64;
    assert!((mean / exact - 1.0).abs() < 0.01, "mean {mean} exact {exact}");
    let fixed = march(&scene, &Ray::new(Vec3::ZERO, dir), 8, false);
    assert!((fixed / exact - 1.0).abs() > 0.01, "8 midpoints alone are off: this test needs the jitter to matter");
}

#[test]
fn vacuum_medium_gives_exactly_the_direct_image() {
    let build = |medium: Option<Medium>| {
        let mut b = SceneBuilder::new()
            .size(32, 24)
            .with_settings(|s| s.spp = 2)
            .material("m", Material::checker(Rgb::splat(0.8), Rgb::splat(0.3), 0.7))
            .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
            .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 1.0), "m")
            .light(Light::quad(vec3(-1.0, 4.0, -1.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 0.0, 2.0), Rgb::splat(4.0)))
            .light(Light::spot(vec3(2.0, 3.0, -2.0), Vec3::ZERO, Rgb::splat(30.0), 25.0, 20.0));
        if let Some(m) = medium {
            b = b.medium(m);
        }
        b.build().unwrap()
    };
    let direct = render(&build(None), &Direct, &RenderObserver::none());
    let vacuum = build(Some(Medium::homogeneous(Rgb::ZERO, Rgb::ZERO, 0.0)));
    let marched = render(&vacuum, &Raymarch::new(RaymarchOptions { steps: 16, jitter: true }), &RenderObserver::none());
    let diff = direct.pixels.iter().zip(&marched.pixels).position(|(a, b)| a != b);
    assert!(
        diff.is_none(),
        "vacuum raymarch differs from direct at pixel {diff:?}: {:?}",
        diff.map(|i| (direct.pixels[i], marched.pixels[i]))
    );
    assert!(direct.mean().x > 0.0);
}

/// Whether the segment from `x` to `light` passes through the sphere.
fn blocked(x: DVec3, light: DVec3, center: DVec3, radius: f64) -> bool {
    let d = light - x;
    let t = ((center - x).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (x + d * t - center).length() < radius
}

#[test]
fn a_sphere_casts_a_shadow_cone_of_the_right_depth() {
    let fog = Fog { sigma_a: 0.02, sigma_s: 0.15, g: 0.0, light: DVec3::new(0.0, 4.0, 0.0), intensity: 20.0 };
    let (center, radius) = (DVec3::new(0.0, 2.0, 0.0), 0.5);
    let scene = fog.scene(12.0, &[(Shape::sphere(center.as_vec3(), radius as f32), "m")]);
    // Independent answer: the lit intervals by bisection of the f64
    // segment–sphere test, each integrated by adaptive Simpson.
    let independent = |o: DVec3, d: DVec3| {
        let n = 2000;
        let visible = |t: f64| !blocked(o + d * t, fog.light, center, radius);
        let mut edges = vec![0.0];
        for i in 0..n {
            let (a, b) = (12.0 * i as f64 / n as f64, 12.0 * (i + 1) as f64 / n as f64);
            if visible(a) != visible(b) {
                let (mut lo, mut hi) = (a, b);
                for _ in 0..60 {
                    let m = 0.5 * (lo + hi);
                    if visible(m) == visible(a) { lo = m } else { hi = m }
                }
                edges.push(0.5 * (lo + hi));
            }
        }
        edges.push(12.0);
        edges
            .windows(2)
            .filter(|w| visible(0.5 * (w[0] + w[1])))
            .map(|w| adaptive_simpson(&|t| fog.integrand(o, d, t), w[0], w[1], 1e-12))
            .sum::<f64>()
    };
    let through = (DVec3::new(-6.0, 0.5, 0.0), DVec3::X);
    let beside = (DVec3::new(-6.0, 0.5, 3.0), DVec3::X);
    let expected_through = independent(through.0, through.1);
    let expected_beside = independent(beside.0, beside.1);
    let unshadowed = adaptive_simpson(&|t| fog.integrand(through.0, through.1, t), 0.0, 12.0, 1e-12);
    let shadow_fraction = 1.0 - expected_through / unshadowed;
    assert!(shadow_fraction > 0.2, "the cone must take a real share: {shadow_fraction}");
    // Jittered march at 4096 steps averaged over 64 samples.
    let mean = |(o, d): (DVec3, DVec3)| {
        let mut sampler = Sampler::for_pixel(3, 3, 3);
        let ray = Ray::new(o.as_vec3(), d.as_vec3());
        (0..64)
            .map(|_| {
                Raymarch::new(RaymarchOptions { steps: 4096, jitter: true }).radiance(&scene, &ray, &mut sampler).x
                    as f64
            })
            .sum::<f64>()
            / 64.0
    };
    let (got_through, got_beside) = (mean(through), mean(beside));
    assert!((got_through / expected_through - 1.0).abs() < 0.01, "{got_through} vs {expected_through}");
    assert!((got_beside / expected_beside - 1.0).abs() < 0.01, "{got_beside} vs {expected_beside}");
    let ratio = got_through / got_beside;
    let expected_ratio = expected_through / expected_beside;
    assert!((ratio / expected_ratio - 1.0).abs() < 0.01, "ratio {ratio} vs {expected_ratio}");
}
