//! Sphere tracing against analytic ray–sphere and ray–box intersection on
//! random rays, alone and through the scene's BVH with analytic shapes.

use airlight::geometry::sdf::{hit_epsilon, sdf_normal, sphere_trace};
use airlight::geometry::{GeometryBuilder, Ray, Sdf, Shape, intersect_box, intersect_sphere};
use airlight::sampling::{Sampler, uniform_sphere};
use glam::{Affine3A, Quat, Vec3};

/// A random ray from a box of side 8 around the origin, aimed near the
/// origin most of the time.
fn random_ray(s: &mut Sampler) -> (Vec3, Vec3) {
    let o = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 8.0;
    let target = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 3.0;
    let d = if s.next() < 0.2 { uniform_sphere(s.next2()) } else { (target - o).normalize() };
    (o, d)
}

struct Tally {
    hits: usize,
    misses: usize,
    grazing: usize,
}

/// Compares the traced distance with the analytic one on `n` rays. Grazing
/// rays are counted apart: those whose closest approach to the surface
/// (`margin`) is within 10⁻³, and those meeting it at under 2° (cos of the
/// incidence below 0.035, from `incidence`, the |cos| at the analytic hit):
/// sphere tracing may exhaust its steps creeping along them, the one way it
/// may differ. Elsewhere the trace stops within ε = hit_epsilon(p) of the
/// surface, so at most ε/cos θ before the analytic hit.
fn compare(
    name: &str,
    n: usize,
    traced: impl Fn(Vec3, Vec3) -> f32,
    analytic: impl Fn(Vec3, Vec3) -> f32,
    margin: impl Fn(Vec3, Vec3) -> f32,
    incidence: impl Fn(Vec3, Vec3, f32) -> f32,
) -> Tally {
    let mut s = Sampler::for_pixel(77, name.len() as u64, 0);
    let mut tally = Tally { hits: 0, misses: 0, grazing: 0 };
    for i in 0..n {
        let (o, d) = random_ray(&mut s);
        let (t, expected) = (traced(o, d), analytic(o, d));
        let cos = if expected.is_finite() { incidence(o, d, expected) } else { 1.0 };
        if margin(o, d).abs() < 1e-3 || cos < 0.035 {
            tally.grazing += 1;
            continue;
        }
        match (t.is_finite(), expected.is_finite()) {
            (true, true) => {
                let tolerance = hit_epsilon(o + d * expected) / cos + 1e-5;
                assert!(
                    t <= expected + 1e-5 && expected - t < tolerance,
                    "{name} ray {i}: traced {t}, analytic {expected}"
                );
                tally.hits += 1;
            }
            (false, false) => tally.misses += 1,
            _ => panic!("{name} ray {i} from {o} along {d}: traced {t}, analytic {expected}"),
        }
    }
    assert!(tally.hits > n / 4 && tally.misses > n / 20, "{name}: {} hits, {} misses", tally.hits, tally.misses);
    assert!(tally.grazing * 50 < n, "{name}: {} grazing", tally.grazing);
    tally
}

#[test]
fn sphere_tracing_matches_ray_sphere_intersection() {
    let (c, r) = (Vec3::new(0.3, -0.2, 0.4), 1.4);
    let sdf = Sdf::Sphere { center: c, radius: r };
    compare(
        "sphere",
        20_000,
        |o, d| sphere_trace(&sdf, o, d, 0.0, f32::INFINITY),
        |o, d| intersect_sphere(c, r, o, d, 0.0, f32::INFINITY),
        // Distance of the ray's line from the centre, minus r (≥ 0 for the
        // whole ray when it starts outside).
        |o, d| {
            let oc = c - o;
            let along = oc.dot(d).max(0.0);
            (oc - d * along).length() - r
        },
        |o, d, t| ((o + d * t - c) / r).dot(d).abs(),
    );
}

#[test]
fn sphere_tracing_matches_ray_box_intersection() {
    let (lo, hi) = (Vec3::new(-1.2, -0.6, -0.9), Vec3::new(0.8, 1.1, 1.3));
    let sdf = Sdf::Box { min: lo, max: hi };
    // The margin: the smallest field value along the ray, sampled finely
    // (for a box, a ray grazes when it passes an edge or face within 10⁻³).
    let closest =
        |o: Vec3, d: Vec3| (0..4000).map(|k| sdf.distance(o + d * (k as f32 * 0.004))).fold(f32::MAX, f32::min);
    compare(
        "box",
        10_000,
        |o, d| sphere_trace(&sdf, o, d, 0.0, f32::INFINITY),
        |o, d| intersect_box(lo, hi, o, d, 0.0, f32::INFINITY),
        |o, d| {
            let m = closest(o, d);
            // A ray that enters the box has a negative minimum: not grazing.
            if m < 0.0 { 1.0 } else { m }
        },
        // The hit face is the one the point lies closest to.
        |o, d, t| {
            let p = o + d * t;
            let gaps = (p - lo).abs().min((hi - p).abs());
            let axis = if gaps.x <= gaps.y && gaps.x <= gaps.z {
                0
            } else if gaps.y <= gaps.z {
                1
            } else {
                2
            };
            d[axis].abs()
        },
    );
}

#[test]
fn sdf_and_analytic_shapes_mix_in_one_bvh() {
    // The same spheres and rotated boxes as analytic shapes and as SDFs, in
    // scenes big enough for the BVH (more than 8 primitives) with a plane:
    // every ray must find the same nearest hit and normal in both.
    let mut analytic = GeometryBuilder::default();
    let mut traced = GeometryBuilder::default();
    let mut s = Sampler::for_pixel(5, 6, 7);
    for i in 0..24 {
        let p = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 10.0;
        if i % 2 == 0 {
            let r = 0.3 + 0.5 * s.next();
            analytic.add(&Shape::sphere(p, r), 0, None);
            traced.add(&Shape::sdf(Sdf::Sphere { center: p, radius: r }), 0, None);
        } else {
            let h = Vec3::new(0.2 + s.next(), 0.2 + s.next(), 0.2 + s.next()) * 0.6;
            let m = Affine3A::from_rotation_translation(Quat::from_rotation_y(s.next() * 3.0), p);
            analytic.add(&Shape::cuboid(-h, h).transformed(m), 0, None);
            traced.add(&Shape::sdf(Sdf::Box { min: -h, max: h }).transformed(m), 0, None);
        }
    }
    analytic.add(&Shape::plane(Vec3::new(0.0, -6.0, 0.0), Vec3::Y), 1, None);
    traced.add(&Shape::sdf(Sdf::Plane { point: Vec3::new(0.0, -6.0, 0.0), normal: Vec3::Y }), 1, None);
    let (analytic, traced) = (analytic.build(), traced.build());
    let (mut agree, mut hits, mut grazing) = (0, 0, 0);
    let n = 5000;
    for _ in 0..n {
        let o = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 14.0;
        let ray = Ray::new(o, uniform_sphere(s.next2()));
        let (a, b) = (analytic.intersect(&ray, f32::INFINITY), traced.intersect(&ray, f32::INFINITY));
        if let Some(a) = a {
            // Hits under 2° are grazing (see `compare`); so are rays that
            // pass the first surface within 10⁻³, where the two may pick
            // different surfaces.
            let cos = analytic.surface(&ray, a).n.dot(ray.dir).abs();
            let tolerance = hit_epsilon(ray.at(a.t)) / cos.max(1e-6) + 1e-4;
            let near_miss = b.is_some_and(|b| b.t < a.t - tolerance);
            if cos < 0.035 || near_miss {
                grazing += 1;
                continue;
            }
        }
        match (a, b) {
            (Some(a), Some(b)) => {
                let cos = analytic.surface(&ray, a).n.dot(ray.dir).abs();
                let tolerance = hit_epsilon(ray.at(a.t)) / cos + 1e-4;
                let (sa, sb) = (analytic.surface(&ray, a), traced.surface(&ray, b));
                // Normals agree but on box edges, where the gradient turns.
                if (a.t - b.t).abs() < tolerance && (sa.n.dot(sb.n) > 0.999 || b.t > 30.0) {
                    agree += 1;
                }
                hits += 1;
                assert_eq!(sa.material, sb.material);
            }
            (None, None) => agree += 1,
            _ => {}
        }
    }
    assert!(grazing * 50 < n, "{grazing} grazing of {n}");
    assert!(agree + grazing >= n - n / 500, "{agree} of {n} agree, {grazing} grazing");
    assert!(hits > n / 3, "{hits} hits");
    // Shadow rays: the SDF geometry blocks the same segments.
    let mut same = 0;
    for _ in 0..n {
        let o = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 14.0;
        let d = uniform_sphere(s.next2());
        same += (analytic.occluded(o, d, 5.0) == traced.occluded(o, d, 5.0)) as usize;
    }
    assert!(same * 1000 >= n * 995, "{same} of {n} shadow rays agree");
}

#[test]
fn gradient_normals_match_analytic_normals() {
    let sphere = Sdf::Sphere { center: Vec3::new(0.2, 0.1, -0.3), radius: 1.2 };
    let mut s = Sampler::for_pixel(1, 1, 1);
    for _ in 0..500 {
        let n = uniform_sphere(s.next2());
        let p = Vec3::new(0.2, 0.1, -0.3) + n * 1.2;
        assert!(sdf_normal(&sphere, p).dot(n) > 0.99999);
    }
    let torus = Sdf::Torus { center: Vec3::ZERO, major_radius: 1.0, minor_radius: 0.25 };
    for _ in 0..500 {
        let (theta, phi) = (s.next() * std::f32::consts::TAU, s.next() * std::f32::consts::TAU);
        let ring = Vec3::new(theta.cos(), 0.0, theta.sin());
        let n = ring * phi.cos() + Vec3::Y * phi.sin();
        let p = ring + n * 0.25;
        assert!(sdf_normal(&torus, p).dot(n) > 0.9999);
    }
}

#[test]
fn rays_along_a_plane_give_up_after_the_step_limit() {
    // A ray skimming a plane approaches it geometrically: it never arrives
    // within ε in MAX_STEPS (512) steps, and is taken to miss (the stated limit).
    let plane = Sdf::Plane { point: Vec3::ZERO, normal: Vec3::Y };
    let d = Vec3::new(1.0, -1e-4, 0.0).normalize();
    assert_eq!(sphere_trace(&plane, Vec3::Y, d, 0.0, f32::INFINITY), f32::INFINITY);
    // Steeper, it arrives.
    let t = sphere_trace(&plane, Vec3::Y, Vec3::new(1.0, -0.5, 0.0).normalize(), 0.0, f32::INFINITY);
    assert!((t - 5f32.sqrt()).abs() < 1e-4, "{t}");
}
