//! The exact primitives against brute-force closest-point distances: the
//! distance to a surface found by searching a parametrisation of it on a
//! fine grid and refining around the best cell, in f64, signed by a plain
//! inside test; and the combinations and transforms against their
//! definitions on random points.

use super::*;
use crate::sampling::Sampler;
use glam::{DVec2, DVec3, Quat};
use std::f64::consts::PI;

/// A surface patch: a map from [0, 1]² to points. The search may step
/// outside [0, 1]²: a patch clamps what must not wrap around.
type Patch<'a> = &'a dyn Fn(DVec2) -> DVec3;

/// min over the patches of |p − patch(u)|: a 48×48 grid, then eight rounds
/// of a 9×9 grid over the 2×2 cells around the best point.
fn closest(p: DVec3, patches: &[Patch]) -> f64 {
    let mut best = f64::INFINITY;
    for patch in patches {
        let dist = |u: DVec2| (patch(u) - p).length();
        let n = 48;
        let mut at = DVec2::ZERO;
        let mut d = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n {
                let u = DVec2::new(i as f64, j as f64) / n as f64;
                let du = dist(u);
                if du < d {
                    (d, at) = (du, u);
                }
            }
        }
        let mut cell = 1.0 / n as f64;
        for _ in 0..8 {
            let centre = at;
            for i in -4..=4 {
                for j in -4..=4 {
                    let u = centre + DVec2::new(i as f64, j as f64) * cell * 0.25;
                    let du = dist(u);
                    if du < d {
                        (d, at) = (du, u);
                    }
                }
            }
            cell *= 0.25;
        }
        best = best.min(d);
    }
    best
}

fn signed(inside: bool, d: f64) -> f64 {
    if inside { -d } else { d }
}

/// The six faces of the box [lo, hi].
fn box_faces(lo: DVec3, hi: DVec3) -> Vec<Box<dyn Fn(DVec2) -> DVec3>> {
    let mut faces: Vec<Box<dyn Fn(DVec2) -> DVec3>> = Vec::new();
    for axis in 0..3 {
        for side in [lo, hi] {
            let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
            faces.push(Box::new(move |u: DVec2| {
                let u = u.clamp(DVec2::ZERO, DVec2::ONE);
                let mut q = DVec3::ZERO;
                q[axis] = side[axis];
                q[a1] = lo[a1] + u.x * (hi[a1] - lo[a1]);
                q[a2] = lo[a2] + u.y * (hi[a2] - lo[a2]);
                q
            }));
        }
    }
    faces
}

fn brute_box(p: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    let faces = box_faces(lo, hi);
    let patches: Vec<Patch> = faces.iter().map(|f| f.as_ref() as Patch).collect();
    let inside = p.cmpgt(lo).all() && p.cmplt(hi).all();
    signed(inside, closest(p, &patches))
}

fn random_point(s: &mut Sampler, scale: f32) -> Vec3 {
    (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * scale
}

fn check(name: &str, sdf: &Sdf, brute: impl Fn(DVec3) -> f64) {
    let mut s = Sampler::for_pixel(11, name.len() as u64, 3);
    let mut worst = 0.0f64;
    for _ in 0..300 {
        let p = random_point(&mut s, 6.0);
        let exact = sdf.distance(p) as f64;
        let expected = brute(p.as_dvec3());
        worst = worst.max((exact - expected).abs());
    }
    assert!(worst < 1e-5 * 50.0, "{name}: worst difference {worst}");
}

#[test]
fn sphere_matches_brute_force() {
    let (c, r) = (Vec3::new(0.3, -0.2, 0.5), 1.3);
    check("sphere", &Sdf::Sphere { center: c, radius: r }, |p| {
        let cd = c.as_dvec3();
        let patch = |u: DVec2| {
            let (theta, phi) = (PI * u.x, 2.0 * PI * u.y);
            cd + r as f64 * DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
        };
        signed((p - cd).length() < r as f64, closest(p, &[&patch]))
    });
}

#[test]
fn box_and_round_box_match_brute_force() {
    let (lo, hi) = (Vec3::new(-1.0, -0.5, -1.5), Vec3::new(1.2, 0.7, 0.4));
    check("box", &Sdf::Box { min: lo, max: hi }, |p| brute_box(p, lo.as_dvec3(), hi.as_dvec3()));
    // A rounded box is the inner box (shrunk by r) grown by r, so its signed
    // distance is the inner box's minus r (Minkowski sum with a ball).
    let r = 0.3;
    check("round box", &Sdf::RoundBox { min: lo, max: hi, rounding: r }, |p| {
        brute_box(p, lo.as_dvec3() + r as f64, hi.as_dvec3() - r as f64) - r as f64
    });
}

#[test]
fn torus_matches_brute_force() {
    let (c, big, small) = (Vec3::new(0.2, 0.1, -0.3), 1.5f32, 0.4f32);
    check("torus", &Sdf::Torus { center: c, major_radius: big, minor_radius: small }, |p| {
        let (cd, big, small) = (c.as_dvec3(), big as f64, small as f64);
        let patch = |u: DVec2| {
            let (theta, phi) = (2.0 * PI * u.x, 2.0 * PI * u.y);
            let ring = big + small * phi.cos();
            cd + DVec3::new(ring * theta.cos(), small * phi.sin(), ring * theta.sin())
        };
        let q = p - cd;
        let inside = ((q.x * q.x + q.z * q.z).sqrt() - big).powi(2) + q.y * q.y < small * small;
        signed(inside, closest(p, &[&patch]))
    });
}

#[test]
fn capsule_matches_brute_force() {
    let (a, b, r) = (Vec3::new(-1.0, 0.2, 0.3), Vec3::new(0.8, -0.4, -0.6), 0.5f32);
    check("capsule", &Sdf::Capsule { a, b, radius: r }, |p| {
        // All points within r of the segment: the distance to the segment,
        // found by search along it, minus r.
        let (ad, bd) = (a.as_dvec3(), b.as_dvec3());
        let seg = |u: DVec2| ad + (bd - ad) * u.x.clamp(0.0, 1.0);
        closest(p, &[&seg]) - r as f64
    });
}

#[test]
fn cylinder_matches_brute_force() {
    let (a, b, r) = (Vec3::new(0.1, -1.0, 0.2), Vec3::new(0.5, 1.2, -0.3), 0.7f32);
    check("cylinder", &Sdf::Cylinder { a, b, radius: r }, |p| {
        let (ad, bd, r) = (a.as_dvec3(), b.as_dvec3(), r as f64);
        let axis = (bd - ad).normalize();
        let e1 = axis.any_orthonormal_vector();
        let e2 = axis.cross(e1);
        let ring = |rho: f64, theta: f64| (e1 * theta.cos() + e2 * theta.sin()) * rho;
        let side = |u: DVec2| ad + (bd - ad) * u.x.clamp(0.0, 1.0) + ring(r, 2.0 * PI * u.y);
        let cap_a = |u: DVec2| ad + ring(r * u.x.clamp(0.0, 1.0), 2.0 * PI * u.y);
        let cap_b = |u: DVec2| bd + ring(r * u.x.clamp(0.0, 1.0), 2.0 * PI * u.y);
        let along = (p - ad).dot(axis);
        let radial = (p - ad - axis * along).length();
        let inside = radial < r && along > 0.0 && along < (bd - ad).length();
        signed(inside, closest(p, &[&side, &cap_a, &cap_b]))
    });
}

#[test]
fn plane_matches_brute_force() {
    let (point, normal) = (Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.3, 1.0, -0.2).normalize());
    check("plane", &Sdf::Plane { point, normal }, |p| {
        // A 40×40 patch of the plane around `point` holds every closest point.
        let n = normal.as_dvec3();
        let e1 = n.any_orthonormal_vector();
        let e2 = n.cross(e1);
        let patch = |u: DVec2| point.as_dvec3() + (e1 * (u.x - 0.5) + e2 * (u.y - 0.5)) * 40.0;
        // (Unclamped: the plane goes on.)
        signed((p - point.as_dvec3()).dot(n) < 0.0, closest(p, &[&patch]))
    });
}

#[test]
fn combinations_follow_their_definitions() {
    let a = Sdf::Sphere { center: Vec3::ZERO, radius: 1.0 };
    let b = Sdf::Box { min: Vec3::splat(0.2), max: Vec3::splat(1.5) };
    let mut s = Sampler::for_pixel(3, 1, 4);
    for _ in 0..200 {
        let p = random_point(&mut s, 4.0);
        let (da, db) = (a.distance(p), b.distance(p));
        assert_eq!(Sdf::Union(vec![a.clone(), b.clone()]).distance(p), da.min(db));
        assert_eq!(Sdf::Intersection(vec![a.clone(), b.clone()]).distance(p), da.max(db));
        assert_eq!(Sdf::Subtraction(vec![a.clone(), b.clone()]).distance(p), da.max(-db));
        let smooth = Sdf::SmoothUnion { children: vec![a.clone(), b.clone()], blend: 0.4 }.distance(p);
        // Never above the union, at most k/4 below it, equal where |a − b| ≥ k.
        assert!(smooth <= da.min(db) && smooth >= da.min(db) - 0.1 - 1e-6);
        if (da - db).abs() >= 0.4 {
            assert_eq!(smooth, da.min(db));
        }
    }
}

#[test]
fn rigid_transforms_keep_distances_and_scales_give_bounds() {
    let inner = Sdf::Box { min: Vec3::new(-1.0, -0.5, -0.25), max: Vec3::new(1.0, 0.5, 0.25) };
    let rotation = Quat::from_rotation_y(0.7) * Quat::from_rotation_x(-0.4);
    let m = Affine3A::from_scale_rotation_translation(Vec3::splat(1.5), rotation, Vec3::new(0.3, 1.0, -2.0));
    let placed = inner.clone().transformed(m);
    let (lo, hi) = placed.bounds().unwrap();
    let mut s = Sampler::for_pixel(8, 8, 8);
    for _ in 0..200 {
        let p = random_point(&mut s, 6.0) + Vec3::new(0.3, 1.0, -2.0);
        // Similarity: distances scale by 1.5 exactly.
        let local = m.inverse().transform_point3(p);
        assert!((placed.distance(p) - 1.5 * inner.distance(local)).abs() < 1e-4);
        // Brute force on the mapped faces: the same distance.
        let faces = box_faces(DVec3::new(-1.0, -0.5, -0.25), DVec3::new(1.0, 0.5, 0.25));
        let md = glam::DAffine3::from_scale_rotation_translation(
            DVec3::splat(1.5),
            rotation.as_dquat(),
            DVec3::new(0.3, 1.0, -2.0),
        );
        let mapped: Vec<Box<dyn Fn(DVec2) -> DVec3>> = faces
            .into_iter()
            .map(|f| Box::new(move |u| md.transform_point3(f(u))) as Box<dyn Fn(DVec2) -> DVec3>)
            .collect();
        let patches: Vec<Patch> = mapped.iter().map(|f| f.as_ref() as Patch).collect();
        let brute = closest(p.as_dvec3(), &patches);
        assert!((placed.distance(p).abs() as f64 - brute).abs() < 1e-4, "{} vs {brute}", placed.distance(p));
        // Inside points lie inside the bounds.
        if placed.distance(p) < 0.0 {
            assert!(p.cmpge(lo).all() && p.cmple(hi).all());
        }
    }
    // Non-uniform scale: a lower bound of the true distance, positive outside.
    let squashed = inner.transformed(Affine3A::from_scale(Vec3::new(3.0, 0.5, 1.0)));
    for _ in 0..200 {
        let p = random_point(&mut s, 8.0);
        let lo = DVec3::new(-3.0, -0.25, -0.25);
        let truth = brute_box(p.as_dvec3(), lo, -lo);
        let d = squashed.distance(p) as f64;
        assert!(d.abs() <= truth.abs() + 1e-5 && d.signum() == truth.signum(), "{d} vs {truth}");
    }
}

#[test]
fn bounds_hold_every_inside_point() {
    let tree = Sdf::SmoothUnion {
        children: vec![
            Sdf::Torus { center: Vec3::new(0.0, 1.0, 0.0), major_radius: 1.0, minor_radius: 0.3 },
            Sdf::Capsule { a: Vec3::ZERO, b: Vec3::new(0.0, 2.0, 0.5), radius: 0.4 },
            Sdf::Subtraction(vec![
                Sdf::Cylinder { a: Vec3::new(1.0, 0.0, 0.0), b: Vec3::new(1.0, 1.5, 0.0), radius: 0.5 },
                Sdf::Sphere { center: Vec3::new(1.0, 1.5, 0.0), radius: 0.4 },
            ]),
        ],
        blend: 0.5,
    };
    let (lo, hi) = tree.bounds().unwrap();
    let mut s = Sampler::for_pixel(2, 2, 2);
    let mut inside = 0;
    for _ in 0..20_000 {
        let p = random_point(&mut s, 5.0) + Vec3::Y;
        if tree.distance(p) <= 0.0 {
            inside += 1;
            assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{p} outside {lo} {hi}");
        }
    }
    assert!(inside > 100);
    let with_plane = Sdf::Union(vec![tree, Sdf::Plane { point: Vec3::ZERO, normal: Vec3::Y }]);
    assert!(with_plane.bounds().is_none());
}

#[test]
fn smallest_singular_value_matches_known_cases() {
    let r = Mat3::from_quat(Quat::from_rotation_z(0.3) * Quat::from_rotation_x(1.1));
    for (scale, expected) in
        [(Vec3::new(2.0, 0.5, 3.0), 0.5), (Vec3::splat(1.7), 1.7), (Vec3::new(1.0, -4.0, 2.0), 1.0)]
    {
        let m = r * Mat3::from_diagonal(scale);
        assert!((smallest_singular_value(m) - expected).abs() < 1e-4, "{scale}");
    }
}

#[test]
fn validation_rejects_bad_parameters() {
    assert!(Sdf::Sphere { center: Vec3::ZERO, radius: -1.0 }.validate().is_err());
    assert!(Sdf::Box { min: Vec3::ONE, max: Vec3::ZERO }.validate().is_err());
    assert!(Sdf::RoundBox { min: Vec3::ZERO, max: Vec3::ONE, rounding: 0.6 }.validate().is_err());
    assert!(Sdf::Cylinder { a: Vec3::ONE, b: Vec3::ONE, radius: 1.0 }.validate().is_err());
    assert!(Sdf::Union(vec![]).validate().is_err());
    assert!(
        Sdf::SmoothUnion { children: vec![Sdf::Sphere { center: Vec3::ZERO, radius: 1.0 }], blend: 0.0 }
            .validate()
            .is_err()
    );
    assert!(Sdf::Sphere { center: Vec3::ZERO, radius: 1.0 }.validate().is_ok());
}
