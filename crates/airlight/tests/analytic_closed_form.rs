//! The analytic integrator's closed forms against numeric integrals written
//! here, independently of the code under test: adaptive Simpson in f64 over
//! the integrand as the physics states it (1/|o + t d − P|² and its
//! attenuated form), never through Packard's coordinates or the special
//! functions.

use airlight::integrator::analytic::{
    Glow, P_FLOOR, glow_extinction, glow_vacuum, glow_vacuum_f32, seed_coordinates, sun_f,
};
use glam::{DVec3, Vec3};

/// A small deterministic generator (SplitMix64), so the cases are fixed.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

mod common;
use common::integrate;

#[test]
fn the_numeric_integrator_is_right() {
    // The oracle itself, on integrals with known values.
    type Case<'a> = (&'a dyn Fn(f64) -> f64, f64, f64, f64);
    let cases: [Case; 3] = [
        (&|x: f64| x.exp(), 0.0, 3.0, 3f64.exp() - 1.0),
        (&|x: f64| 1.0 / (1e-4 + x * x), -2.0, 5.0, ((5e2f64).atan() + (2e2f64).atan()) * 1e2),
        (&|x: f64| x.cos(), 0.0, 10.0, 10f64.sin()),
    ];
    for (f, a, b, exact) in cases {
        let got = integrate(f, a, b, &[0.0], 1e-13);
        assert!((got / exact - 1.0).abs() < 1e-12, "{got} vs {exact}");
    }
}

#[test]
fn atan_form_matches_numeric_integration_for_10000_random_rays() {
    let mut rng = Rng(4);
    let (mut worst, mut worst_f32) = (0.0f64, 0.0f64);
    let mut errors_f32 = Vec::new();
    for _ in 0..10_000 {
        let light = DVec3::new(rng.range(-10.0, 10.0), rng.range(-5.0, 5.0), rng.range(-10.0, 10.0));
        let origin = DVec3::new(rng.range(-10.0, 10.0), rng.range(-5.0, 5.0), rng.range(-10.0, 10.0));
        let dir = rng.unit();
        let t_end = rng.range(0.01, 30.0);
        // The f32 scene coordinates the renderer would see, exactly in f64.
        let (l32, o32, d32) = (light.as_vec3(), origin.as_vec3(), dir.as_vec3().normalize());
        let (light, origin, dir) = (l32.as_dvec3(), o32.as_dvec3(), d32.as_dvec3().normalize());
        let t_end = t_end as f32 as f64;

        let (a, b, p) = seed_coordinates(light, origin, dir, t_end);
        let got = glow_vacuum(p, a, b);
        let f = |t: f64| 1.0 / (origin + dir * t - light).length_squared();
        let foot = dir.dot(light - origin);
        let expected = integrate(&f, 0.0, t_end, &[foot], 1e-13);
        let rel = (got / expected - 1.0).abs();
        assert!(rel <= 1e-9, "P={light} O={origin} D={dir} T={t_end}: {got} vs {expected} ({rel:e})");
        worst = worst.max(rel);

        let got32 = glow_vacuum_f32(l32, o32, d32, t_end as f32) as f64;
        let rel32 = (got32 / expected - 1.0).abs();
        worst_f32 = worst_f32.max(rel32);
        errors_f32.push(rel32);
    }
    errors_f32.sort_by(f64::total_cmp);
    let median = errors_f32[errors_f32.len() / 2];
    let p999 = errors_f32[errors_f32.len() * 999 / 1000];
    println!(
        "atan form, f64: worst relative error {worst:.2e}; \
         f32: median {median:.2e}, 99.9th percentile {p999:.2e}, worst {worst_f32:.2e}"
    );
    // The f32 form: p = |Δ − (D·Δ) D| loses digits when the light is near
    // the ray's line (p ≪ |Δ|); typical errors are a few ulps.
    assert!(median < 1e-6, "{median:e}");
    assert!(p999 < 1e-3, "{p999:e}");
}

#[test]
fn atan_form_near_and_on_the_line_is_finite_and_bounded() {
    // Foot inside the segment, light on the line: the stated bound.
    for (a, b) in [(-1.0, 1.0), (-30.0, 0.5), (0.0, 2.0)] {
        let v = glow_vacuum(0.0, a, b);
        let bound = std::f64::consts::PI / (P_FLOOR * (a.abs() + b.abs()));
        assert!(v.is_finite() && v > 0.0 && v <= bound * (1.0 + 1e-12), "{v}");
        assert!(glow_vacuum(1e-300, a, b) <= bound * (1.0 + 1e-12));
    }
    // Foot outside the segment: the exact limit 1/a − 1/b as p → 0.
    for (a, b) in [(1.0, 3.0), (-5.0, -0.25), (0.5, 1e3)] {
        let limit = 1.0 / a - 1.0 / b;
        for p in [0.0, 1e-12, 1e-8] {
            let v = glow_vacuum(p, a, b);
            assert!((v / limit - 1.0).abs() < 1e-9, "p={p}: {v} vs {limit}");
        }
    }
    // Empty or reversed segments give 0, NaN input gives no panic.
    assert_eq!(glow_vacuum(1.0, 2.0, 2.0), 0.0);
    assert_eq!(glow_vacuum(1.0, 3.0, 2.0), 0.0);
    let _ = glow_vacuum(f64::NAN, 0.0, 1.0);
    // With extinction too, a light on the ray's line stays finite.
    let g = Glow::new(0.3, DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Z, 10.0);
    let v = g.between(0.0, 10.0);
    assert!(v.is_finite() && v > 0.0, "{v}");
    // f32: a light exactly on the ray.
    let v = glow_vacuum_f32(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Z, 10.0);
    assert!(v.is_finite() && v > 0.0);
}

/// ∫_a^b e^{−σt (y + r)} / r² dy, r² = p² + y², numerically.
fn extinction_numeric(sigma_t: f64, p: f64, a: f64, b: f64) -> f64 {
    let f = |y: f64| {
        let r2 = p * p + y * y;
        (-sigma_t * (y + r2.sqrt())).exp() / r2
    };
    integrate(&f, a, b, &[0.0], 1e-12)
}

#[test]
fn extinction_form_matches_numeric_integration_on_a_grid() {
    let sigmas = [1e-4, 0.01, 0.1, 0.5, 2.0, 10.0];
    let ps = [0.003, 0.1, 1.0, 4.0, 25.0];
    let ends = [-40.0, -6.0, -1.0, -0.1, 0.0, 0.05, 0.7, 3.0, 12.0, 80.0];
    let mut worst = 0.0f64;
    let mut count = 0;
    for &s in &sigmas {
        for &p in &ps {
            for (i, &a) in ends.iter().enumerate() {
                for &b in &ends[i + 1..] {
                    let expected = extinction_numeric(s, p, a, b);
                    let got = glow_extinction(s, p, a, b);
                    if expected < 1e-250 {
                        assert!(got.abs() < 1e-240, "σt={s} p={p} [{a},{b}]: {got}");
                        continue;
                    }
                    let rel = (got / expected - 1.0).abs();
                    assert!(rel <= 1e-3, "σt={s} p={p} [{a}, {b}]: {got} vs {expected} ({rel:e})");
                    worst = worst.max(rel);
                    count += 1;
                }
            }
        }
    }
    println!("extinction form: worst relative error {worst:.2e} over {count} cases");
    assert!(worst < 1e-8, "{worst:e}");
}

#[test]
fn extinction_form_along_random_rays_matches_numeric_integration() {
    // The Glow built from world positions, with the foot anywhere (before
    // the origin, past the end), and very short spans (where the closed
    // form's two terms nearly cancel).
    let mut rng = Rng(11);
    let mut worst = 0.0f64;
    for i in 0..2000 {
        let light = DVec3::new(rng.range(-10.0, 10.0), rng.range(0.0, 6.0), rng.range(-10.0, 30.0));
        let origin = DVec3::new(rng.range(-3.0, 3.0), rng.range(0.0, 3.0), rng.range(-10.0, 0.0));
        let dir = rng.unit();
        let sigma_t = [0.002, 0.05, 0.4, 3.0][i % 4];
        let t1 = rng.range(0.01, 60.0);
        let t0 = if i % 3 == 0 { t1 * (1.0 - 1e-6 * rng.next()) } else { rng.range(0.0, t1) };
        let glow = Glow::new(sigma_t, light, origin, dir, t1);
        let got = glow.between(t0, t1);
        let f = |t: f64| {
            let r2 = (origin + dir * t - light).length_squared();
            (-sigma_t * (t + r2.sqrt())).exp() / r2
        };
        let expected = integrate(&f, t0, t1, &[dir.dot(light - origin)], 1e-12);
        if expected < 1e-250 {
            continue;
        }
        let rel = (got / expected - 1.0).abs();
        assert!(rel < 1e-9, "case {i}: {got} vs {expected} ({rel:e})");
        worst = worst.max(rel);
    }
    println!("extinction form along rays: worst relative error {worst:.2e}");
}

#[test]
fn sun_f_matches_its_definition() {
    // F(u, v) = ∫₀^v e^{−u tan ξ} dξ (Sun et al. 2005, eq. 7).
    for &u in &[0.0, 1e-3, 0.2, 1.0, 3.0, 9.0, 40.0] {
        for &v in &[1e-4, 0.1, 0.6, 1.0, 1.4, 1.55, std::f64::consts::FRAC_PI_2] {
            let f = |x: f64| (-u * x.tan()).exp();
            // tan ξ blows up at π/2; the integrand there is 0 (or 1 for u = 0).
            let top = v.min(std::f64::consts::FRAC_PI_2 - 1e-9);
            let mut expected = integrate(&f, 0.0, top, &[], 1e-12);
            if u == 0.0 {
                expected = v;
            }
            let got = sun_f(u, v);
            let err = (got - expected).abs() / expected.max(1e-300);
            assert!(err < 1e-8, "F({u}, {v}) = {got}, numeric {expected}");
        }
    }
}
