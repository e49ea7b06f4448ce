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
