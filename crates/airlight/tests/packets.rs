//! Packet traversal (`Geometry::intersect_packet`, `occluded_packet`)
//! against the one-ray queries and testing every primitive: the same hit
//! (distance and primitive) and the same blocked-or-not for every ray, with
//! every lane width the processor has (sixteen AVX-512 lanes, eight AVX
//! lanes, four SSE lanes, the portable scalar lanes), for coherent camera
//! rays of which some miss, for shadow rays of which some start blocked by
//! a plane or end before any surface, and for incoherent random rays.

use airlight::geometry::{Geometry, GeometryBuilder, Hit, LaneWidth, Ray, Segment, Shape};
use airlight::sampling::{Sampler, uniform_sphere};
use glam::{Vec2, Vec3};

/// A bumpy UV sphere of 2·n² triangles (the benchmark's mesh, smaller).
fn bumpy_sphere(n: u32) -> Shape {
    let mut positions = Vec::new();
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..=n {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
            let dir = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            positions.push(dir * (1.0 + 0.08 * (5.0 * theta).sin() * (7.0 * phi).sin()));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            let b = a + n + 1;
            triangles.push([a, b, a + 1]);
            triangles.push([a + 1, b, b + 1]);
        }
    }
    Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }
}

/// The mesh on a floor plane, with a sphere and a box beside it (leaves
/// holding other primitives than triangles take the general path).
fn mesh_scene() -> Geometry {
    let mut b = GeometryBuilder::default();
    b.add(&bumpy_sphere(60), 0, None);
    b.add(&Shape::Plane { point: Vec3::new(0.0, -1.2, 0.0), normal: Vec3::Y }, 1, None);
    b.add(&Shape::Sphere { center: Vec3::new(1.6, -0.7, 0.3), radius: 0.5 }, 2, None);
    b.add(&Shape::Box { min: Vec3::new(-2.2, -1.2, -0.3), max: Vec3::new(-1.4, -0.2, 0.5) }, 3, None);
    b.build()
}

/// The lane widths this processor runs; the others are named as skipped,
/// so that a pass on an older processor says what it left out.
fn lane_widths() -> Vec<LaneWidth> {
    let (runs, skipped): (Vec<_>, Vec<_>) = LaneWidth::ALL.into_iter().partition(|l| l.available());
    for lanes in skipped {
        eprintln!("skipped: {lanes:?} lanes (this processor does not run them)");
    }
    runs
}

/// Camera rays from a pinhole through a w×h grid, in 8×8 blocks (the order
/// packets want); the view is wider than the scene, so some rays miss.
fn camera_rays(eye: Vec3, w: u32, h: u32, fov: f32) -> Vec<Ray> {
    let forward = (-eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let scale = (fov.to_radians() * 0.5).tan();
    let mut rays = Vec::new();
    for by in (0..h).step_by(8) {
        for bx in (0..w).step_by(8) {
            for y in by..(by + 8).min(h) {
                for x in bx..(bx + 8).min(w) {
                    let film = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32) * 2.0 - 1.0;
                    let d = forward + right * (film.x * scale) + up * (-film.y * scale);
                    rays.push(Ray::new(eye, d.normalize()));
                }
            }
        }
    }
    rays
}

/// Every lane width's packet answers (of those this processor has) against
/// the one-ray queries (and, for `check_brute` rays, against testing every
/// primitive). Returns the number of hits and of blocked shadow rays.
fn agree(geometry: &Geometry, rays: &[Ray], tmax: f32, shadow: &[Segment], check_brute: usize) -> (usize, usize) {
    let single: Vec<Option<Hit>> = rays.iter().map(|r| geometry.intersect(r, tmax)).collect();
    for (i, r) in rays.iter().enumerate().step_by((rays.len() / check_brute.max(1)).max(1)) {
        assert_eq!(single[i], geometry.intersect_brute_force(r, tmax), "ray {i}: {r:?}");
    }
    // One ray at a time on each lane width: the same answers.
    for lanes in lane_widths() {
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(geometry.intersect_on(lanes, r, tmax), single[i], "ray {i} (one, {lanes:?} lanes): {r:?}");
        }
    }
    for lanes in lane_widths() {
        let mut packets = vec![None; rays.len()];
        geometry.intersect_packet_on(lanes, rays, tmax, &mut packets);
        for i in 0..rays.len() {
            assert_eq!(packets[i], single[i], "ray {i} ({lanes:?} lanes): {:?}", rays[i]);
        }
    }
    let mut widest = vec![None; rays.len()];
    geometry.intersect_packet(rays, tmax, &mut widest);
    assert_eq!(widest, single);
    let hits = single.iter().filter(|h| h.is_some()).count();
    let single: Vec<bool> = shadow.iter().map(|s| geometry.occluded(s.origin, s.dir, s.tmax)).collect();
    for lanes in lane_widths() {
        let one: Vec<bool> = shadow.iter().map(|s| geometry.occluded_on(lanes, s.origin, s.dir, s.tmax)).collect();
        assert_eq!(one, single, "one ray at a time, {lanes:?} lanes");
    }
    for lanes in lane_widths() {
        let mut packets = vec![false; shadow.len()];
        geometry.occluded_packet_on(lanes, shadow, &mut packets);
        assert_eq!(packets, single, "{lanes:?} lanes");
    }
    let mut widest = vec![false; shadow.len()];
    geometry.occluded_packet(shadow, &mut widest);
    assert_eq!(widest, single);
    (hits, single.iter().filter(|&&b| b).count())
}

/// Shadow segments from each hit toward `light`, stopping short of it;
/// every third one stops at a tenth of the way (mostly unblocked).
fn shadow_segments(geometry: &Geometry, rays: &[Ray], light: Vec3) -> Vec<Segment> {
    let mut out = Vec::new();
    for (i, ray) in rays.iter().enumerate() {
        let Some(hit) = geometry.intersect(ray, f32::INFINITY) else { continue };
        let s = geometry.surface(ray, hit);
        let origin = airlight::geometry::offset_origin(s.p, s.n, light - s.p);
        let to = light - origin;
        let length = to.length() * if i % 3 == 0 { 0.1 } else { 0.9999 };
        out.push(Segment { origin, dir: to / to.length(), tmax: length });
    }
    out
}

#[test]
fn packets_agree_with_single_rays_on_a_mesh() {
    let geometry = mesh_scene();
    let rays = camera_rays(Vec3::new(0.3, 0.8, -4.0), 96, 72, 60.0);
    let tmax = f32::INFINITY;
    let shadow = shadow_segments(&geometry, &rays, Vec3::new(2.5, 3.0, -2.0));
    let (hits, blocked) = agree(&geometry, &rays, tmax, &shadow, 500);
    // Some rays miss everything (above the horizon), most hit; some shadow
    // rays are blocked, most not.
    assert!(hits > rays.len() / 2 && hits < rays.len(), "{hits} of {}", rays.len());
    assert!(blocked > shadow.len() / 20 && blocked < shadow.len() / 2, "{blocked} of {}", shadow.len());
    // A finite tmax that ends some rays before the mesh.
    let (short_hits, _) = agree(&geometry, &rays, 3.6, &[], 200);
    assert!(short_hits > 0 && short_hits < hits, "{short_hits}");
    // A light below the floor: the plane blocks every shadow ray before
    // the traversal starts, and a packet with no open ray traverses nothing.
    let under = shadow_segments(&geometry, &rays, Vec3::new(0.0, -5.0, 0.0));
    let mut blocked = vec![false; under.len()];
    geometry.occluded_packet(&under, &mut blocked);
    let single: Vec<bool> = under.iter().map(|s| geometry.occluded(s.origin, s.dir, s.tmax)).collect();
    assert_eq!(blocked, single);
}

#[test]
fn packets_agree_whether_leaves_meet_few_rays_or_many() {
    // A leaf that few of a packet's rays enter is tested ray by ray, one
    // that many enter triangle by triangle across the rays: a fine mesh
    // (about eight triangles a pixel) and a coarse one (about fifty pixels
    // a triangle), which took both ways (63,848 leaves ray by ray and
    // 43,057 across rays, counted once). Both give the one-ray hits.
    for n in [240, 12] {
        let mut b = GeometryBuilder::default();
        b.add(&bumpy_sphere(n), 0, None);
        let geometry = b.build();
        let rays = camera_rays(Vec3::new(0.3, 0.8, -4.0), 160, 120, 40.0);
        let shadow = shadow_segments(&geometry, &rays, Vec3::new(2.5, 3.0, -2.0));
        let (hits, blocked) = agree(&geometry, &rays, f32::INFINITY, &shadow, 300);
        assert!(hits > rays.len() / 4 && blocked > shadow.len() / 20, "{n}: {hits} hits, {blocked} blocked");
    }
}

#[test]
fn a_hit_exactly_at_tmax_is_past_the_open_segment_in_packets_too() {
    // A wall of triangles at z = 1 and rays along +z from z = 0 that end
    // at t = 1 exactly: no ray hits it, whichever way it is traced (each
    // ray alone or a packet), and with a longer segment every ray does.
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..=20u32 {
        for j in 0..=20u32 {
            positions.push(Vec3::new(i as f32 * 0.25 - 2.5, j as f32 * 0.25 - 2.5, 1.0));
        }
    }
    for i in 0..20u32 {
        for j in 0..20u32 {
            let a = i * 21 + j;
            triangles.push([a, a + 21, a + 1]);
            triangles.push([a + 1, a + 21, a + 22]);
        }
    }
    let mut b = GeometryBuilder::default();
    b.add(&Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }, 0, None);
    let geometry = b.build();
    let rays: Vec<Ray> =
        (0..64).map(|i| Ray::new(Vec3::new(0.0625 * (i % 8) as f32, 0.0625 * (i / 8) as f32, 0.0), Vec3::Z)).collect();
    for (tmax, expected) in [(1.0, 0), (1.5, rays.len())] {
        let single = rays.iter().filter(|r| geometry.intersect(r, tmax).is_some()).count();
        assert_eq!(single, expected, "one at a time, tmax {tmax}");
        let (hits, _) = agree(&geometry, &rays, tmax, &[], 64);
        assert_eq!(hits, expected, "tmax {tmax}");
    }
}

#[test]
fn packets_of_mixed_octants_and_odd_sizes_agree() {
    let geometry = mesh_scene();
    // From inside the mesh's bounds, a camera whose view spans all eight
    // octants; the counts leave partial packets and groups of one to three.
    for (w, h) in [(37, 23), (5, 3), (1, 1), (64, 1)] {
        let rays = camera_rays(Vec3::new(0.05, 0.02, -0.1), w, h, 150.0);
        let shadow = shadow_segments(&geometry, &rays, Vec3::new(0.0, 0.1, 0.0));
        agree(&geometry, &rays, f32::INFINITY, &shadow, 50);
    }
    // Axis-aligned directions with ±0 components.
    let rays: Vec<Ray> = (0..40)
        .map(|i| {
            let dir = [Vec3::X, Vec3::NEG_Y, -Vec3::Z, Vec3::Z][i % 4];
            Ray::new(Vec3::new(-3.0 + 0.15 * i as f32, 0.1, -3.0) * if i % 4 == 0 { 1.0 } else { 0.3 }, dir)
        })
        .collect();
    agree(&geometry, &rays, f32::INFINITY, &[], 40);
}

#[test]
fn packets_of_random_rays_agree_in_the_lamp_room() {
    // Incoherent rays through a real scene: glTF meshes, boxes and quads
    // sharing edges and faces (ties at equal distances name the lowest
    // primitive in both queries).
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/gltf_lamp_room_fog.toml");
    let scene = airlight::SceneFile::load(&path).expect("scene loads").scene;
    let geometry = scene.geometry();
    let (lo, hi) = geometry.bounds().expect("bounded geometry");
    let mut s = Sampler::for_pixel(5, 2, 7);
    let mut rays = Vec::new();
    let mut shadow = Vec::new();
    for _ in 0..6000 {
        let o = lo + (hi - lo) * Vec3::new(s.next(), s.next(), s.next());
        let d = uniform_sphere(s.next2());
        rays.push(Ray::new(o, d));
        shadow.push(Segment { origin: o, dir: d, tmax: (hi - lo).length() * s.next() });
    }
    let (hits, blocked) = agree(geometry, &rays, f32::INFINITY, &shadow, 6000);
    assert!(hits > 1200 && blocked > 1000, "{hits} hits, {blocked} blocked");
}

/// A small scene (the Cornell box: five quads, two turned boxes and its
/// light's quad) takes its packets through the quads' and boxes' lanes,
/// eight rays against one primitive at a time, not through the tree: the
/// one-ray answers still, for camera rays from outside the room and from
/// inside it, for shadow rays toward the light, and, with a bound of each
/// ray's own, for `intersect_each`, on that scene and on one of a quad alone.
#[test]
fn packets_agree_in_a_small_scene() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell_box.toml");
    let scene = airlight::SceneFile::load(&path).expect("scene loads").scene;
    let geometry = scene.geometry();
    let light = Vec3::new(2.78, 5.4, 2.8);
    let mut total = (0, 0);
    let centre = Vec3::new(2.78, 2.73, 2.8);
    for (eye, fov) in [(Vec3::new(2.78, 2.73, -8.0), 40.0), (Vec3::new(2.0, 2.0, 1.0), 150.0)] {
        // Toward the room's centre (`camera_rays` looks at the origin).
        let rays: Vec<Ray> =
            camera_rays(eye - centre, 45, 37, fov).into_iter().map(|r| Ray::new(r.origin + centre, r.dir)).collect();
        let shadow = shadow_segments(geometry, &rays, light);
        let (hits, blocked) = agree(geometry, &rays, f32::INFINITY, &shadow, 200);
        total = (total.0 + hits, total.1 + blocked);
    }
    assert!(total.0 > 2500 && total.1 > 100, "{total:?}");
    let mut quad = GeometryBuilder::default();
    quad.add(
        &Shape::Quad { corner: Vec3::new(-1.0, -1.0, 2.0), edge_u: Vec3::X * 2.0, edge_v: Vec3::Y * 2.0 },
        0,
        None,
    );
    let quad = quad.build();
    for (geometry, origin) in [(geometry, Vec3::new(2.0, 2.0, 1.0)), (&quad, Vec3::new(0.2, 0.1, 1.5))] {
        let mut s = Sampler::for_pixel(9, 9, 9);
        let rays: Vec<Ray> = (0..301).map(|_| Ray::new(origin, uniform_sphere(s.next2()))).collect();
        let tmax: Vec<f32> = rays.iter().map(|_| if s.next() < 0.2 { f32::INFINITY } else { 8.0 * s.next() }).collect();
        let mut each = vec![None; rays.len()];
        geometry.intersect_each(&rays, &tmax, &mut each);
        let single: Vec<Option<Hit>> = rays.iter().zip(&tmax).map(|(r, &t)| geometry.intersect(r, t)).collect();
        assert_eq!(each, single);
        assert!(single.iter().filter(|h| h.is_some()).count() > 20);
    }
}
