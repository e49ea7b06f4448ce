//! Volumetric shadows: where along a ray a point emitter is visible.

use super::boundaries::{box_boundaries, plane_boundaries, polygon_boundaries, sphere_boundaries};
use super::{Analytic, MESH_MARCH_STEPS, PointEmitter};
use crate::geometry::Occluder;
use crate::scene::Scene;
use glam::{DAffine3, DMat3, DVec3};

/// Bisection steps refining each boundary found by the march.
const BISECTIONS: usize = 40;

impl Analytic {
    /// Adds the ray parameters where the light's visibility may change.
    pub(super) fn shadow_boundaries(
        &self,
        scene: &Scene,
        e: &PointEmitter,
        o: DVec3,
        d: DVec3,
        range: (f64, f64),
        out: &mut Vec<f64>,
    ) {
        let p = e.position;
        for (occluder, emitter) in scene.geometry.occluders() {
            if emitter == Some(e.light) {
                continue;
            }
            match occluder {
                Occluder::Sphere { center, radius } => {
                    sphere_boundaries(p, center.as_dvec3(), radius as f64, o, d, range, out)
                }
                Occluder::Box { min, max } => box_boundaries(p, min.as_dvec3(), max.as_dvec3(), o, d, range, out),
                Occluder::Quad { corner, edge_u, edge_v } => {
                    let (c, u, v) = (corner.as_dvec3(), edge_u.as_dvec3(), edge_v.as_dvec3());
                    polygon_boundaries(p, &[c, c + u, c + u + v, c + v], o, d, range, out)
                }
                Occluder::Plane { point, normal } => {
                    plane_boundaries(point.as_dvec3(), normal.as_dvec3(), o, d, range, out)
                }
                Occluder::InstancedSphere { local_from_world, center, radius } => {
                    let m = to_f64(&local_from_world);
                    let (lp, lo, ld) = (m.transform_point3(p), m.transform_point3(o), m.transform_vector3(d));
                    sphere_boundaries(lp, center.as_dvec3(), radius as f64, lo, ld, range, out)
                }
                Occluder::InstancedBox { local_from_world, min, max } => {
                    let m = to_f64(&local_from_world);
                    let (lp, lo, ld) = (m.transform_point3(p), m.transform_point3(o), m.transform_vector3(d));
                    box_boundaries(lp, min.as_dvec3(), max.as_dvec3(), lo, ld, range, out)
                }
                // Meshes: below, by marching.
                Occluder::Triangle { .. } => {}
            }
        }
        if self.meshes {
            march_boundaries(scene, e, o, d, range, out);
        }
    }
}

/// Brackets visibility changes with MESH_MARCH_STEPS samples at the middles
/// of equal steps, then bisects each bracket. A shadow thinner than a step
/// can be missed; every boundary found is exact to 2^−40 of a step.
fn march_boundaries(scene: &Scene, e: &PointEmitter, o: DVec3, d: DVec3, (t0, t1): (f64, f64), out: &mut Vec<f64>) {
    let n = MESH_MARCH_STEPS;
    let dt = (t1 - t0) / n as f64;
    let sees = |t: f64| visible(scene, o + d * t, e);
    let mut prev_t = t0 + 0.5 * dt;
    let mut prev = sees(prev_t);
    for i in 1..n {
        let t = t0 + (i as f64 + 0.5) * dt;
        let v = sees(t);
        if v != prev {
            let (mut lo, mut hi) = (prev_t, t);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if sees(mid) == prev {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            out.push(0.5 * (lo + hi));
        }
        prev = v;
        prev_t = t;
    }
}

/// Whether `x` sees the emitter: one shadow ray, stopping short of it.
pub(super) fn visible(scene: &Scene, x: DVec3, e: &PointEmitter) -> bool {
    let to = e.position - x;
    let dist = to.length();
    let reach = (dist - e.gap) * (1.0 - 1e-4);
    if reach.is_nan() || reach <= 0.0 {
        return true;
    }
    !scene.geometry.occluded(x.as_vec3(), (to / dist).as_vec3(), reach as f32)
}

fn to_f64(m: &glam::Affine3A) -> DAffine3 {
    DAffine3 {
        matrix3: DMat3::from_cols(
            m.matrix3.x_axis.as_dvec3(),
            m.matrix3.y_axis.as_dvec3(),
            m.matrix3.z_axis.as_dvec3(),
        ),
        translation: m.translation.as_dvec3(),
    }
}
