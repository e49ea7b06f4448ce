//! A small scene's tests for packets of rays: each quad and box against
//! eight rays at once, where the single-ray tests (`mod.rs`) take eight
//! quads (or four boxes) against one ray. The Cornell box's two boxes fill
//! two of four lanes there and eight of eight here, and each ray's nearest
//! hit is kept in its lane, without the branches of picking it out of a
//! group. The arithmetic is the single-ray tests' own (the lanes'
//! `distance`), so the hits are the same bit for bit.

use super::{Isa, Small};
use crate::geometry::Hit;
use crate::geometry::records::Record;
use glam::Vec3;

/// Rays per packet in the small scene's packet tests.
pub(in crate::geometry) const RAYS: usize = 8;

/// Up to [`RAYS`] rays side by side, each coordinate one array across them.
/// Unused lanes have tmax 0 and meet nothing (hits need 0 < t < tmax).
#[derive(Clone, Debug, Default)]
pub(in crate::geometry) struct RayLanes {
    origin: [[f32; RAYS]; 3],
    dir: [[f32; RAYS]; 3],
    pub tmax: [f32; RAYS],
}

impl RayLanes {
    /// The packet of the rays (origin, direction, tmax) given, at most [`RAYS`].
    pub fn new(rays: impl IntoIterator<Item = (Vec3, Vec3, f32)>) -> Self {
        let mut lanes = RayLanes::default();
        for (r, (o, d, tmax)) in rays.into_iter().take(RAYS).enumerate() {
            for axis in 0..3 {
                (lanes.origin[axis][r], lanes.dir[axis][r]) = (o[axis], d[axis]);
            }
            lanes.tmax[r] = tmax;
        }
        lanes
    }

    #[inline(always)]
    pub fn origin(&self, r: usize) -> Vec3 {
        Vec3::new(self.origin[0][r], self.origin[1][r], self.origin[2][r])
    }

    #[inline(always)]
    pub fn dir(&self, r: usize) -> Vec3 {
        Vec3::new(self.dir[0][r], self.dir[1][r], self.dir[2][r])
    }
}

/// Takes (`t`, `id`) as the best hit if it comes before it
/// ([`comes_before`](crate::geometry::batch::comes_before)), without
/// branches (so that a loop over a packet's rays vectorises).
#[inline(always)]
fn keep_if_before(t: f32, id: u32, best_t: &mut f32, best_id: &mut u32) {
    let before = (t < *best_t) | ((t == *best_t) & (*best_id != u32::MAX) & (id < *best_id));
    // The same as taking `t` when `before`: a tie keeps an equal value. (A
    // select here became a masked store, microcoded on AMD's Zen, that took
    // a fifth of the packet test's time.)
    *best_t = best_t.min(t);
    *best_id = if before { id } else { *best_id };
}

/// A group of primitives side by side in lanes (quads or boxes), as the
/// packet tests read it.
pub(in crate::geometry) trait LaneGroup {
    /// Each lane's record, u32::MAX for an unused lane.
    fn ids(&self) -> &[u32];
    /// Lane `k`'s hit distance for the ray `o + t·d` in (0, tmax), or
    /// infinity: the single-ray test's own arithmetic.
    fn distance(&self, k: usize, o: Vec3, d: Vec3, tmax: f32) -> f32;
}

/// Keeps, for each ray r of the packet, its nearest hit among `groups` in
/// (`best_t[r]`, `best_id[r]`) if it comes before what they hold (see
/// [`keep_if_before`]): the primitives one after another, each against all
/// eight rays at once.
// One index across the packet's arrays.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn nearest_in_packet<G: LaneGroup>(groups: &[G], rays: &RayLanes, best_t: &mut [f32; RAYS], best_id: &mut [u32; RAYS]) {
    for g in groups {
        for (k, &id) in g.ids().iter().enumerate().filter(|&(_, &id)| id != u32::MAX) {
            for r in 0..RAYS {
                let t = g.distance(k, rays.origin(r), rays.dir(r), rays.tmax[r]);
                keep_if_before(t, id, &mut best_t[r], &mut best_id[r]);
            }
        }
    }
}

/// Marks in `blocked` each ray of the packet that a primitive of `groups` meets.
// One index across the packet's arrays.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn any_in_packet<G: LaneGroup>(groups: &[G], rays: &RayLanes, blocked: &mut [bool; RAYS]) {
    for g in groups {
        for (k, _) in g.ids().iter().enumerate().filter(|&(_, &id)| id != u32::MAX) {
            for r in 0..RAYS {
                blocked[r] |= g.distance(k, rays.origin(r), rays.dir(r), rays.tmax[r]) < rays.tmax[r];
            }
        }
    }
}

impl Small {
    /// For each ray r of the packet, keeps in (`best_t[r]`, `best_id[r]`)
    /// its nearest hit at 0 < t < tmax if it comes before them, as
    /// [`Small::nearest`] does for one ray: start them at (tmax, u32::MAX).
    #[inline]
    pub fn nearest_packet(
        &self,
        records: &[Record],
        rays: &RayLanes,
        best_t: &mut [f32; RAYS],
        best_id: &mut [u32; RAYS],
    ) {
        match self.isa {
            // SAFETY: `isa` names only instruction sets the processor has.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.nearest_packet_avx512(records, rays, best_t, best_id) },
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.nearest_packet_avx2(records, rays, best_t, best_id) },
            _ => self.nearest_packet_baseline(records, rays, best_t, best_id),
        }
    }

    #[inline(never)]
    fn nearest_packet_baseline(&self, records: &[Record], rays: &RayLanes, t: &mut [f32; RAYS], id: &mut [u32; RAYS]) {
        self.nearest_packet_here(records, rays, t, id)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq,avx512bw")]
    unsafe fn nearest_packet_avx512(
        &self,
        records: &[Record],
        rays: &RayLanes,
        t: &mut [f32; RAYS],
        id: &mut [u32; RAYS],
    ) {
        self.nearest_packet_here(records, rays, t, id)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn nearest_packet_avx2(
        &self,
        records: &[Record],
        rays: &RayLanes,
        t: &mut [f32; RAYS],
        id: &mut [u32; RAYS],
    ) {
        self.nearest_packet_here(records, rays, t, id)
    }

    #[inline(always)]
    fn nearest_packet_here(
        &self,
        records: &[Record],
        rays: &RayLanes,
        best_t: &mut [f32; RAYS],
        best_id: &mut [u32; RAYS],
    ) {
        nearest_in_packet(self.quads.groups(), rays, best_t, best_id);
        nearest_in_packet(self.boxes.groups(), rays, best_t, best_id);
        for r in 0..RAYS {
            if rays.tmax[r] <= 0.0 {
                continue;
            }
            let mut best = Hit { t: best_t[r], id: best_id[r] };
            self.nearest_other(records, rays.origin(r), rays.dir(r), &mut best);
            (best_t[r], best_id[r]) = (best.t, best.id);
        }
    }

    /// Marks in `blocked` each ray of the packet that something meets at
    /// 0 < t < tmax, as [`Small::any`] answers for one ray.
    #[inline]
    pub fn any_packet(&self, records: &[Record], rays: &RayLanes, blocked: &mut [bool; RAYS]) {
        match self.isa {
            // SAFETY: as in `nearest`.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.any_packet_avx512(records, rays, blocked) },
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.any_packet_avx2(records, rays, blocked) },
            _ => self.any_packet_baseline(records, rays, blocked),
        }
    }

    #[inline(never)]
    fn any_packet_baseline(&self, records: &[Record], rays: &RayLanes, blocked: &mut [bool; RAYS]) {
        self.any_packet_here(records, rays, blocked)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq,avx512bw")]
    unsafe fn any_packet_avx512(&self, records: &[Record], rays: &RayLanes, blocked: &mut [bool; RAYS]) {
        self.any_packet_here(records, rays, blocked)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn any_packet_avx2(&self, records: &[Record], rays: &RayLanes, blocked: &mut [bool; RAYS]) {
        self.any_packet_here(records, rays, blocked)
    }

    // One index across the packet's arrays.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn any_packet_here(&self, records: &[Record], rays: &RayLanes, blocked: &mut [bool; RAYS]) {
        any_in_packet(self.quads.groups(), rays, blocked);
        any_in_packet(self.boxes.groups(), rays, blocked);
        for r in 0..RAYS {
            if !blocked[r] && rays.tmax[r] > 0.0 {
                blocked[r] = self.any_other(records, rays.origin(r), rays.dir(r), rays.tmax[r]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::room;
    use super::super::{Isa, small_scene};
    use super::*;
    use crate::geometry::Hit;
    use crate::sampling::{Sampler, uniform_sphere};
    use glam::vec3;

    #[test]
    fn packets_give_each_ray_its_own_answer_on_every_instruction_set() {
        // Packets of one to eight rays, each with its own bound, against the
        // single-ray tests (which are checked against each record alone).
        let records = room();
        let mut small = small_scene(&records).expect("a small scene");
        let mut s = Sampler::for_pixel(2, 7, 1);
        let mut rays = Vec::new();
        for i in 0..9000 {
            let o = vec3(2.0 * s.next() - 1.0, 2.0 * s.next(), 2.0 * s.next() - 1.0);
            let tmax = if i % 3 == 0 { f32::INFINITY } else { 2.0 * s.next() };
            rays.push((o, uniform_sphere(s.next2()), tmax));
        }
        let (mut hits, mut blocked) = (0, 0);
        for isa in Isa::available() {
            small.isa = isa;
            let mut start = 0;
            for size in (1..=RAYS).cycle() {
                let Some(packet) = rays.get(start..(start + size).min(rays.len())).filter(|p| !p.is_empty()) else {
                    break;
                };
                start += size;
                let lanes = RayLanes::new(packet.iter().copied());
                let (mut best_t, mut best_id) = (lanes.tmax, [u32::MAX; RAYS]);
                small.nearest_packet(&records, &lanes, &mut best_t, &mut best_id);
                let mut found = [false; RAYS];
                small.any_packet(&records, &lanes, &mut found);
                for (r, &(o, d, tmax)) in packet.iter().enumerate() {
                    let mut want = Hit { t: tmax, id: u32::MAX };
                    small.nearest(&records, o, d, tmax, &mut want);
                    assert_eq!(
                        (best_t[r].to_bits(), best_id[r]),
                        (want.t.to_bits(), want.id),
                        "{isa:?}: {o} {d} {tmax}"
                    );
                    assert_eq!(found[r], small.any(&records, o, d, tmax), "{isa:?}: {o} {d} {tmax}");
                    hits += (want.id != u32::MAX) as u32;
                    blocked += found[r] as u32;
                }
                // Unused lanes meet nothing.
                assert!(best_id[packet.len()..].iter().all(|&id| id == u32::MAX));
                assert!(!found[packet.len()..].iter().any(|&b| b));
            }
        }
        assert!(hits > 6000 && blocked > 6000, "{hits} hits, {blocked} blocked");
    }
}
