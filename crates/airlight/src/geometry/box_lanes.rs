//! A small scene's boxes, turned or not, tested four at a time in
//! structure-of-arrays lanes, as `quad_lanes.rs` tests its quads.
//!
//! One by one, a turned box costs a branch on its kind, a pointer to its
//! instance, the ray's transform into its space, three divisions and a
//! slab test with data-dependent branches; the Cornell box's two blocks took
//! 8% of a path-traced render so. Here the transform and the slabs run for
//! every box of a group at once, without branches. Each lane does the
//! arithmetic of `Prim::Instance` and [`intersect_box`](super::shape::intersect_box)
//! in the same order (glam's `Affine3A::transform_point3`:
//! ((x·oₓ + y·o_y) + z·o_z) + translation; glam's `min`, `max` and
//! `max_element` as the same comparisons, which treat a NaN as they do), so
//! the distances are the same bit for bit and images do not change.

use super::quad_lanes::any_below;
use super::small::LaneGroup;
use glam::{Affine3A, Vec3};

/// Boxes per group: one SSE register per operation.
const LANES: usize = 4;

/// Four boxes, each field one array across them. A box in world space is
/// not turned: its lane takes the ray as it is. (The identity transform
/// would turn a direction's −0 into +0 and so flip an infinite slab
/// distance; the test shows that the answer is the same, but taking the
/// ray as it is needs no such argument.) Unused lanes have id u32::MAX and
/// always miss.
#[derive(Clone, Debug)]
pub(super) struct Group {
    /// Columns of the linear part of local_from_world, then its translation.
    axes: [[[f32; LANES]; 3]; 3],
    translation: [[f32; LANES]; 3],
    min: [[f32; LANES]; 3],
    max: [[f32; LANES]; 3],
    turned: [bool; LANES],
    id: [u32; LANES],
}

/// A scene's boxes (record index, local_from_world if turned, local min,
/// local max), in groups of [`LANES`], in the order given.
#[derive(Clone, Debug)]
pub(super) struct BoxLanes {
    groups: Vec<Group>,
}

impl BoxLanes {
    pub fn new(boxes: &[(u32, Option<Affine3A>, Vec3, Vec3)]) -> Self {
        let groups = boxes
            .chunks(LANES)
            .map(|chunk| {
                let mut g = Group {
                    axes: [[[0.0; LANES]; 3]; 3],
                    translation: [[0.0; LANES]; 3],
                    min: [[0.0; LANES]; 3],
                    max: [[0.0; LANES]; 3],
                    turned: [false; LANES],
                    id: [u32::MAX; LANES],
                };
                for (k, &(id, turn, min, max)) in chunk.iter().enumerate() {
                    let local_from_world = turn.unwrap_or(Affine3A::IDENTITY);
                    let m = local_from_world.matrix3;
                    for (column, axis) in [m.x_axis, m.y_axis, m.z_axis].into_iter().enumerate() {
                        for row in 0..3 {
                            g.axes[column][row][k] = axis[row];
                        }
                    }
                    for row in 0..3 {
                        g.translation[row][k] = local_from_world.translation[row];
                        g.min[row][k] = min[row];
                        g.max[row][k] = max[row];
                    }
                    g.turned[k] = turn.is_some();
                    g.id[k] = id;
                }
                g
            })
            .collect();
        BoxLanes { groups }
    }

    /// Calls `found(t, id)` for every box the ray `o + t·d` meets at
    /// 0 < t < tmax, with its distance, in the order given: the caller
    /// keeps the nearest (and breaks its ties).
    #[inline(always)]
    pub fn for_each_hit(&self, o: Vec3, d: Vec3, tmax: f32, mut found: impl FnMut(f32, u32)) {
        for g in &self.groups {
            let t = distances(g, o, d, tmax);
            for (&t, &id) in t.iter().zip(&g.id) {
                if t < tmax {
                    found(t, id);
                }
            }
        }
    }

    /// Whether any box meets the ray at 0 < t < tmax.
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

/// Each lane's hit distance in (0, tmax), or infinity: the ray taken into
/// the box's space and its slab test, lane by lane, without branches.
#[inline(always)]
fn distances(g: &Group, o: Vec3, d: Vec3, tmax: f32) -> [f32; LANES] {
    let mut out = [f32::INFINITY; LANES];
    for (k, t) in out.iter_mut().enumerate() {
        *t = distance(g, k, o, d, tmax);
    }
    out
}

/// Lane `k`'s hit distance in (0, tmax), or infinity: the ray taken into
/// the box's space and its slab test, without branches. Inlined into a loop
/// over the lanes (one ray, four boxes) or over rays (eight rays, one box),
/// it is straight-line code the compiler vectorises.
// `&` rather than `&&`: no branches.
#[inline(always)]
fn distance(g: &Group, k: usize, o: Vec3, d: Vec3, tmax: f32) -> f32 {
    // glam's comparisons, NaN and all: a NaN on the left yields the right.
    let lesser = |a: f32, b: f32| if a < b { a } else { b };
    let greater = |a: f32, b: f32| if a > b { a } else { b };
    let mut nearest = [0.0f32; 3];
    let mut farthest = [0.0f32; 3];
    for row in 0..3 {
        let [x, y, z] = [g.axes[0][row][k], g.axes[1][row][k], g.axes[2][row][k]];
        let turned_o = ((x * o.x + y * o.y) + z * o.z) + g.translation[row][k];
        let turned_d = (x * d.x + y * d.y) + z * d.z;
        let local_o = if g.turned[k] { turned_o } else { o[row] };
        let local_d = if g.turned[k] { turned_d } else { d[row] };
        let inv = 1.0 / local_d;
        let t_a = (g.min[row][k] - local_o) * inv;
        let t_b = (g.max[row][k] - local_o) * inv;
        nearest[row] = lesser(t_a, t_b);
        farthest[row] = greater(t_a, t_b);
    }
    // max_element and min_element: x against (y against z).
    let near = greater(nearest[0], greater(nearest[1], nearest[2]));
    let far = lesser(farthest[0], lesser(farthest[1], farthest[2]));
    let near_in = (near > 0.0) & (near < tmax);
    let far_in = (far > 0.0) & (far < tmax);
    let t = if near > far {
        f32::INFINITY
    } else if near_in {
        near
    } else if far_in {
        far
    } else {
        f32::INFINITY
    };
    if g.id[k] == u32::MAX { f32::INFINITY } else { t }
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
    use crate::geometry::records::{Instance, Prim};
    use crate::sampling::{Sampler, uniform_sphere};
    use glam::{Mat3, Quat};
    use obvhs::aabb::Aabb;

    #[test]
    fn lanes_give_the_one_by_one_distances_bit_for_bit() {
        // Seven boxes, turned and not (a full group and a partial one),
        // and rays from around them, some along the axes (zero direction
        // components, of either sign) and some from on a face: every lane
        // against the record's own test.
        let mut s = Sampler::for_pixel(3, 4, 5);
        let mut v = move || Vec3::new(s.next(), s.next(), s.next()) - 0.5;
        let mut boxes = Vec::new();
        let mut prims = Vec::new();
        for i in 0..7u32 {
            let (min, max) = (v() - 0.6, v() + 0.6);
            if i % 3 == 0 {
                boxes.push((i, None, min, max));
                prims.push(Prim::Box { min, max });
            } else {
                let axis = v().normalize();
                let world_from_local =
                    Affine3A::from_rotation_translation(Quat::from_axis_angle(axis, 2.0 * v().x), v() * 3.0);
                let local_from_world = world_from_local.inverse();
                boxes.push((i, Some(local_from_world), min, max));
                prims.push(Prim::Instance(Box::new(Instance {
                    prim: Prim::Box { min, max },
                    local_from_world,
                    normal_to_world: Mat3::IDENTITY,
                    bounds: Aabb::empty(),
                })));
            }
        }
        let lanes = BoxLanes::new(&boxes);
        let mut s = Sampler::for_pixel(6, 7, 8);
        let mut rays = Vec::new();
        for i in 0..20_000 {
            let o = (Vec3::new(s.next(), s.next(), s.next()) - 0.5) * 5.0;
            let tmax = if i % 2 == 0 { f32::INFINITY } else { 4.0 * s.next() };
            rays.push((o, uniform_sphere(s.next2()), tmax));
        }
        // From on the planes of the world boxes' faces, along another axis:
        // the direction's component across the face is +0 or −0, so a slab
        // distance is 0·∞, a NaN, whose handling must match.
        for &(_, _, min, max) in boxes.iter().filter(|b| b.1.is_none()) {
            for face in 0..3 {
                for plane in [min[face], max[face]] {
                    for along in (0..3).filter(|&a| a != face) {
                        for (sign, zero, outside) in (0..8).map(|k| (1 - 2 * (k & 1), k & 2 == 0, k & 4 == 0)) {
                            let mut o = 0.5 * (min + max) + (v() * 0.8) * (max - min);
                            o[face] = plane;
                            if outside {
                                // Before the box, so that it is met ahead.
                                o[along] = if sign > 0 { min[along] - 0.5 } else { max[along] + 0.5 };
                            }
                            let mut d = Vec3::splat(if zero { 0.0 } else { -0.0 });
                            d[along] = sign as f32;
                            rays.push((o, d, f32::INFINITY));
                        }
                    }
                }
            }
        }
        let mut hits = 0;
        for (o, d, tmax) in rays {
            let want: Vec<f32> = prims.iter().map(|p| p.intersect(o, d, 0.0, tmax)).collect();
            for g in &lanes.groups {
                let got = distances(g, o, d, tmax);
                for (k, &id) in g.id.iter().enumerate() {
                    let want = want.get(id as usize).copied().unwrap_or(f32::INFINITY);
                    assert_eq!(got[k].to_bits(), want.to_bits(), "ray {o} {d} {tmax} box {id}");
                }
            }
            let mut found = Vec::new();
            lanes.for_each_hit(o, d, tmax, |t, id| found.push((id, t)));
            let expected: Vec<(u32, f32)> =
                want.iter().enumerate().filter(|(_, t)| t.is_finite()).map(|(i, &t)| (i as u32, t)).collect();
            assert_eq!(found, expected);
            assert_eq!(lanes.any_hit(o, d, tmax), !expected.is_empty());
            hits += expected.len();
        }
        assert!(hits > 2000, "hits {hits}");
    }
}
