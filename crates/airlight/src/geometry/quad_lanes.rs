//! A small scene's quads tested all at once, in structure-of-arrays lanes,
//! instead of through the BVH, for single rays. (Plain arrays that the
//! compiler vectorises; `lanes.rs` holds the packet traversal's explicit
//! lane types.)
//!
//! A room of a handful of quads and boxes (the Cornell box) has too few
//! primitives for a tree to pay: most rays pass through the boxes of most
//! nodes, and the traversal's bookkeeping costs more than the tests it
//! spares. Eight quads side by side take one pass of straight-line
//! arithmetic that the compiler turns into SIMD. Each lane does exactly the
//! arithmetic of [`intersect_quad`](super::shape::intersect_quad), in the
//! same order, so the hits are the same bit for bit as testing the quads
//! one by one: images do not change, only the time.

use super::small::LaneGroup;
use glam::Vec3;

/// Quads per group: two SSE registers per operation, enough independent
/// work to hide the division's latency.
const LANES: usize = 8;

/// Eight quads, each field one array across them. Unused lanes have a zero
/// normal, which the parallel-ray test rejects.
#[derive(Clone, Debug)]
pub(super) struct Group {
    corner: [[f32; LANES]; 3],
    edge_u: [[f32; LANES]; 3],
    edge_v: [[f32; LANES]; 3],
    /// edge_u × edge_v, and 1/|edge_u × edge_v|².
    normal: [[f32; LANES]; 3],
    inv_nn: [f32; LANES],
    /// The record each lane is, u32::MAX for an unused lane.
    id: [u32; LANES],
}

/// A scene's quads (record index, corner, edge_u, edge_v) in groups of
/// [`LANES`], in the order given.
#[derive(Clone, Debug)]
pub(super) struct QuadLanes {
    groups: Vec<Group>,
}

impl QuadLanes {
    pub fn new(quads: &[(u32, Vec3, Vec3, Vec3)]) -> Self {
        let groups = quads
            .chunks(LANES)
            .map(|chunk| {
                let mut g = Group {
                    corner: [[0.0; LANES]; 3],
                    edge_u: [[0.0; LANES]; 3],
                    edge_v: [[0.0; LANES]; 3],
                    normal: [[0.0; LANES]; 3],
                    inv_nn: [0.0; LANES],
                    id: [u32::MAX; LANES],
                };
                for (k, &(id, corner, edge_u, edge_v)) in chunk.iter().enumerate() {
                    let n = edge_u.cross(edge_v);
                    for axis in 0..3 {
                        g.corner[axis][k] = corner[axis];
                        g.edge_u[axis][k] = edge_u[axis];
                        g.edge_v[axis][k] = edge_v[axis];
                        g.normal[axis][k] = n[axis];
                    }
                    g.inv_nn[k] = 1.0 / n.length_squared();
                    g.id[k] = id;
                }
                g
            })
            .collect();
        QuadLanes { groups }
    }

    /// Calls `found(t, id)`, group by group, for the nearest of the quads
    /// the ray `o + t·d` meets at 0 < t < tmax (each at that distance, if
    /// several are): the nearest hit and, of equal ones, any tie-break the
    /// caller applies come out as from every hit.
    #[inline(always)]
    pub fn for_each_nearest(&self, o: Vec3, d: Vec3, tmax: f32, mut found: impl FnMut(f32, u32)) {
        for g in &self.groups {
            let t = distances(g, o, d, tmax);
            let nearest = t.iter().fold(f32::INFINITY, |a, &b| a.min(b));
            if nearest < tmax {
                for (&t, &id) in t.iter().zip(&g.id) {
                    if t == nearest {
                        found(t, id);
                    }
                }
            }
        }
    }

    /// Whether any quad meets the ray at 0 < t < tmax.
    #[inline(always)]
    pub fn any_hit(&self, o: Vec3, d: Vec3, tmax: f32) -> bool {
        // A plain loop, no closure: all of it inlines into the caller, and
        // so runs on the instructions it is compiled for (small.rs).
        for g in &self.groups {
            if any_below(distances(g, o, d, tmax), tmax) {
                return true;
            }
        }
        false
    }

    /// The groups, for the packet tests (`small/packets.rs`).
    pub fn groups(&self) -> &[Group] {
        &self.groups
    }
}

/// Whether any lane's distance is below `tmax`: a loop without branches
/// (and without a closure, which could be compiled apart from the caller).
#[inline(always)]
pub(super) fn any_below<const N: usize>(distances: [f32; N], tmax: f32) -> bool {
    let mut hit = false;
    for t in distances {
        hit |= t < tmax;
    }
    hit
}

/// Each lane's hit distance in (0, tmax), or infinity: `intersect_quad`'s
/// operations lane by lane, without branches (a miss selects infinity).
#[inline(always)]
fn distances(g: &Group, o: Vec3, d: Vec3, tmax: f32) -> [f32; LANES] {
    let mut out = [f32::INFINITY; LANES];
    for (k, t) in out.iter_mut().enumerate() {
        *t = distance(g, k, o, d, tmax);
    }
    out
}

/// Lane `k`'s hit distance in (0, tmax), or infinity: `intersect_quad`'s
/// operations in its order, without branches (a miss selects infinity).
/// Inlined into a loop over the lanes (one ray, eight quads) or over rays
/// (eight rays, one quad), it is straight-line code the compiler vectorises.
// `&` rather than `&&` and range `contains`: no branches.
#[allow(clippy::manual_range_contains)]
#[inline(always)]
fn distance(g: &Group, k: usize, o: Vec3, d: Vec3, tmax: f32) -> f32 {
    let [nx, ny, nz] = [g.normal[0][k], g.normal[1][k], g.normal[2][k]];
    let [cx, cy, cz] = [g.corner[0][k], g.corner[1][k], g.corner[2][k]];
    let [ux, uy, uz] = [g.edge_u[0][k], g.edge_u[1][k], g.edge_u[2][k]];
    let [vx, vy, vz] = [g.edge_v[0][k], g.edge_v[1][k], g.edge_v[2][k]];
    // n·d, n·(corner − o)
    let denom = (nx * d.x) + (ny * d.y) + (nz * d.z);
    let t = ((nx * (cx - o.x)) + (ny * (cy - o.y)) + (nz * (cz - o.z))) / denom;
    // rel = o + d·t − corner
    let (rx, ry, rz) = ((o.x + d.x * t) - cx, (o.y + d.y * t) - cy, (o.z + d.z * t) - cz);
    // (rel × edge_v)·n and (edge_u × rel)·n
    let (ax, ay, az) = (ry * vz - vy * rz, rz * vx - vz * rx, rx * vy - vx * ry);
    let (bx, by, bz) = (uy * rz - ry * uz, uz * rx - rz * ux, ux * ry - rx * uy);
    let alpha = ((ax * nx) + (ay * ny) + (az * nz)) * g.inv_nn[k];
    let beta = ((bx * nx) + (by * ny) + (bz * nz)) * g.inv_nn[k];
    // (A NaN denominator fails here, and its NaN t fails in the original.)
    let hit = (denom.abs() >= 1e-20)
        & (t > 0.0)
        & (t < tmax)
        & (alpha >= 0.0)
        & (alpha <= 1.0)
        & (beta >= 0.0)
        & (beta <= 1.0);
    if hit { t } else { f32::INFINITY }
}

impl LaneGroup for Group {
    #[inline(always)]
    fn ids(&self) -> &[u32] {
        &self.id
    }

    #[inline(always)]
    fn distance(&self, k: usize, o: Vec3, d: Vec3, tmax: f32) -> f32 {
        distance(self, k, o, d, tmax)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::intersect_quad;
    use crate::sampling::{Sampler, uniform_sphere};

    #[test]
    fn lanes_give_the_one_by_one_distances_bit_for_bit() {
        // Eleven random quads (a full group and a partial one), random rays
        // from inside their bounds: every lane's hit against intersect_quad.
        let mut s = Sampler::for_pixel(5, 6, 7);
        let mut v = || Vec3::new(s.next(), s.next(), s.next()) - 0.5;
        let quads: Vec<(u32, Vec3, Vec3, Vec3)> = (0..11).map(|i| (i, v() * 4.0, v() * 3.0, v() * 3.0)).collect();
        let lanes = QuadLanes::new(&quads);
        let mut s = Sampler::for_pixel(8, 9, 10);
        let mut hits = 0;
        for i in 0..20_000 {
            let o = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 4.0;
            let d = uniform_sphere(s.next2());
            let tmax = if i % 2 == 0 { f32::INFINITY } else { 3.0 * s.next() };
            let want: Vec<f32> = quads.iter().map(|&(_, c, u, w)| intersect_quad(c, u, w, o, d, 0.0, tmax)).collect();
            for g in &lanes.groups {
                let got = distances(g, o, d, tmax);
                for (k, &id) in g.id.iter().enumerate() {
                    let want = want.get(id as usize).copied().unwrap_or(f32::INFINITY);
                    assert_eq!(got[k].to_bits(), want.to_bits(), "ray {o} {d} {tmax} quad {id}");
                }
            }
            // The nearest per group: no quad of the group nearer.
            let mut nearest = Vec::new();
            lanes.for_each_nearest(o, d, tmax, |t, id| nearest.push((t, id)));
            for (t, id) in nearest {
                assert_eq!(t, want[id as usize]);
                let group = id as usize / LANES;
                assert!(want[group * LANES..].iter().take(LANES).all(|&w| w >= t));
            }
            assert_eq!(lanes.any_hit(o, d, tmax), want.iter().any(|t| t.is_finite()));
            hits += want.iter().filter(|t| t.is_finite()).count();
        }
        assert!(hits > 2000, "hits {hits}");
    }
}
