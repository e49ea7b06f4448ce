//! Small scenes for single rays: a room of a handful of quads and boxes
//! (the Cornell box) is tested all at once, quads and boxes in SIMD lanes
//! (quad_lanes.rs, box_lanes.rs) and anything else one by one, instead of
//! through the BVH, whose bookkeeping costs more there than the tests it
//! spares.
//!
//! The tests are compiled three times (`crate::isa`), for x86-64's
//! baseline, for AVX2 with FMA, and for AVX-512 (its 256-bit forms and 32
//! registers), and the processor's best is chosen when the scene is built.
//! The arithmetic is the same in each (Rust never fuses a multiply and an
//! add on its own), so the hits are the same bit for bit. On an Intel Xeon
//! with AVX-512 the Cornell box's path tracing took 0.94× the baseline's
//! time on AVX2 and 0.91× on AVX-512, the viewer's flight 0.90× and 0.86×
//! (6 side-by-side pairs each). Everything the tests do must inline into
//! each copy: the shadow test's `Iterator::any` with a closure was compiled
//! apart, for the baseline, and cost 1.06×, so the loops here and in the
//! lanes are plain `for` loops. (The quads' lanes alone compiled for AVX
//! gave no gain on an AMD Zen 5: the divisions take as long.)

use super::Hit;
use super::batch::{comes_before, test_bound};
use super::box_lanes::BoxLanes;
use super::quad_lanes::QuadLanes;
use super::records::{Prim, Record};
use super::shape::{box_face, box_face_normal};
use crate::isa::Isa;
use glam::{Affine3A, Vec3};

mod packets;
pub(in crate::geometry) use packets::{LaneGroup, RAYS, RayLanes};

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
    /// Each record's unit normals where they are few and known: a quad's,
    /// the same everywhere, and a turned box's six; the normal of each hit
    /// without a square root and a division of its own.
    normals: Vec<KnownNormals>,
    /// The instructions the tests run on.
    isa: Isa,
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
    let normals = records.iter().map(|r| KnownNormals::of(&r.prim)).collect();
    let (quads, boxes) = (QuadLanes::new(&quads), BoxLanes::new(&boxes));
    Some(Small { quads, boxes, others, normals, isa: Isa::best() })
}

/// A record's unit normals, found once with `Prim::normal`'s own
/// arithmetic, so the same bits.
#[derive(Clone, Debug)]
enum KnownNormals {
    None,
    Quad(Vec3),
    /// A turned box's faces', in [`box_face`]'s order.
    TurnedBox([Vec3; 6]),
}

impl KnownNormals {
    fn of(prim: &Prim) -> KnownNormals {
        match prim {
            Prim::Quad { .. } => KnownNormals::Quad(prim.normal(Vec3::ZERO)),
            Prim::Instance(inst) if matches!(inst.prim, Prim::Box { .. }) => {
                KnownNormals::TurnedBox(std::array::from_fn(|face| inst.world_normal(box_face_normal(face))))
            }
            _ => KnownNormals::None,
        }
    }
}

impl Small {
    /// The unit normal of record `index` (whose primitive is `prim`) at
    /// its point `p` if it is a quad or a turned box: [`Prim::normal`]'s.
    #[inline]
    pub fn known_normal(&self, index: usize, prim: &Prim, p: Vec3) -> Option<Vec3> {
        match (self.normals.get(index)?, prim) {
            (KnownNormals::Quad(n), _) => Some(*n),
            (KnownNormals::TurnedBox(faces), Prim::Instance(inst)) => match inst.prim {
                Prim::Box { min, max } => {
                    box_face(min, max, inst.local_from_world.transform_point3(p)).map(|face| faces[face])
                }
                _ => None,
            },
            _ => None,
        }
    }

    /// Keeps in `best` the nearest hit of the ray `o + t·d`, 0 < t < tmax,
    /// if it comes before `best` (closer, or as close and of a lower index).
    #[inline]
    pub fn nearest(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32, best: &mut Hit) {
        match self.isa {
            // SAFETY: `isa` names only instruction sets the processor has.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.nearest_avx512(records, o, d, tmax, best) },
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.nearest_avx2(records, o, d, tmax, best) },
            _ => self.nearest_baseline(records, o, d, tmax, best),
        }
    }

    // Each copy is a call of its own, so that `nearest` stays small enough
    // to inline into its callers.
    #[inline(never)]
    fn nearest_baseline(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32, best: &mut Hit) {
        self.nearest_here(records, o, d, tmax, best)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq,avx512bw")]
    unsafe fn nearest_avx512(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32, best: &mut Hit) {
        self.nearest_here(records, o, d, tmax, best)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn nearest_avx2(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32, best: &mut Hit) {
        self.nearest_here(records, o, d, tmax, best)
    }

    /// [`Small::nearest`] for whatever instructions its caller is compiled
    /// for (inlined into it).
    #[inline(always)]
    fn nearest_here(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32, best: &mut Hit) {
        let mut keep = |t, id| {
            if comes_before(t, id, best.t, best.id) {
                *best = Hit { t, id };
            }
        };
        self.quads.for_each_nearest(o, d, tmax, &mut keep);
        self.boxes.for_each_hit(o, d, tmax, &mut keep);
        self.nearest_other(records, o, d, best);
    }

    /// Keeps in `best` the nearest hit among the records that are neither
    /// quads nor boxes, if it comes before `best` (single rays and packets).
    #[inline(always)]
    fn nearest_other(&self, records: &[Record], o: Vec3, d: Vec3, best: &mut Hit) {
        // A plain loop, no closure: all of it inlines (see `any_here`).
        for other in &self.others {
            if !other.may_hit(o, d) {
                continue;
            }
            let i = other.index;
            let t = records[i as usize].prim.intersect(o, d, 0.0, test_bound(best.t, best.id));
            if comes_before(t, i, best.t, best.id) {
                *best = Hit { t, id: i };
            }
        }
    }

    /// Whether a record that is neither a quad nor a box meets the ray at
    /// 0 < t < tmax (single rays and packets).
    #[inline(always)]
    fn any_other(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32) -> bool {
        for other in &self.others {
            if other.may_hit(o, d) && records[other.index as usize].prim.intersect(o, d, 0.0, tmax) < tmax {
                return true;
            }
        }
        false
    }

    /// Whether anything meets the ray `o + t·d` at 0 < t < tmax.
    #[inline]
    pub fn any(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32) -> bool {
        match self.isa {
            // SAFETY: as in `nearest`.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.any_avx512(records, o, d, tmax) },
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.any_avx2(records, o, d, tmax) },
            _ => self.any_baseline(records, o, d, tmax),
        }
    }

    #[inline(never)]
    fn any_baseline(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.any_here(records, o, d, tmax)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq,avx512bw")]
    unsafe fn any_avx512(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.any_here(records, o, d, tmax)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn any_avx2(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.any_here(records, o, d, tmax)
    }

    /// [`Small::any`] for whatever instructions its caller is compiled for.
    #[inline(always)]
    fn any_here(&self, records: &[Record], o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.quads.any_hit(o, d, tmax) || self.boxes.any_hit(o, d, tmax) || self.any_other(records, o, d, tmax)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::records::NO_ATTRIBUTES;
    use crate::sampling::{Sampler, uniform_sphere};
    use glam::vec3;

    /// A room of six quads with two boxes and a sphere in it.
    pub(super) fn room() -> Vec<Record> {
        let quad = |corner: Vec3, edge_u: Vec3, edge_v: Vec3| Prim::Quad { corner, edge_u, edge_v };
        let prims = [
            quad(vec3(-1.0, 0.0, -1.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 0.0, 2.0)),
            quad(vec3(-1.0, 2.0, -1.0), vec3(0.0, 0.0, 2.0), vec3(2.0, 0.0, 0.0)),
            quad(vec3(-1.0, 0.0, 1.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 2.0, 0.0)),
            quad(vec3(-1.0, 0.0, -1.0), vec3(0.0, 2.0, 0.0), vec3(0.0, 0.0, 2.0)),
            quad(vec3(1.0, 0.0, -1.0), vec3(0.0, 0.0, 2.0), vec3(0.0, 2.0, 0.0)),
            quad(vec3(-0.3, 1.99, -0.3), vec3(0.6, 0.0, 0.0), vec3(0.0, 0.0, 0.6)),
            Prim::Box { min: vec3(-0.7, 0.0, -0.2), max: vec3(-0.1, 1.2, 0.4) },
            Prim::Box { min: vec3(0.2, 0.0, -0.6), max: vec3(0.8, 0.6, 0.0) },
            Prim::Sphere { center: vec3(0.4, 1.2, 0.5), radius: 0.3 },
        ];
        prims.into_iter().map(|prim| Record { prim, material: 0, emitter: None, attributes: NO_ATTRIBUTES }).collect()
    }

    #[test]
    fn every_instruction_set_gives_the_hits_of_each_record_tested_alone() {
        let records = room();
        let mut small = small_scene(&records).expect("a small scene");
        let isas = Isa::available();
        let mut s = Sampler::for_pixel(3, 1, 4);
        let mut hits = 0;
        for i in 0..20_000 {
            let o = vec3(2.0 * s.next() - 1.0, 2.0 * s.next(), 2.0 * s.next() - 1.0);
            let d = uniform_sphere(s.next2());
            let tmax = if i % 2 == 0 { f32::INFINITY } else { 2.0 * s.next() };
            // Each record alone; the nearest, ties to the lower index.
            let mut want = Hit { t: tmax, id: u32::MAX };
            for (id, record) in (0u32..).zip(&records) {
                let t = record.prim.intersect(o, d, 0.0, tmax);
                if comes_before(t, id, want.t, want.id) {
                    want = Hit { t, id };
                }
            }
            hits += (want.id != u32::MAX) as u32;
            for &isa in &isas {
                small.isa = isa;
                let mut got = Hit { t: tmax, id: u32::MAX };
                small.nearest(&records, o, d, tmax, &mut got);
                assert_eq!((got.t.to_bits(), got.id), (want.t.to_bits(), want.id), "{isa:?}: ray {o} {d} {tmax}");
                assert_eq!(small.any(&records, o, d, tmax), want.id != u32::MAX, "{isa:?}: ray {o} {d} {tmax}");
            }
        }
        // Most rays start inside the room; the short ones may stop short.
        assert!(hits > 12_000, "hits {hits}");
    }

    /// The normals kept for quads and turned boxes are the ones
    /// `Prim::normal` finds at each hit, to the bit.
    #[test]
    fn known_normals_are_the_primitives_own() {
        let mut records = room();
        let world_from_local = Affine3A::from_rotation_translation(
            glam::Quat::from_axis_angle(vec3(0.3, 1.0, 0.2).normalize(), 0.7),
            vec3(-0.2, 0.9, -0.5),
        );
        let instance = super::super::records::Instance {
            prim: Prim::Box { min: vec3(-0.2, -0.3, -0.1), max: vec3(0.2, 0.3, 0.1) },
            local_from_world: world_from_local.inverse(),
            normal_to_world: glam::Mat3::from(world_from_local.matrix3).inverse().transpose(),
            bounds: obvhs::aabb::Aabb::empty(),
        };
        records.push(Record {
            prim: Prim::Instance(Box::new(instance)),
            material: 0,
            emitter: None,
            attributes: NO_ATTRIBUTES,
        });
        let turned = records.len() - 1;
        let small = small_scene(&records).expect("a small scene");
        let mut s = Sampler::for_pixel(5, 2, 7);
        let mut known = [0; 2];
        for _ in 0..20_000 {
            let o = vec3(2.0 * s.next() - 1.0, 2.0 * s.next(), 2.0 * s.next() - 1.0);
            let d = uniform_sphere(s.next2());
            let mut hit = Hit { t: f32::INFINITY, id: u32::MAX };
            small.nearest(&records, o, d, f32::INFINITY, &mut hit);
            let Some(record) = records.get(hit.id as usize) else { continue };
            let p = o + d * hit.t;
            if let Some(n) = small.known_normal(hit.id as usize, &record.prim, p) {
                assert_eq!(n.to_array().map(f32::to_bits), record.prim.normal(p).to_array().map(f32::to_bits));
                known[(hit.id as usize == turned) as usize] += 1;
            }
        }
        assert!(known[0] > 10_000 && known[1] > 200, "{known:?} quads' and the turned box's");
    }
}
