//! Sphere tracing (Hart, "Sphere Tracing: a geometric method for the
//! antialiased ray tracing of implicit surfaces", The Visual Computer 1996):
//! from a point where the field reads d, no surface lies within |d|, so the
//! ray may advance by |d|. Stepping by |d| rather than d also finds the far
//! side of a solid from a ray that starts inside it, as the analytic shapes do.

use super::Sdf;
use glam::Vec3;

/// Most steps per trace. A ray still short of a surface after this many is
/// taken to miss: only rays grazing a surface for a long way (a plane seen
/// edge-on) get there.
pub const MAX_STEPS: u32 = 512;

/// The hit epsilon at `p`: a trace stops when |d(p)| < 10⁻⁵·(1 + |p|∞). It
/// grows with |p| because f32 spacing does, and it is ten times smaller than
/// the offset by which shadow rays leave surfaces (`offset_origin`,
/// 10⁻⁴·(1 + |p|∞)), so a shadow ray never hits the surface it leaves.
#[inline]
pub fn hit_epsilon(p: Vec3) -> f32 {
    1e-5 * (1.0 + p.abs().max_element())
}

/// The first t in [t0, t1] where the ray o + t·d meets the surface of `sdf`,
/// or ∞. `d` need not be unit length.
pub fn sphere_trace(sdf: &Sdf, o: Vec3, d: Vec3, t0: f32, t1: f32) -> f32 {
    let inv_len = d.length().recip();
    if t0.is_nan() || t1.is_nan() || t0 > t1 || !inv_len.is_finite() {
        return f32::INFINITY;
    }
    let mut t = t0;
    for _ in 0..MAX_STEPS {
        let p = o + d * t;
        let dist = sdf.distance(p).abs();
        if dist < hit_epsilon(p) {
            return t;
        }
        t += dist * inv_len;
        if t > t1 {
            break;
        }
    }
    f32::INFINITY
}

/// The unit outward normal at `p`: the gradient of the field by central
/// differences on a tetrahedron (four evaluations; Quilez,
/// iquilezles.org/articles/normalsSDF): Σ kᵢ·d(p + h·kᵢ) over the corners kᵢ
/// of (±1, ±1, ±1) with an even number of minus signs, which is 4h·∇d + O(h³).
/// h = 10⁻⁴·(1 + |p|∞), above f32 noise and below the scale of features.
pub fn sdf_normal(sdf: &Sdf, p: Vec3) -> Vec3 {
    let h = 1e-4 * (1.0 + p.abs().max_element());
    const K: [Vec3; 4] =
        [Vec3::new(1.0, -1.0, -1.0), Vec3::new(-1.0, -1.0, 1.0), Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, 1.0)];
    let g = K.iter().fold(Vec3::ZERO, |g, &k| g + k * sdf.distance(p + k * h));
    let n = g.normalize_or_zero();
    if n == Vec3::ZERO { Vec3::Y } else { n }
}
