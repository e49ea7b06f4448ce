use super::*;

/// Composite Simpson integral of f over [a, b] with n (even) intervals, f64.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut sum = f(a) + f(b);
    for i in 1..n {
        sum += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

#[test]
fn homogeneous_transmittance_is_beer_lambert() {
    let m = Medium::homogeneous(Rgb::new(0.1, 0.0, 0.3), Rgb::new(0.2, 0.0, 0.1), 0.0);
    let t = m.transmittance(Vec3::ZERO, Vec3::X, 1.0, 4.0);
    let numeric = |sigma: f64| (-simpson(|_| sigma, 1.0, 4.0, 2)).exp();
    assert!((t.x as f64 / numeric(0.3) - 1.0).abs() < 1e-6);
    assert_eq!(t.y, 1.0);
    assert!((t.z as f64 / numeric(0.4) - 1.0).abs() < 1e-6);
    // A channel with σt = 0 transmits everything even over an infinite length.
    assert_eq!(m.transmittance(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY).y, 1.0);
}

#[test]
fn height_fog_optical_depth_matches_numeric_integral() {
    let m = Medium::height(Rgb::splat(0.05), Rgb::splat(0.2), 0.0, 0.5, 0.7);
    let dirs = [
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.3, -0.6, 0.2).normalize(),
        Vec3::new(1.0, 1e-6, 0.0).normalize(),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(-0.2, 0.9, 0.4).normalize(),
    ];
    for d in dirs {
        let o = Vec3::new(0.3, 1.2, -2.0);
        let (t0, t1) = (0.5f32, 6.0f32);
        let density = |t: f64| (-0.7 * (o.y as f64 + t * d.y as f64 - 0.5)).exp();
        let numeric = 0.25 * simpson(density, t0 as f64, t1 as f64, 20_000);
        let closed = m.optical_depth(o, d, t0, t1).x as f64;
        assert!((closed / numeric - 1.0).abs() < 1e-6, "d {d}: {closed} vs {numeric}");
    }
}

#[test]
fn height_fog_to_infinity_upward_converges() {
    let m = Medium::height(Rgb::ZERO, Rgb::splat(1.0), 0.0, 0.0, 2.0);
    let o = Vec3::new(0.0, 1.0, 0.0);
    let d = Vec3::new(0.6, 0.8, 0.0);
    // ∫0^∞ e^{−2(1 + 0.8 t)} dt = e^{−2}/1.6
    let expected = (-2.0f64).exp() / 1.6;
    let depth = m.optical_depth(o, d, 0.0, f32::INFINITY).x as f64;
    assert!((depth / expected - 1.0).abs() < 1e-6);
    assert_eq!(m.transmittance(o, -d, 0.0, f32::INFINITY).x, 0.0, "downward it never ends");
}

#[test]
fn henyey_greenstein_integrates_to_one_and_g_is_forward() {
    for g in [-0.9f32, -0.5, 0.0, 0.3, 0.8, 0.95] {
        // ∫ p dω = 2π ∫_{-1}^{1} p(μ) dμ; dense Simpson for the peaked g.
        let total =
            2.0 * std::f64::consts::PI * simpson(|mu| henyey_greenstein(mu as f32, g) as f64, -1.0, 1.0, 200_000);
        assert!((total - 1.0).abs() < 1e-4, "g {g}: {total}");
    }
    // Forward: light continuing straight on, wi = −wo, cos θ = −1.
    assert!(henyey_greenstein(-1.0, 0.5) > henyey_greenstein(1.0, 0.5));
    assert_eq!(henyey_greenstein(0.3, 0.0), isotropic());
}

/// Profiles met along rays: level, slightly and steeply up and down, a
/// start far below the base (ρ0 = e^40) and far above it (ρ0 = e^−40).
fn profiles() -> Vec<DensityProfile> {
    let mut all = Vec::new();
    for ln_rho0 in [0.0, 1.3, -2.0, 40.0, -40.0] {
        for a in [0.0, 1e-9, -1e-9, 0.35, -0.35, 2.4, -2.4] {
            all.push(DensityProfile { ln_rho0, a });
        }
    }
    all
}

#[test]
fn density_profile_integral_matches_quadrature() {
    for p in profiles() {
        let density = |t: f64| (p.ln_rho0 - p.a * t).exp();
        for (t0, t1) in [(0.0, 0.3), (0.5, 6.0), (2.0, 17.0), (0.0, 1e-7)] {
            let numeric = simpson(density, t0, t1, 20_000);
            let closed = p.integral(t0, t1);
            assert!((closed / numeric - 1.0).abs() < 1e-9, "{p:?} [{t0}, {t1}]: {closed} vs {numeric}");
        }
        assert_eq!(p.integral(3.0, 3.0), 0.0);
        assert_eq!(p.integral(3.0, 1.0), 0.0);
        // To infinity: finite heading up, ρ(t0)/a; else infinite.
        let whole = p.integral(1.0, f64::INFINITY);
        if p.a > 0.0 {
            let numeric = simpson(density, 1.0, 1.0 + 60.0 / p.a, 200_000);
            assert!((whole / numeric - 1.0).abs() < 1e-9, "{p:?}: {whole} vs {numeric}");
        } else {
            assert_eq!(whole, f64::INFINITY, "{p:?}");
        }
    }
}

#[test]
fn density_profile_distance_inverts_the_integral() {
    // The distance t at which the quadrature of ρ over [0, t] reaches x, for
    // x spread over the orders of magnitude a flight meets; infinite exactly
    // when the whole line holds less than x.
    for p in profiles() {
        let density = |t: f64| (p.ln_rho0 - p.a * t).exp();
        let rho0 = p.ln_rho0.exp();
        for x in [1e-12, 1e-4, 0.02, 0.5, 1.0, 3.0, 40.0] {
            let t = p.distance_to(x * rho0);
            if p.a > 0.0 && x * p.a >= 1.0 {
                assert_eq!(t, f64::INFINITY, "{p:?} x {x}");
                continue;
            }
            assert!(t.is_finite() && t >= 0.0, "{p:?} x {x}: {t}");
            let reached = simpson(density, 0.0, t, 20_000);
            assert!((reached / (x * rho0) - 1.0).abs() < 1e-8, "{p:?} x {x}: t {t}, ∫ {reached}");
        }
        assert_eq!(p.distance_to(0.0), 0.0);
        assert_eq!(p.distance_to(-1.0), 0.0);
        assert_eq!(p.distance_to(f64::INFINITY), f64::INFINITY);
    }
}

#[test]
fn density_profile_never_gives_nan_at_extremes() {
    // Far below the base (ρ0 overflows f64), far above (it underflows),
    // heading either way over huge lengths: finite, infinite or zero,
    // never NaN, and the inverse stays monotone.
    for ln_rho0 in [-900.0, -300.0, 0.0, 300.0, 900.0] {
        for a in [-50.0, -1e-3, 0.0, 1e-3, 50.0] {
            let p = DensityProfile { ln_rho0, a };
            for (t0, t1) in [(0.0, 1e-30), (0.0, 1.0), (0.0, 1e6), (1e3, 1e7), (0.0, f64::INFINITY)] {
                let x = p.integral(t0, t1);
                assert!(!x.is_nan() && x >= 0.0, "{p:?} [{t0}, {t1}]: {x}");
            }
            let mut last = 0.0;
            for x in [1e-300, 1e-30, 1e-3, 1.0, 1e3, 1e30, 1e300] {
                let t = p.distance_to(x);
                assert!(!t.is_nan() && t >= last, "{p:?} x {x}: {t} after {last}");
                last = t;
            }
        }
    }
}

#[test]
fn height_fog_transmittance_matches_quadrature_from_below_the_base() {
    // Starting 3 units below the base (density e^{2.4} there) heading down
    // and up, and above it heading level, against exp(−σt ∫ρ) by Simpson.
    let m = Medium::height(Rgb::new(0.05, 0.1, 0.0), Rgb::new(0.3, 0.2, 0.0), 0.0, -1.0, 0.8);
    for (o, d) in [
        (Vec3::new(0.0, -4.0, 0.0), Vec3::new(0.5, -0.7, 0.1).normalize()),
        (Vec3::new(0.0, -4.0, 0.0), Vec3::new(0.2, 0.9, 0.0).normalize()),
        (Vec3::new(1.0, 2.0, 0.0), Vec3::X),
    ] {
        let density = |t: f64| (-0.8 * (o.y as f64 + t * d.y as f64 + 1.0)).exp();
        let integral = simpson(density, 0.0, 5.0, 20_000);
        let t = m.transmittance(o, d, 0.0, 5.0);
        for (c, sigma_t) in [0.35, 0.3, 0.0].into_iter().enumerate() {
            let expected = (-sigma_t * integral).exp();
            assert!((t[c] as f64 - expected).abs() < 1e-6 * expected.max(1e-30), "{d}: {} vs {expected}", t[c]);
        }
    }
}

#[test]
fn free_flight_scattering_integrates_to_the_scattered_fraction() {
    // ∫0^L σs ρ(t) T(0, t) dt = (σs/σt)(1 − T(0, L)): every flight that
    // collides before L scatters with probability σs/σt. Quadrature of the
    // density against transmittances from the quadrature of ρ.
    let m = Medium::height(Rgb::new(0.05, 0.0, 0.2), Rgb::new(0.3, 0.5, 0.0), 0.0, -1.0, 0.8);
    for (o, d) in [
        (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.3, -0.8, 0.0).normalize()),
        (Vec3::new(0.0, -3.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
        (Vec3::new(0.0, 0.5, 0.0), Vec3::Z),
    ] {
        let length = 8.0f32;
        let n = 4000;
        let h = length as f64 / n as f64;
        let mut integral = glam::DVec3::ZERO;
        for i in 0..n {
            let t = (i as f64 + 0.5) * h;
            integral += m.free_flight_scattering(o, d, t as f32).as_dvec3() * h;
        }
        let density = |t: f64| (-0.8 * (o.y as f64 + t * d.y as f64 + 1.0)).exp();
        let depth = simpson(density, 0.0, length as f64, 20_000);
        for c in 0..3 {
            let (sigma_s, sigma_t) = (m.sigma_s[c] as f64, m.sigma_t()[c] as f64);
            let expected = if sigma_t > 0.0 { sigma_s / sigma_t * (1.0 - (-sigma_t * depth).exp()) } else { 0.0 };
            assert!(
                (integral[c] - expected).abs() < 2e-4 * expected.max(1e-3),
                "{d} channel {c}: {} vs {expected}",
                integral[c]
            );
        }
    }
    // Deep below the base ρ overflows f32; the product stays finite.
    let deep = m.free_flight_scattering(Vec3::new(0.0, -300.0, 0.0), Vec3::X, 0.0);
    assert!(deep.is_finite() && deep.x > 0.0, "{deep}");
}
