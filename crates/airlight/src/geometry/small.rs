//! Small scenes for single rays: a room of a handful of quads and boxes
//! (the Cornell box) is tested all at once, quads and boxes in SIMD lanes
//! (quad_lanes.rs, box_lanes.rs) and anything else one by one, instead of
//! through the BVH, whose bookkeeping costs more there than the tests it
//! spares. (The same loops compiled for AVX, eight floats to a register
//! rather than two SSE registers of four, rendered the Cornell box in
//! 1.02× the time, 6 side-by-side pairs: the divisions take as long.)

use super::Hit;
use super::batch::{comes_before, test_bound};
use super::box_lanes::BoxLanes;
use super::quad_lanes::QuadLanes;
use super::records::{Prim, Record};
use glam::{Affine3A, Vec3};

/// Up to this many primitives, at least half of them quads and none a
/// signed distance field, single rays test the quads and boxes in SIMD lanes
/// and the rest one by one rather than through the BVH: the Cornell box
/// (six quads, two rotated boxes) renders faster so, with the same hits.
pub(super) const SMALL_LIMIT: usize = 16;

/// A small scene's primitives for single rays: quads and boxes (turned
/// or not) in SIMD lanes, and the other records one by one.
#[derive(Clone, Debug)]
pub(super) struct Small {
    quads: QuadLanes,
    boxes: BoxLanes,
    others: Vec<Other>,
}

/// A small scene's record that is neither a quad nor a box, with a sphere
/// around it: a ray that misses the sphere misses the record, without the
/// record's own test (a turned sphere's transform of the ray costs more).
#[derive(Clone, Copy, Debug)]
struct Other {
    index: u32,
    center: Vec3,
    radius_squared: f32,
}

impl Other {
    /// Whether the ray `o + t·d`, t > 0, may meet the record: it passes
    /// within the sphere, and the sphere is not wholly behind its origin.
    #[inline]
    fn may_hit(&self, o: Vec3, d: Vec3) -> bool {
        let oc = self.center - o;
        let b = oc.dot(d);
        let oc2 = oc.length_squared();
        let inside = oc2 <= self.radius_squared;
        inside || (b > 0.0 && oc2 * d.length_squared() - b * b <= self.radius_squared * d.length_squared())
    }
}

/// A box record as the box lanes take it: local_from_world if turned, and
/// its bounds in its own space.
fn as_box(prim: &Prim) -> Option<(Option<Affine3A>, Vec3, Vec3)> {
    match prim {
        Prim::Box { min, max } => Some((None, *min, *max)),
        Prim::Instance(inst) => match inst.prim {
            Prim::Box { min, max } => Some((Some(inst.local_from_world), min, max)),
            _ => None,
        },
        _ => None,
    }
}

/// The quads and boxes in lanes and the other records, for a scene small
/// enough ([`SMALL_LIMIT`]).
pub(super) fn small_scene(records: &[Record]) -> Option<Small> {
    // Decided before anything is collected: a mesh's million records
    // would otherwise each get a bounding sphere only to be dropped.
    let is_quad = |r: &Record| matches!(r.prim, Prim::Quad { .. });
    let fits = records.len() <= SMALL_LIMIT
        && 2 * records.iter().filter(|r| is_quad(r)).count() >= records.len()
        && !records.iter().any(|r| matches!(r.prim, Prim::Sdf(_)));
    if !fits {
        return None;
    }
    // One pass, each record to the first list that takes it, in order.
    let (mut quads, mut boxes, mut others) = (Vec::new(), Vec::new(), Vec::new());
    for (index, record) in (0u32..).zip(records) {
        if let Prim::Quad { corner, edge_u, edge_v } = record.prim {
            quads.push((index, corner, edge_u, edge_v));
        } else if let Some((turn, min, max)) = as_box(&record.prim) {
            boxes.push((index, turn, min, max));
        } else {
            let b = record.prim.bounds();
            let (min, max) = (Vec3::from(b.min), Vec3::from(b.max));
            // Generous: a sphere that only just holds the box could lose a
            // grazing hit to rounding.
            let radius = 0.5 * (max - min).length() * 1.001 + 1e-4 * (1.0 + min.abs().max(max.abs()).max_element());
            others.push(Other { index, center: 0.5 * (min + max), radius_squared: radius * radius });
        }
    }
    Some(Small { quads: QuadLanes::new(&quads), boxes: BoxLanes::new(&boxes), others })
}

impl Small {
    /// Keeps in `best` the nearest hit of the ray `o + t·d`, 0 < t < tmax,
    /// if it comes before `best` (closer, or as close and of a lower index).
    #[inline]
    pub fn nearest(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32, best: &mut Hit) {
        let mut keep = |t, id| {
            if comes_before(t, id, best.t, best.id) {
                *best = Hit { t, id };
            }
        };
        self.quads.for_each_nearest(o, d, tmax, &mut keep);
        self.boxes.for_each_hit(o, d, tmax, &mut keep);
        for other in self.others.iter().filter(|other| other.may_hit(o, d)) {
            let i = other.index;
            let t = records[i as usize].prim.intersect(o, d, 0.0, test_bound(best.t, best.id));
            if comes_before(t, i, best.t, best.id) {
                *best = Hit { t, id: i };
            }
        }
    }

    /// Whether anything meets the ray `o + t·d` at 0 < t < tmax.
    #[inline]
    pub fn any(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.quads.any_hit(o, d, tmax)
            || self.boxes.any_hit(o, d, tmax)
            || self.others.iter().any(|other| {
                other.may_hit(o, d) && records[other.index as usize].prim.intersect(o, d, 0.0, tmax) < tmax
            })
    }
}
