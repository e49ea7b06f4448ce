//! Form factors between patches, and their visibility.
//!
//! The form factor from a patch i to a patch j is Madams's
//!
//!   F_ij = cos φi · cos φj / (π r²) · A_j,
//!
//! the differential-area-to-area form factor at i's centre (Cohen and
//! Wallace, "Radiosity and Realistic Image Synthesis", 1993, §4): the
//! fraction of the light leaving a small area at i that reaches j, and, by
//! reciprocity, the irradiance at i from j per unit radiosity of j:
//! E_i = Σ_j F_ij B_j. It holds when r is large beside the patches; for
//! patches closer than [`NEAR`] × (sum of their radii), [`form_factor`]
//! uses the exact point-to-polygon factor ([`point_polygon_factor`])
//! averaged over 6×6 equal-area points, symmetrised over both directions.
//! Visibility multiplies it: one ray between the centres for distant pairs,
//! the fraction of [`NEAR_RAYS`] unblocked rays between points of both
//! patches for near ones; both directions test the same segments, so
//! A_i F_ij = A_j F_ji holds for what the rays see too.

use super::hierarchy::mix;
use super::patches::Patch;
use crate::geometry::{Geometry, offset_origin};
use glam::Vec3;
use std::f32::consts::PI;

/// Pairs closer than NEAR × (radius_i + radius_j) are integrated over
/// points of the patches instead of taken at their centres.
pub const NEAR: f32 = 2.0;
/// Rays for the visibility of a near pair.
pub const NEAR_RAYS: usize = 4;
const QUAD_N: usize = 6;

/// The point-to-area form factor cos φi cos φj / (π r²) · A_j from the point
/// `x` with normal `n` to a small area `area` at `y` with normal `m`; zero
/// when either faces away.
#[inline]
pub fn point_factor(x: Vec3, n: Vec3, y: Vec3, m: Vec3, area: f32) -> f32 {
    let d = y - x;
    let r2 = d.length_squared();
    let ci = n.dot(d);
    let cj = -m.dot(d);
    if ci <= 0.0 || cj <= 0.0 || r2 == 0.0 {
        return 0.0;
    }
    ci * cj / (PI * r2 * r2) * area
}

fn quad_points(p: &Patch) -> ([Vec3; QUAD_N * QUAD_N], usize) {
    let mut v = Vec::with_capacity(QUAD_N * QUAD_N);
    p.shape.quadrature_points(QUAD_N, &mut v);
    let mut out = [p.center; QUAD_N * QUAD_N];
    out[..v.len()].copy_from_slice(&v);
    (out, v.len())
}

/// Whether a pair of patches is near enough to be integrated over points.
#[inline]
pub fn is_near(a: &Patch, b: &Patch) -> bool {
    a.center.distance(b.center) < NEAR * (a.radius + b.radius)
}

/// The exact unoccluded form factor from a point `x` with normal `n` to the
/// flat polygon `poly` whose front side faces along `m`, by Lambert's
/// contour formula (Cohen and Wallace 1993, §4.5; Baum, Rushmeier and
/// Winget 1989):
///
///   F = 1/(2π) · Σ_k γ_k · n · (R_k × R_{k+1}) / |R_k × R_{k+1}|,
///
/// R_k = v_k − x and γ_k the angle between R_k and R_{k+1}, after clipping
/// the polygon to the half space in front of x. Zero when x is behind the
/// polygon's front side.
pub fn point_polygon_factor(x: Vec3, n: Vec3, poly: &[Vec3], m: Vec3) -> f32 {
    if m.dot(x - poly[0]) <= 0.0 {
        return 0.0;
    }
    // Clip to n·(v − x) ≥ 0 (Sutherland–Hodgman against one plane).
    let mut clipped = [Vec3::ZERO; 8];
    let mut count = 0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (da, db) = (n.dot(a - x), n.dot(b - x));
        if da >= 0.0 {
            clipped[count] = a;
            count += 1;
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped[count] = a + (b - a) * (da / (da - db));
            count += 1;
        }
    }
    if count < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..count {
        let (a, b) = (clipped[k] - x, clipped[(k + 1) % count] - x);
        let c = a.cross(b);
        let len = c.length();
        if len <= 1e-12 * a.length() * b.length() {
            continue;
        }
        let gamma = len.atan2(a.dot(b));
        sum += gamma * n.dot(c) / len;
    }
    (sum / (2.0 * PI)).abs()
}

fn polygon(p: &Patch) -> ([Vec3; 4], usize) {
    let s = &p.shape;
    if s.triangle {
        ([s.origin, s.origin + s.e1, s.origin + s.e2, Vec3::ZERO], 3)
    } else {
        ([s.origin, s.origin + s.e1, s.origin + s.e1 + s.e2, s.origin + s.e2], 4)
    }
}

/// The unoccluded form factor F_ij from patch i to patch j (see the module
/// documentation): the point formula at i's centre when far; when near,
/// the mean of the two one-sided estimates F_ij and (A_j/A_i)·F_ji, each the
/// exact point-to-polygon factor averaged over 6×6 equal-area points of the
/// receiver. One side's integrand may jump (a floor patch half under a
/// block sees the block's face from one half only), where midpoint
/// quadrature errs by a few per cent; averaging halves that and makes the
/// near factors exactly reciprocal, A_i F_ij = A_j F_ji.
pub fn form_factor(pi: &Patch, pj: &Patch) -> f32 {
    let d = pj.center - pi.center;
    // All of j behind i, or i behind j: nothing passes.
    if pi.normal.dot(d) + pj.radius <= 0.0 || -pj.normal.dot(d) + pi.radius <= 0.0 {
        return 0.0;
    }
    if !is_near(pi, pj) {
        return point_factor(pi.center, pi.normal, pj.center, pj.normal, pj.area);
    }
    let forward = one_sided_factor(pi, pj);
    let backward = one_sided_factor(pj, pi);
    0.5 * (forward + backward * pj.area / pi.area)
}

fn one_sided_factor(pi: &Patch, pj: &Patch) -> f32 {
    let (a, na) = quad_points(pi);
    let (poly, count) = polygon(pj);
    // The exact factor is to the patch's polygon; scale to its stated area
    // (they differ only for the tangent pieces of a sphere).
    let poly_area = if pj.shape.triangle { 0.5 } else { 1.0 } * pj.shape.e1.cross(pj.shape.e2).length();
    let scale = if poly_area > 0.0 { pj.area / poly_area } else { 0.0 };
    let mut sum = 0.0;
    for x in &a[..na] {
        sum += point_polygon_factor(*x, pi.normal, &poly[..count], pj.normal);
    }
    scale * sum / na as f32
}

/// Whether the segment between `x` (normal `n`) and `y` (normal `m`) is
/// free, each end lifted off its surface toward the other.
#[inline]
pub fn segment_clear(geometry: &Geometry, x: Vec3, n: Vec3, y: Vec3, m: Vec3) -> bool {
    let a = offset_origin(x, n, y - x);
    let b = offset_origin(y, m, x - y);
    let d = b - a;
    let len = d.length();
    if len == 0.0 {
        return true;
    }
    !geometry.occluded(a, d / len, len * (1.0 - 1e-4))
}

/// The visible fraction between patches i and j: one centre-to-centre ray
/// when far, [`NEAR_RAYS`] rays between points of both when near. Symmetric
/// in (i, j): both orders test the same segments.
pub fn visibility(geometry: &Geometry, patches: &[Patch], i: usize, j: usize, seed: u64) -> f32 {
    let (lo, hi) = (i.min(j), i.max(j));
    let (a, b) = (&patches[lo], &patches[hi]);
    if !is_near(a, b) {
        return segment_clear(geometry, a.center, a.normal, b.center, b.normal) as u32 as f32;
    }
    let key = mix(seed ^ mix(((lo as u64) << 32) | hi as u64));
    let mut clear = 0;
    for k in 0..NEAR_RAYS {
        let h = mix(key.wrapping_add(k as u64));
        let u = |bits: u64| (bits & 0xffff) as f32 / 65536.0;
        // Stratified in s on each patch, hashed in t.
        let s = (k as f32 + u(h)) / NEAR_RAYS as f32;
        let x = a.shape.point(s, u(h >> 16));
        let s2 = ((k * 3 + 1) % NEAR_RAYS) as f32 + u(h >> 32);
        let y = b.shape.point(s2 / NEAR_RAYS as f32, u(h >> 48));
        clear += segment_clear(geometry, x, a.normal, y, b.normal) as u32;
    }
    clear as f32 / NEAR_RAYS as f32
}
