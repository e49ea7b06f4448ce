//! Volumetric shadows: where along a ray a point emitter is visible.
//!
//! Each occluder's shadow along the ray is found exactly and without
//! shadow rays, whatever the arrangement (the light or the camera inside a
//! box, a sphere or a closed mesh, between planes): spheres, boxes, quads
//! and planes by their boundaries and one segment test per piece
//! (blockers.rs), triangles by clipping the ray against their shadow
//! volumes (triangles.rs). The union is [`Analytic::shadow_intervals`].

use super::{Analytic, PointEmitter};
use glam::DVec3;

impl Analytic {
    /// The shadowed parts of the ray o + t d, t in `range`, for the emitter
    /// `e`, as sorted disjoint intervals in `out`: for each occluder other
    /// than a triangle whose bounding sphere the ray's shadow segments can
    /// reach, its candidate boundaries, then one segment–surface test at the
    /// middle of each piece between them; for each triangle those segments
    /// can reach, its clipped interval.
    pub(super) fn shadow_intervals(
        &self,
        e: &PointEmitter,
        o: DVec3,
        d: DVec3,
        range: (f64, f64),
        cands: &mut Vec<f64>,
        out: &mut Vec<(f64, f64)>,
    ) {
        out.clear();
        let p = e.position;
        for b in &self.blockers {
            if b.emitter == Some(e.light) || b.misses(p, o, d, range) {
                continue;
            }
            cands.clear();
            cands.push(range.0);
            cands.push(range.1);
            b.boundaries(p, o, d, range, cands);
            cands.sort_unstable_by(f64::total_cmp);
            let mut run: Option<f64> = None;
            for w in cands.windows(2) {
                let (t0, t1) = (w[0], w[1]);
                if t1 <= t0 {
                    continue;
                }
                let x = o + d * (0.5 * (t0 + t1));
                let shadowed = segment_end(x, e).is_some_and(|y| b.blocks(x, y));
                match (shadowed, run) {
                    (true, None) => run = Some(t0),
                    (false, Some(s)) => {
                        out.push((s, t0));
                        run = None;
                    }
                    _ => {}
                }
            }
            if let Some(s) = run {
                out.push((s, range.1));
            }
        }
        self.meshes.shadows(p, o, d, range, out);
        // Union: sort by start, merge overlaps.
        out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut k = 0;
        for i in 0..out.len() {
            if k > 0 && out[i].0 <= out[k - 1].1 {
                out[k - 1].1 = out[k - 1].1.max(out[i].1);
            } else {
                out[k] = out[i];
                k += 1;
            }
        }
        out.truncate(k);
    }
}

/// Whether ray parameter t lies inside one of the sorted disjoint intervals.
pub(super) fn in_intervals(intervals: &[(f64, f64)], t: f64) -> bool {
    intervals.iter().any(|&(a, b)| t > a && t < b)
}

/// The end of the shadow segment from `x` toward the emitter: short of it by
/// its gap (a sphere light's radius) and a relative 1e-4, as the shadow rays
/// of the other integrators; None when x is that close to it.
fn segment_end(x: DVec3, e: &PointEmitter) -> Option<DVec3> {
    let to = e.position - x;
    let dist = to.length();
    let reach = (dist - e.gap) * (1.0 - 1e-4);
    (reach > 0.0).then(|| x + to * (reach / dist))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::analytic::{AnalyticOptions, Emission, LightQuadrature};
    use crate::prelude::*;
    use crate::scene::Scene;
    use glam::{Affine3A, Quat};

    /// Whether `x` sees the emitter: one shadow ray through the BVH,
    /// stopping short of it as [`segment_end`] does (the independent answer).
    fn visible(scene: &Scene, x: DVec3, e: &PointEmitter) -> bool {
        let to = e.position - x;
        let dist = to.length();
        let reach = (dist - e.gap) * (1.0 - 1e-4);
        if reach.is_nan() || reach <= 0.0 {
            return true;
        }
        !scene.geometry().occluded(x.as_vec3(), (to / dist).as_vec3(), reach as f32)
    }

    /// A cube of twelve triangles, centre `c`, half side `s`.
    fn mesh_cube(c: Vec3, s: f32) -> Shape {
        let positions: Vec<Vec3> = (0..8)
            .map(|i| {
                c + s * vec3(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                )
            })
            .collect();
        let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
        let triangles = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
        Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }
    }

    /// SplitMix64 in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn exact_shadow_intervals_agree_with_shadow_rays_through_the_bvh() {
        // Every occluder kind: sphere, box, quad, plane, an instanced
        // (non-uniformly scaled, rotated) sphere and box, a closed mesh; the
        // lights anywhere above the floor, inside the shapes too.
        let tilt = Quat::from_rotation_y(0.5) * Quat::from_rotation_x(0.3);
        let scene = SceneBuilder::new()
            .size(8, 8)
            .camera(Camera::look_at(vec3(0.0, 2.0, -7.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 45.0))
            .medium(Medium::homogeneous(Rgb::splat(0.01), Rgb::splat(0.1), 0.0))
            .material("m", Material::diffuse(Rgb::splat(0.5)))
            .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
            .object(Shape::sphere(vec3(-1.5, 1.0, 0.5), 0.7), "m")
            .object(Shape::cuboid(vec3(0.6, 0.0, -0.4), vec3(1.4, 0.9, 0.6)), "m")
            .object(Shape::quad(vec3(-0.5, 2.2, -0.5), vec3(1.0, 0.0, 0.2), vec3(0.1, 0.3, 1.0)), "m")
            .object_transformed(
                Shape::sphere(Vec3::ZERO, 0.5),
                Affine3A::from_scale_rotation_translation(vec3(1.5, 0.6, 1.0), tilt, vec3(0.5, 1.2, 2.0)),
                "m",
            )
            .object_transformed(
                Shape::cuboid(Vec3::splat(-0.4), Vec3::splat(0.4)),
                Affine3A::from_rotation_translation(tilt, vec3(-0.3, 0.6, -1.6)),
                "m",
            )
            .object(mesh_cube(vec3(1.2, 2.6, 1.0), 0.5), "m")
            .light(Light::point(vec3(0.2, 4.0, 0.3), Rgb::splat(10.0)))
            .build()
            .unwrap();
        let options = AnalyticOptions { shadows: true, light_steps: 16, quadrature: LightQuadrature::Gauss };
        let analytic = Analytic::new(&scene, options).unwrap();
        assert!(!analytic.meshes.is_empty() && analytic.blockers.len() == 6);
        let mut state = 11;
        let (mut cands, mut shadow) = (Vec::new(), Vec::new());
        let (mut checked, mut shadowed, mut wrong) = (0, 0, 0);
        // Points inside each closed shape: sphere, box, instanced sphere and
        // box, mesh.
        let inside = [(-1.5, 1.0, 0.5), (1.0, 0.45, 0.1), (0.5, 1.2, 2.0), (-0.3, 0.6, -1.6), (1.2, 2.6, 1.0)];
        for i in 0..3000 {
            let mut r = || uniform(&mut state);
            let jitter = 0.2 * DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5);
            let near = |k: usize| {
                let (x, y, z) = inside[k % inside.len()];
                DVec3::new(x, y, z) + jitter
            };
            // Lights and ray origins anywhere above the floor, half the
            // lights and a third of the origins inside a shape; rays any way.
            let light =
                if i % 2 == 0 { near(i / 2) } else { DVec3::new(4.0 * r() - 2.0, 0.05 + 4.0 * r(), 4.0 * r() - 2.0) };
            let o = if i % 3 == 0 {
                near(i / 3 + 2)
            } else {
                DVec3::new(8.0 * r() - 4.0, 0.1 + 3.0 * r(), 8.0 * r() - 4.0)
            };
            let d = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            let e = PointEmitter {
                position: light,
                intensity: DVec3::ONE,
                emission: Emission::Isotropic,
                light: 0,
                gap: 0.0,
            };
            let range = (0.0, 10.0);
            analytic.shadow_intervals(&e, o, d, range, &mut cands, &mut shadow);
            for _ in 0..100 {
                let t = 10.0 * uniform(&mut state);
                // Not within f32's reach of a boundary.
                if shadow.iter().any(|&(a, b)| (t - a).abs() < 1e-4 || (t - b).abs() < 1e-4) {
                    continue;
                }
                let x = o + d * t;
                let exact = !in_intervals(&shadow, t);
                let ray = visible(&scene, x, &e);
                checked += 1;
                shadowed += (!ray) as u32;
                wrong += (exact != ray) as u32;
            }
        }
        println!("exact shadow intervals: {checked} points, {shadowed} in shadow, {wrong} disagree with shadow rays");
        assert!(shadowed > checked / 10);
        // A shadow ray in f32 may differ within ~1e-6 of an occluder's
        // surface, and both stop 1e-4 of the distance short of the light: a
        // light that close to a surface (19 of the 1500 here, at random
        // points) lights or not a few points beyond the boundaries.
        assert!(wrong as f64 <= 1e-4 * checked as f64, "{wrong} of {checked}");
    }
}
