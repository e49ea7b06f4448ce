//! Ray–shape intersections against a brute-force oracle (marching the ray in
//! f64 and bisecting a sign change of the shape's inside test), and the BVH
//! against testing every primitive.

use airlight::geometry::{
    GeometryBuilder, Ray, Shape, intersect_box, intersect_quad, intersect_sphere, intersect_triangle, triangle_blocks,
};
use airlight::sampling::{Sampler, uniform_sphere};
use glam::{Affine3A, DVec3, Quat, Vec3};

const T_MAX: f64 = 12.0;
const STEPS: usize = 24_000;

/// First t in (0, T_MAX) where `inside` changes, found by a fine march and
/// bisection; None if it never changes.
fn march_first_crossing(o: DVec3, d: DVec3, inside: impl Fn(DVec3) -> bool) -> Option<f64> {
    let dt = T_MAX / STEPS as f64;
    let start = inside(o + d * 1e-9);
    for i in 1..=STEPS {
        let t = i as f64 * dt;
        if inside(o + d * t) != start {
            let (mut lo, mut hi) = (t - dt, t);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if inside(o + d * mid) == start { lo = mid } else { hi = mid }
            }
            return Some(0.5 * (lo + hi));
        }
    }
    None
}

/// First t where the segment crosses a plane at a point `accept` takes.
fn plane_crossing(o: DVec3, d: DVec3, point: DVec3, n: DVec3, accept: impl Fn(DVec3) -> bool) -> Option<f64> {
    let t = n.dot(point - o) / n.dot(d);
    (t > 0.0 && t < T_MAX && accept(o + d * t)).then_some(t)
}

/// Coordinates (α, β) of `p − corner` in the basis (u, v), by the normal
/// equations of least squares, in f64.
fn coords(p: DVec3, corner: DVec3, u: DVec3, v: DVec3) -> (f64, f64) {
    let r = p - corner;
    let (uu, uv, vv) = (u.dot(u), u.dot(v), v.dot(v));
    let (ru, rv) = (r.dot(u), r.dot(v));
    let det = uu * vv - uv * uv;
    ((ru * vv - rv * uv) / det, (rv * uu - ru * uv) / det)
}

struct Case {
    hits_agree: usize,
    misses_agree: usize,
    disagree: usize,
    worst: f64,
}

fn check(name: &str, rays: usize, shape_t: impl Fn(Vec3, Vec3) -> f32, oracle: impl Fn(DVec3, DVec3) -> Option<f64>) {
    let mut s = Sampler::for_pixel(42, name.len() as u64, 0);
    let mut c = Case { hits_agree: 0, misses_agree: 0, disagree: 0, worst: 0.0 };
    for _ in 0..rays {
        let o = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 6.0;
        // Aim near the origin, so most rays hit.
        let target = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 2.5;
        let d = if s.next() < 0.2 { uniform_sphere(s.next2()) } else { (target - o).normalize() };
        let t = shape_t(o, d);
        let expected = oracle(o.as_dvec3(), d.as_dvec3());
        match (t.is_finite(), expected) {
            (true, Some(e)) => {
                let err = (t as f64 - e).abs();
                c.worst = c.worst.max(err);
                if err < 1e-3 { c.hits_agree += 1 } else { c.disagree += 1 }
            }
            (false, None) => c.misses_agree += 1,
            _ => c.disagree += 1,
        }
    }
    // Grazing rays whose chord is shorter than the march step may disagree.
    assert!(c.disagree * 500 <= rays, "{name}: {} of {rays} rays disagree", c.disagree);
    // (The triangle, the smallest target, takes about a fifth of the rays.)
    assert!(c.hits_agree > rays / 10 && c.misses_agree > rays / 20, "{name}: too few hits or misses to mean much");
    assert!(c.worst < 1e-3, "{name}: worst distance error {}", c.worst);
}

#[test]
fn sphere_matches_oracle() {
    let (c, r) = (Vec3::new(0.3, -0.2, 0.1), 1.1f32);
    check(
        "sphere",
        3000,
        |o, d| intersect_sphere(c, r, o, d, 0.0, T_MAX as f32),
        |o, d| march_first_crossing(o, d, |p| (p - c.as_dvec3()).length_squared() < (r as f64).powi(2)),
    );
}

#[test]
fn box_matches_oracle() {
    let (lo, hi) = (Vec3::new(-1.0, -0.5, -0.7), Vec3::new(0.8, 1.2, 0.6));
    check(
        "box",
        3000,
        |o, d| intersect_box(lo, hi, o, d, 0.0, T_MAX as f32),
        |o, d| march_first_crossing(o, d, |p| p.cmpgt(lo.as_dvec3()).all() && p.cmplt(hi.as_dvec3()).all()),
    );
}

#[test]
fn quad_matches_oracle() {
    let (corner, u, v) = (Vec3::new(-1.0, -0.3, 0.2), Vec3::new(2.0, 0.3, 0.1), Vec3::new(-0.2, 1.5, 0.9));
    let (cd, ud, vd) = (corner.as_dvec3(), u.as_dvec3(), v.as_dvec3());
    check(
        "quad",
        3000,
        |o, d| intersect_quad(corner, u, v, o, d, 0.0, T_MAX as f32),
        |o, d| {
            plane_crossing(o, d, cd, ud.cross(vd), |p| {
                let (a, b) = coords(p, cd, ud, vd);
                (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)
            })
        },
    );
}

#[test]
fn triangle_matches_oracle() {
    let (a, b, c) = (Vec3::new(-1.2, -0.5, 0.0), Vec3::new(1.0, -0.8, 0.4), Vec3::new(0.1, 1.3, -0.3));
    let (ad, e1, e2) = (a.as_dvec3(), (b - a).as_dvec3(), (c - a).as_dvec3());
    check(
        "triangle",
        3000,
        |o, d| intersect_triangle(a, b - a, c - a, o, d, 0.0, T_MAX as f32),
        |o, d| {
            plane_crossing(o, d, ad, e1.cross(e2), |p| {
                let (u, v) = coords(p, ad, e1, e2);
                u >= 0.0 && v >= 0.0 && u + v <= 1.0
            })
        },
    );
}

#[test]
fn triangle_blocks_where_the_hit_lies_before_the_segments_end() {
    // The shadow test without a division against the hit distance, on
    // segments that end before, near and after the triangle, from both of
    // its sides. They may differ only in a rounding's last bit, which
    // random rays do not meet.
    let (a, b, c) = (Vec3::new(-1.2, -0.5, 0.0), Vec3::new(1.0, -0.8, 0.4), Vec3::new(0.1, 1.3, -0.3));
    let mut s = Sampler::for_pixel(11, 0, 0);
    let (mut blocked, mut open) = (0, 0);
    for _ in 0..200_000 {
        let o = uniform_sphere(s.next2()) * (1.0 + 3.0 * s.next());
        let target = Vec3::new(2.4 * s.next() - 1.2, 2.4 * s.next() - 1.0, 0.8 * s.next() - 0.4);
        let d = (target - o).normalize();
        let tmax = (target - o).length() * 2.0 * s.next();
        let expected = intersect_triangle(a, b - a, c - a, o, d, 0.0, tmax) < tmax;
        assert_eq!(triangle_blocks(a, b - a, c - a, o, d, tmax), expected, "{o} {d} {tmax}");
        if expected { blocked += 1 } else { open += 1 }
    }
    assert!(blocked > 20_000 && open > 20_000, "{blocked} blocked, {open} open");
}

/// A shape added to a Geometry, intersected through the BVH.
fn through_geometry(shape: Shape) -> impl Fn(Vec3, Vec3) -> f32 {
    let mut builder = GeometryBuilder::default();
    builder.add(&shape, 0, None);
    let geometry = builder.build();
    move |o, d| geometry.intersect(&Ray::new(o, d), T_MAX as f32).map_or(f32::INFINITY, |h| h.t)
}

#[test]
fn transformed_sphere_and_box_match_oracle() {
    // An ellipsoid: a unit sphere scaled (1.4, 0.6, 1), rotated, moved.
    let m = Affine3A::from_scale_rotation_translation(
        Vec3::new(1.4, 0.6, 1.0),
        Quat::from_rotation_z(0.5) * Quat::from_rotation_y(0.9) * Quat::from_rotation_x(0.3),
        Vec3::new(0.2, 0.1, -0.3),
    );
    let inv = glam::Mat4::from(m.inverse()).as_dmat4();
    let local = |p: DVec3| inv.transform_point3(p);
    check("ellipsoid", 2000, through_geometry(Shape::sphere(Vec3::ZERO, 1.0).transformed(m)), |o, d| {
        march_first_crossing(o, d, |p| local(p).length_squared() < 1.0)
    });
    check(
        "rotated box",
        2000,
        through_geometry(Shape::cuboid(Vec3::splat(-0.8), Vec3::splat(0.8)).transformed(m)),
        |o, d| march_first_crossing(o, d, |p| local(p).abs().max_element() < 0.8),
    );
    // A uniformly scaled, rotated sphere stays a sphere of the scaled radius.
    let similar = Affine3A::from_scale_rotation_translation(Vec3::splat(2.0), Quat::from_rotation_y(1.0), Vec3::X);
    assert_eq!(Shape::sphere(Vec3::ZERO, 0.5).transformed(similar), Shape::sphere(Vec3::X, 1.0));
}

#[test]
fn bvh_agrees_with_brute_force_on_a_triangle_soup() {
    let mut s = Sampler::for_pixel(9, 9, 9);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..20_000u32 {
        let c = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 10.0;
        for _ in 0..3 {
            positions.push(c + (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 0.6);
        }
        triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let mut builder = GeometryBuilder::default();
    builder.add(&Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }, 0, None);
    builder.add(&Shape::sphere(Vec3::new(1.0, 2.0, 0.0), 1.5), 0, None);
    builder.add(&Shape::plane(Vec3::new(0.0, -5.5, 0.0), Vec3::Y), 0, None);
    let geometry = builder.build();
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..5000 {
        let o = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 14.0;
        let d = uniform_sphere(s.next2());
        let ray = Ray::new(o, d);
        let tmax = if s.next() < 0.5 { f32::INFINITY } else { 4.0 * s.next() };
        let fast = geometry.intersect(&ray, tmax);
        let slow = geometry.intersect_brute_force(&ray, tmax);
        assert_eq!(fast.map(|h| h.t), slow.map(|h| h.t), "ray {o} {d}");
        assert_eq!(geometry.occluded(o, d, tmax), slow.is_some());
        if slow.is_some() { hits += 1 } else { misses += 1 }
    }
    assert!(hits > 500 && misses > 500, "hits {hits} misses {misses}");
}

#[test]
fn axis_aligned_rays_find_flat_quads_through_the_bvh() {
    // Flat bounding boxes and directions with −0 components (−Vec3::Y is
    // (−0, −1, −0)) once made the BVH miss what brute force hits.
    let mut builder = GeometryBuilder::default();
    for i in 0..7 {
        let y = i as f32 * 1.5;
        builder.add(
            &Shape::quad(Vec3::new(-1.0, y, -1.0), Vec3::new(0.0, 0.0, 2.0), Vec3::new(2.0, 0.0, 0.0)),
            0,
            None,
        );
        builder.add(
            &Shape::quad(Vec3::new(3.0 + y, -1.0, -1.0), Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 0.0, 2.0)),
            0,
            None,
        );
    }
    let geometry = builder.build();
    for dir in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z, -Vec3::Y, -Vec3::X] {
        for origin in
            [Vec3::new(0.2, 4.0, 0.1), Vec3::new(-5.0, 0.3, 0.2), Vec3::new(20.0, 0.1, -0.4), Vec3::new(0.0, 20.0, 0.0)]
        {
            let ray = Ray::new(origin, dir);
            assert_eq!(geometry.intersect(&ray, 100.0), geometry.intersect_brute_force(&ray, 100.0), "{origin} {dir}");
        }
    }
    let down = Ray::new(Vec3::new(0.2, 4.0, 0.1), -Vec3::Y);
    assert!(geometry.intersect(&down, 100.0).is_some());
}

#[test]
fn bvh_agrees_with_brute_force_in_the_lamp_room() {
    // A real scene: glTF meshes, boxes and quads sharing edges and faces.
    bvh_agrees_with_brute_force_in("gltf_lamp_room_fog.toml", 5000);
}

#[test]
fn bvh_agrees_with_brute_force_in_the_cornell_box() {
    // Eight primitives (six quads and two rotated boxes): a small scene,
    // whose single rays test the quads in SIMD lanes instead of the BVH.
    bvh_agrees_with_brute_force_in("compare_cornell.toml", 8000);
}

/// Random rays through a scene file's geometry: the BVH's nearest hit
/// distance and occlusion against testing every primitive.
fn bvh_agrees_with_brute_force_in(scene: &str, min_hits: u32) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(scene);
    let scene = airlight::SceneFile::load(&path).expect("scene loads").scene;
    let geometry = scene.geometry();
    let (lo, hi) = geometry.bounds().expect("bounded geometry");
    let mut s = Sampler::for_pixel(3, 1, 4);
    let mut hits = 0;
    for _ in 0..20_000 {
        let o = lo + (hi - lo) * Vec3::new(s.next(), s.next(), s.next());
        let d = uniform_sphere(s.next2());
        let ray = Ray::new(o, d);
        let tmax = if s.next() < 0.5 { f32::INFINITY } else { (hi - lo).length() * s.next() };
        let fast = geometry.intersect(&ray, tmax);
        let slow = geometry.intersect_brute_force(&ray, tmax);
        // The same distance and the same primitive: of equal distances (a
        // shared edge, coinciding faces) both name the lowest index.
        assert_eq!(fast, slow, "ray {o} {d}");
        assert_eq!(geometry.occluded(o, d, tmax), slow.is_some(), "ray {o} {d}");
        hits += slow.is_some() as u32;
    }
    assert!(hits > min_hits, "hits {hits}");
}
