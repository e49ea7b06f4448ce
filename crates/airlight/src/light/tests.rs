use super::*;
use std::f64::consts::PI;

/// Irradiance at the origin (normal +y) from a uniformly emitting polygon, by
/// Lambert's closed form: E = L/2 · |Σ θ_i (n · unit(v_i × v_{i+1}))|, v_i the
/// unit vectors to the vertices and θ_i the angle between consecutive ones.
fn polygon_irradiance(vertices: &[glam::DVec3], radiance: f64, n: glam::DVec3) -> f64 {
    let mut sum = 0.0;
    for i in 0..vertices.len() {
        let a = vertices[i].normalize();
        let b = vertices[(i + 1) % vertices.len()].normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * radiance * sum.abs()
}

/// Irradiance on a surface with normal `n` at `p`, from a stratified grid of
/// k×k light samples (unshadowed).
fn estimated_irradiance(light: &Light, p: Vec3, n: Vec3, k: usize) -> f64 {
    let mut sum = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
            if let Some(s) = light.sample(p, u) {
                sum += (s.weight.x * s.wi.dot(n).max(0.0)) as f64;
            }
        }
    }
    sum / (k * k) as f64
}

#[test]
fn quad_light_irradiance_matches_lambert_closed_form() {
    // A 2×1 light, 1.5 above a point and offset, facing down.
    let corner = Vec3::new(-0.3, 1.5, -0.4);
    let (eu, ev) = (Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
    assert!(eu.cross(ev).y < 0.0, "faces down");
    let light = Light::quad(corner, eu, ev, Rgb::splat(3.0));
    let verts: Vec<glam::DVec3> =
        [corner, corner + eu, corner + eu + ev, corner + ev].iter().map(|v| v.as_dvec3()).collect();
    let exact = polygon_irradiance(&verts, 3.0, glam::DVec3::Y);
    // 1024 samples, as the issue asks.
    let est = estimated_irradiance(&light, Vec3::ZERO, Vec3::Y, 32);
    assert!((est / exact - 1.0).abs() < 0.01, "estimate {est} exact {exact}");
    // From above, the light's back faces the point: no light.
    assert_eq!(estimated_irradiance(&light, Vec3::new(0.5, 3.0, 0.1), -Vec3::Y, 4), 0.0);
}

#[test]
fn triangle_light_irradiance_matches_lambert_closed_form() {
    // A slanted triangle above the point, wound to face it, near and far.
    for (lift, tolerance) in [(0.6f32, 0.01), (4.0, 0.002)] {
        let (a, b, c) =
            (Vec3::new(-0.7, lift, -0.2), Vec3::new(0.2, lift + 0.5, 0.9), Vec3::new(0.9, lift - 0.1, -0.4));
        let light = Light::triangle(a, c, b, Rgb::splat(2.5));
        let Light::Triangle { edge_1, edge_2, .. } = light else { unreachable!() };
        assert!(edge_1.cross(edge_2).y < 0.0, "faces down");
        let exact = polygon_irradiance(&[a, c, b].map(|v| v.as_dvec3()), 2.5, glam::DVec3::Y);
        let est = estimated_irradiance(&light, Vec3::ZERO, Vec3::Y, 64);
        assert!((est / exact - 1.0).abs() < tolerance, "lift {lift}: estimate {est} exact {exact}");
        // Wound the other way it faces away: no light.
        let back = Light::triangle(a, b, c, Rgb::splat(2.5));
        assert_eq!(estimated_irradiance(&back, Vec3::ZERO, Vec3::Y, 8), 0.0);
    }
}

#[test]
fn two_triangles_give_the_light_of_their_quad() {
    let (corner, eu, ev) = (Vec3::new(-0.5, 2.0, -0.3), Vec3::new(1.2, 0.0, 0.0), Vec3::new(0.0, 0.3, 0.8));
    let quad = Light::quad(corner, eu, ev, Rgb::splat(4.0));
    let halves = [
        Light::triangle(corner, corner + eu, corner + eu + ev, Rgb::splat(4.0)),
        Light::triangle(corner, corner + eu + ev, corner + ev, Rgb::splat(4.0)),
    ];
    for (p, n) in [(Vec3::ZERO, Vec3::Y), (Vec3::new(1.5, 0.5, -1.0), Vec3::new(-0.5, 1.0, 0.6).normalize())] {
        let of_quad = estimated_irradiance(&quad, p, n, 64);
        let of_triangles: f64 = halves.iter().map(|t| estimated_irradiance(t, p, n, 64)).sum();
        assert!((of_triangles / of_quad - 1.0).abs() < 0.003, "{of_triangles} vs {of_quad}");
    }
}

#[test]
fn triangle_light_pdf_is_the_pdf_it_samples_with() {
    let light = Light::triangle(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 1.5, 0.0), Vec3::new(0.0, 1.2, 1.0), Rgb::ONE);
    let p = Vec3::new(0.3, -0.5, 0.2);
    let mut seen = 0;
    for i in 0..16 {
        let u = Vec2::new((i as f32 + 0.5) / 16.0, ((i * 7) % 16) as f32 / 16.0 + 0.03);
        if let Some(s) = light.sample(p, u) {
            let pdf = light.pdf(p, s.wi, s.distance);
            assert!((pdf / s.pdf - 1.0).abs() < 1e-4, "{pdf} vs {}", s.pdf);
            // The sampled point lies on the light's surface.
            let surface = light.surface().unwrap();
            let crate::geometry::Shape::Mesh { positions, .. } = surface else { unreachable!() };
            let (a, e1, e2) = (positions[0], positions[1] - positions[0], positions[2] - positions[0]);
            let t = crate::geometry::intersect_triangle(a, e1, e2, p, s.wi, 0.0, f32::INFINITY);
            assert!((t / s.distance - 1.0).abs() < 1e-4, "hit at {t}, sampled at {}", s.distance);
            seen += 1;
        }
    }
    assert!(seen > 0, "the light faces p but gave no sample");
}

#[test]
fn sphere_light_irradiance_matches_closed_form() {
    // E = π L (r/D)² on a point facing the sphere's centre at distance D.
    for (radius, dist) in [(0.5f32, 3.0f32), (1.0, 1.2), (0.05, 10.0)] {
        let light = Light::sphere(Vec3::new(0.0, dist, 0.0), radius, Rgb::splat(2.0));
        let exact = PI * 2.0 * (radius as f64 / dist as f64).powi(2);
        let est = estimated_irradiance(&light, Vec3::ZERO, Vec3::Y, 64);
        assert!((est / exact - 1.0).abs() < 0.005, "r {radius} D {dist}: {est} vs {exact}");
    }
}

#[test]
fn sphere_light_samples_land_on_the_sphere() {
    let c = Vec3::new(1.0, 2.0, 3.0);
    let light = Light::sphere(c, 0.7, Rgb::ONE);
    let p = Vec3::new(-1.0, 0.5, 0.0);
    for i in 0..100 {
        let u = Vec2::new((i as f32 * 0.618) % 1.0, (i as f32 * 0.377) % 1.0);
        let s = light.sample(p, u).unwrap();
        let x = p + s.wi * s.distance;
        assert!(((x - c).length() - 0.7).abs() < 1e-4);
        assert!((x - c).dot(s.wi) <= 1e-4, "the near side");
    }
}

#[test]
fn point_light_gives_inverse_square_irradiance() {
    let light = Light::point(Vec3::new(0.0, 2.0, 0.0), Rgb::splat(8.0));
    let s = light.sample(Vec3::ZERO, Vec2::ZERO).unwrap();
    assert_eq!(s.weight, Rgb::splat(2.0));
    assert_eq!(s.wi, Vec3::Y);
}

#[test]
fn spot_profiles_match_their_definitions() {
    let (cone, start) = (30f32.to_radians(), 20f32.to_radians());
    for profile in [SpotProfile::Smoothstep, SpotProfile::Linear] {
        assert_eq!(spot_falloff(profile, 1.0, cone, start), 1.0);
        assert_eq!(spot_falloff(profile, 19f32.to_radians().cos(), cone, start), 1.0);
        assert_eq!(spot_falloff(profile, 31f32.to_radians().cos(), cone, start), 0.0);
    }
    // Linear: half-way in angle gives one half.
    let mid = spot_falloff(SpotProfile::Linear, 25f32.to_radians().cos(), cone, start);
    assert!((mid - 0.5).abs() < 1e-4);
    // Smoothstep: half-way in cosine gives one half.
    let mid_cos = 0.5 * (cone.cos() + start.cos());
    assert!((spot_falloff(SpotProfile::Smoothstep, mid_cos, cone, start) - 0.5).abs() < 1e-4);
    // Equal angles: a hard edge.
    assert_eq!(spot_falloff(SpotProfile::Smoothstep, 29.9f32.to_radians().cos(), cone, cone), 1.0);
    assert_eq!(spot_falloff(SpotProfile::Linear, 30.1f32.to_radians().cos(), cone, cone), 0.0);
}

#[test]
fn seed_sphere_attenuation_is_exact_for_a_facing_point() {
    // Madams's 1/(d/r + 1)² in Airlight's normalisation, E = πL·f(d),
    // equals the closed form πL(r/D)² on a point facing the sphere, and the
    // cone-sampled exact light agrees.
    let (r, l) = (0.4f32, 3.0f32);
    for dist in [0.5f32, 1.0, 2.5, 9.0] {
        let center = Vec3::new(0.0, dist, 0.0);
        let approx = Light::sphere(center, r, Rgb::splat(l))
            .with_attenuation(Attenuation::new(AttenuationModel::Sphere, r, 0.0, None, None).unwrap());
        let s = approx.sample(Vec3::ZERO, Vec2::ZERO).unwrap();
        let seed = std::f64::consts::PI * l as f64 * sphere_falloff(dist - r, r) as f64;
        let closed = PI * l as f64 * (r as f64 / dist as f64).powi(2);
        assert!((s.weight.x as f64 / seed - 1.0).abs() < 1e-5);
        assert!((seed / closed - 1.0).abs() < 1e-5, "d {dist}: {seed} vs {closed}");
        let exact = estimated_irradiance(&Light::sphere(center, r, Rgb::splat(l)), Vec3::ZERO, Vec3::Y, 64);
        assert!((exact / closed - 1.0).abs() < 0.005);
    }
}

#[test]
fn sphere_light_cone_sampling_agrees_with_random_area_sampling() {
    // An independent estimator: uniform points on the sphere's surface,
    // E = ∫ L cosθ cosθ' / r² dA over the visible cap, at a tilted point.
    let (c, r, l) = (Vec3::new(0.3, 2.0, -0.4), 0.6f32, 2.0f32);
    let n = Vec3::new(0.2, 1.0, 0.1).normalize();
    let mut s = crate::sampling::Sampler::for_pixel(4, 4, 4);
    let samples = 400_000;
    let mut area_sum = 0.0f64;
    for _ in 0..samples {
        let on = crate::sampling::uniform_sphere(s.next2());
        let x = c + on * r;
        let to = x - Vec3::ZERO;
        let d2 = to.length_squared();
        let wi = to / d2.sqrt();
        let cos_surface = wi.dot(n).max(0.0);
        let cos_light = (-wi).dot(on);
        if cos_light > 0.0 {
            area_sum += (l * cos_surface * cos_light / d2) as f64;
        }
    }
    let area_estimate = area_sum / samples as f64 * 4.0 * PI * (r as f64).powi(2);
    let cone = estimated_irradiance(&Light::sphere(c, r, Rgb::splat(l)), Vec3::ZERO, n, 128);
    assert!((cone / area_estimate - 1.0).abs() < 0.005, "cone {cone} area {area_estimate}");
}
