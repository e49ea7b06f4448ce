//! Volumetric shadows: where along a ray a point emitter is visible.
//!
//! Without meshes, each occluder's shadow along the ray is found exactly
//! and without shadow rays (see blockers.rs): [`Analytic::shadow_intervals`].
//! With meshes, whose triangles are too many to treat one by one, the
//! analytic occluders' boundaries are joined by those found by a coarse
//! march refined by bisection, and every piece between boundaries is
//! classified by one shadow ray ([`visible`]).

use super::{Analytic, MESH_MARCH_STEPS, PointEmitter};
use crate::scene::Scene;
use glam::DVec3;

/// Bisection steps refining each boundary found by the march.
const BISECTIONS: usize = 40;

impl Analytic {
    /// The shadowed parts of the ray o + t d, t in `range`, for the emitter
    /// `e`, as sorted disjoint intervals in `out`, from the analytic
    /// occluders only: for each occluder whose bounding sphere the ray's
    /// shadow segments can reach, its candidate boundaries, then one
    /// segment–shape test at the middle of each piece between them.
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

    /// Adds the ray parameters where the light's visibility may change
    /// (scenes with meshes): every occluder's candidates, and the march's.
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
        for b in &self.blockers {
            if b.emitter == Some(e.light) || b.misses(p, o, d, range) {
                continue;
            }
            b.boundaries(p, o, d, range, out);
        }
        march_boundaries(scene, e, o, d, range, out);
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
    !scene.geometry().occluded(x.as_vec3(), (to / dist).as_vec3(), reach as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::analytic::{AnalyticOptions, Emission, LightQuadrature};
    use crate::prelude::*;
    use glam::{Affine3A, Quat};

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
        // Every analytic occluder kind: sphere, box, quad, plane, an
        // instanced (non-uniformly scaled, rotated) sphere and box.
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
            .light(Light::point(vec3(0.2, 4.0, 0.3), Rgb::splat(10.0)))
            .build()
            .unwrap();
        let options = AnalyticOptions { shadows: true, light_steps: 16, quadrature: LightQuadrature::Gauss };
        let analytic = Analytic::new(&scene, options).unwrap();
        assert!(!analytic.meshes && analytic.blockers.len() == 6);
        let mut state = 11;
        let (mut cands, mut shadow) = (Vec::new(), Vec::new());
        let (mut checked, mut shadowed, mut wrong) = (0, 0, 0);
        for _ in 0..3000 {
            let mut r = || uniform(&mut state);
            // Lights and ray origins anywhere above the floor, rays any way.
            let light = DVec3::new(4.0 * r() - 2.0, 2.5 + 2.0 * r(), 4.0 * r() - 2.0);
            let o = DVec3::new(8.0 * r() - 4.0, 0.1 + 3.0 * r(), 8.0 * r() - 4.0);
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
        // A shadow ray in f32 may differ within ~1e-6 of an occluder's surface.
        assert!(wrong as f64 <= 1e-4 * checked as f64, "{wrong} of {checked}");
    }
}
