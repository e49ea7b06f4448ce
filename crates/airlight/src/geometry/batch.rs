//! Geometry queries for many rays at once: nearest hits of camera rays and
//! shadow-ray tests, traced in packets of coherent rays (`packet.rs`). Each
//! ray's answer is the one-ray query's, bit for bit: the same hit distance,
//! the same primitive (ties go to the lowest index in both), the same
//! blocked or not.

use super::accel::Geometry;
use super::blocks::{TriangleBlock, blocks_of};
#[cfg(target_arch = "x86_64")]
use super::lanes::{Avx8, Avx16};
use super::lanes::{LaneWidth, Lanes, NativeLanes, Scalar4};
use super::packet::{PACKET, Packet, lane_mask, octant};
use super::{Hit, Ray};
use glam::Vec3;

/// A shadow ray: the open segment `origin + t·dir`, 0 < t < `tmax`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tmax: f32,
}

/// Groups of fewer rays than this are traced one by one: a packet's fixed
/// cost (its setup, the interval tests) outweighs what it shares.
const MIN_PACKET: usize = 4;

/// Calls `f` with the indices of each packet: the rays taken [`PACKET`] at
/// a time in their order and split by [`octant`] (a packet's rays must
/// share their direction signs).
#[inline(always)]
fn for_each_packet(n: usize, dir: impl Fn(usize) -> Vec3, mut f: impl FnMut(&[usize])) {
    let mut octants = [0u8; PACKET];
    let mut indices = [0usize; PACKET];
    for start in (0..n).step_by(PACKET) {
        let end = (start + PACKET).min(n);
        for i in start..end {
            octants[i - start] = octant(dir(i)) as u8;
        }
        let mut present = 0u8;
        for &o in &octants[..end - start] {
            present |= 1 << o;
        }
        for o in 0..8u8 {
            if present & (1 << o) == 0 {
                continue;
            }
            let mut len = 0;
            for i in start..end {
                if octants[i - start] == o {
                    indices[len] = i;
                    len += 1;
                }
            }
            f(&indices[..len]);
        }
    }
}

impl Geometry {
    /// The nearest hit with 0 < t < tmax of each ray: `hits[i]` is
    /// `self.intersect(&rays[i], tmax)`, bit for bit, found by tracing
    /// neighbouring rays together. Rays are fastest in the order of nearby
    /// pixels (a tile), whose packets share most of their traversal.
    /// Sixteen rays at a time where the processor has AVX-512, eight where
    /// it has AVX, else four; in a small scene (a room of quads and boxes),
    /// eight rays against each primitive in turn.
    pub fn intersect_packet(&self, rays: &[Ray], tmax: f32, hits: &mut [Option<Hit>]) {
        self.intersect_packet_on(LaneWidth::widest(), rays, tmax, hits)
    }

    /// [`Geometry::intersect_packet`] on the given lanes, which the
    /// processor must have ([`LaneWidth::available`]; panics if not): for
    /// tests and benchmarks. (A small scene's packets take its own lanes,
    /// whatever is given.)
    #[doc(hidden)]
    pub fn intersect_packet_on(&self, lanes: LaneWidth, rays: &[Ray], tmax: f32, hits: &mut [Option<Hit>]) {
        assert!(lanes.available(), "this processor has no {lanes:?} lanes");
        if self.has_cutouts() {
            // Each ray goes its own way through the cut-outs.
            assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
            for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
                *hit = self.intersect_on(lanes, ray, tmax);
            }
            return;
        }
        if let Some(small) = self.small() {
            assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
            return self.intersect_small_packets(small, rays, |_| tmax, hits);
        }
        match lanes {
            LaneWidth::Portable => self.intersect_packet_with::<Scalar4>(rays, tmax, hits),
            LaneWidth::Four => self.intersect_packet_with::<NativeLanes>(rays, tmax, hits),
            // SAFETY: the processor has AVX (asserted above).
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Eight => unsafe { self.intersect_packet_avx(rays, tmax, hits) },
            // SAFETY: the processor has AVX-512F (asserted above).
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Sixteen => unsafe { self.intersect_packet_avx512(rays, tmax, hits) },
            #[cfg(not(target_arch = "x86_64"))]
            LaneWidth::Eight | LaneWidth::Sixteen => unreachable!("never available here"),
        }
    }

    /// The packet traversal compiled for AVX, with eight lanes.
    ///
    /// # Safety
    /// The processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn intersect_packet_avx(&self, rays: &[Ray], tmax: f32, hits: &mut [Option<Hit>]) {
        self.intersect_packet_with::<Avx8>(rays, tmax, hits)
    }

    /// The packet traversal compiled for AVX-512, with sixteen lanes.
    ///
    /// # Safety
    /// The processor must have AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn intersect_packet_avx512(&self, rays: &[Ray], tmax: f32, hits: &mut [Option<Hit>]) {
        self.intersect_packet_with::<Avx16>(rays, tmax, hits)
    }

    /// Whether something blocks each segment: `blocked[i]` is
    /// `self.occluded(s.origin, s.dir, s.tmax)` for `s = segments[i]`,
    /// traced in packets. Fastest for segments from nearby points toward
    /// one light. Sixteen, eight or four rays at a time, as
    /// [`Geometry::intersect_packet`].
    pub fn occluded_packet(&self, segments: &[Segment], blocked: &mut [bool]) {
        self.occluded_packet_on(LaneWidth::widest(), segments, blocked)
    }

    /// [`Geometry::occluded_packet`] on the given lanes, which the processor
    /// must have (panics if not): for tests and benchmarks. (A small scene's
    /// packets take its own lanes, whatever is given.)
    #[doc(hidden)]
    pub fn occluded_packet_on(&self, lanes: LaneWidth, segments: &[Segment], blocked: &mut [bool]) {
        assert!(lanes.available(), "this processor has no {lanes:?} lanes");
        if self.has_cutouts() {
            for (s, b) in segments.iter().zip(blocked.iter_mut()) {
                *b = self.occluded_on(lanes, s.origin, s.dir, s.tmax);
            }
            return;
        }
        match lanes {
            LaneWidth::Portable => self.occluded_packet_with::<Scalar4>(segments, blocked),
            LaneWidth::Four => self.occluded_packet_with::<NativeLanes>(segments, blocked),
            // SAFETY: the processor has AVX (asserted above).
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Eight => unsafe { self.occluded_packet_avx(segments, blocked) },
            // SAFETY: the processor has AVX-512F (asserted above).
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Sixteen => unsafe { self.occluded_packet_avx512(segments, blocked) },
            #[cfg(not(target_arch = "x86_64"))]
            LaneWidth::Eight | LaneWidth::Sixteen => unreachable!("never available here"),
        }
    }

    /// The packet shadow test compiled for AVX, with eight lanes.
    ///
    /// # Safety
    /// The processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn occluded_packet_avx(&self, segments: &[Segment], blocked: &mut [bool]) {
        self.occluded_packet_with::<Avx8>(segments, blocked)
    }

    /// The packet shadow test compiled for AVX-512, with sixteen lanes.
    ///
    /// # Safety
    /// The processor must have AVX-512F.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    unsafe fn occluded_packet_avx512(&self, segments: &[Segment], blocked: &mut [bool]) {
        self.occluded_packet_with::<Avx16>(segments, blocked)
    }

    // Inlined into the AVX and AVX-512 entry points, so that all of it is
    // compiled with those instructions there (the lanes' operations are
    // inlined only into such code).
    #[inline(always)]
    fn intersect_packet_with<L: Lanes>(&self, rays: &[Ray], tmax: f32, hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        let Some(bvh) = self.bvh() else {
            for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
                *hit = self.intersect(ray, tmax);
            }
            return;
        };
        let mut packet: Option<Box<Packet>> = None;
        for_each_packet(
            rays.len(),
            |i| rays[i].dir,
            |indices| {
                if indices.len() < MIN_PACKET {
                    for &i in indices {
                        hits[i] = self.intersect(&rays[i], tmax);
                    }
                    return;
                }
                let items = indices.iter().map(|&i| (rays[i].origin, rays[i].dir, tmax));
                let p = match &mut packet {
                    Some(p) => {
                        p.fill(items);
                        p
                    }
                    None => packet.insert(Packet::new(items)),
                };
                let leaf = |first, count, mixed, rays, p: &mut Packet| {
                    self.packet_leaf_closest::<L>(first, count, mixed, rays, p);
                    0
                };
                bvh.packet::<L, true>(p, p.all(), leaf, |first, count| self.prefetch_triangles(first, count));
                for (k, &i) in indices.iter().enumerate() {
                    let mut best = Hit { t: p.tmax[k], id: p.id[k] };
                    self.intersect_unbounded(&rays[i], &mut best);
                    hits[i] = (best.id != u32::MAX).then_some(best);
                }
            },
        );
    }

    #[inline(always)]
    fn occluded_packet_with<L: Lanes>(&self, segments: &[Segment], blocked: &mut [bool]) {
        assert_eq!(segments.len(), blocked.len(), "one answer per segment");
        super::accel::count_shadow_rays(segments.len() as u64);
        for (s, b) in segments.iter().zip(blocked.iter_mut()) {
            *b = self.occluded_unbounded(s.origin, s.dir, s.tmax);
        }
        if let Some(small) = self.small() {
            return self.occluded_small_packets(small, segments, blocked);
        }
        let Some(bvh) = self.bvh() else {
            for (s, b) in segments.iter().zip(blocked.iter_mut()) {
                *b = *b || self.occluded_linear(s.origin, s.dir, s.tmax);
            }
            return;
        };
        let mut packet: Option<Box<Packet>> = None;
        for_each_packet(
            segments.len(),
            |i| segments[i].dir,
            |indices| {
                if indices.len() < MIN_PACKET {
                    for &i in indices {
                        let s = &segments[i];
                        blocked[i] = blocked[i] || self.occluded_bvh::<L::Four>(bvh, s.origin, s.dir, s.tmax);
                    }
                    return;
                }
                let items = indices.iter().map(|&i| (segments[i].origin, segments[i].dir, segments[i].tmax));
                let p = match &mut packet {
                    Some(p) => {
                        p.fill(items);
                        p
                    }
                    None => packet.insert(Packet::new(items)),
                };
                // Rays already blocked by a plane need no traversal.
                let open = indices.iter().enumerate().fold(0u64, |m, (k, &i)| m | ((!blocked[i] as u64) << k));
                let mut found = 0u64;
                let leaf = |first, count, mixed, rays, p: &mut Packet| {
                    let b = self.packet_leaf_any::<L>(first, count, mixed, rays, p);
                    found |= b;
                    b
                };
                bvh.packet::<L, false>(p, open, leaf, |first, count| self.prefetch_triangles(first, count));
                for (k, &i) in indices.iter().enumerate() {
                    blocked[i] |= found & (1 << k) != 0;
                }
            },
        );
    }

    /// Starts fetching the blocks of a leaf of `count` triangles from
    /// block `first`. (A leaf with other primitives links to its first
    /// primitive instead: the fetch is then of the wrong memory, harmless.)
    #[inline(always)]
    pub(super) fn prefetch_triangles(&self, first: u32, count: u32) {
        let end = (first as usize + blocks_of(count)).min(self.blocks.len());
        if let Some(blocks) = self.blocks.get(first as usize..end) {
            for block in blocks.iter().take(2) {
                super::packet::prefetch(block);
            }
        }
    }

    /// The blocks of a leaf of `count` triangles from block `first`.
    #[inline(always)]
    pub(super) fn blocks_of_leaf(&self, first: u32, count: u32) -> &[TriangleBlock] {
        &self.blocks[first as usize..first as usize + blocks_of(count)]
    }

    /// The (primitive, [v0, e1, e2]) of a leaf of `count` triangles from
    /// block `first`, in the leaf's order.
    #[inline(always)]
    pub(super) fn leaf_triangles(&self, first: u32, count: u32) -> impl Iterator<Item = (u32, [Vec3; 3])> + '_ {
        let blocks = self.blocks_of_leaf(first, count);
        (0..count as usize).map(move |k| {
            let block = &blocks[k / 4];
            (block.ids[k % 4], block.triangle(k % 4))
        })
    }

    /// A leaf of a nearest-hit packet query: tests primitives `first ..
    /// first + count` against the packet's rays in `rays` and records in
    /// the packet each ray's hits that come before its best so far (the
    /// rule of [`comes_before`], so that the result is the one-ray query's).
    #[inline(always)]
    pub(super) fn packet_leaf_closest<L: Lanes>(&self, first: u32, count: u32, mixed: bool, rays: u64, p: &mut Packet) {
        if mixed {
            for k in bits(rays) {
                let (o, d) = p.ray(k);
                for i in first..first + count {
                    let t = self.intersect_one(i as usize, o, d, test_bound(p.tmax[k], p.id[k]));
                    if comes_before(t, i, p.tmax[k], p.id[k]) {
                        (p.tmax[k], p.id[k]) = (t, i);
                    }
                }
            }
            return;
        }
        if few_rays::<L>(rays, count) {
            for k in bits(rays) {
                let (o, d) = p.ray(k);
                if let Some(hit) = self.leaf_nearest::<L::Four>(first, count, o, d, (p.tmax[k], p.id[k])) {
                    (p.tmax[k], p.id[k]) = hit;
                }
            }
            return;
        }
        for (i, triangle) in self.leaf_triangles(first, count) {
            let triangle = &triangle;
            for (s, lanes) in groups::<L>(rays) {
                let (hit, t) = p.triangle_lanes::<L>(s, triangle);
                let tmax = L::load(&p.tmax[s..]);
                let found = hit & lanes;
                // `comes_before`: nearer, or as near and a lower index.
                let mut nearer = found & t.lt(tmax);
                let ties = found & t.eq(tmax);
                for lane in bits(ties as u64) {
                    // As `comes_before`: a tie only with a hit found.
                    let id = p.id[s + lane];
                    if id != u32::MAX && i < id {
                        nearer |= 1 << lane;
                    }
                }
                if nearer != 0 {
                    t.store_where(nearer, &mut p.tmax[s..]);
                    L::fill_where(nearer, i, &mut p.id[s..]);
                }
            }
        }
    }

    /// A leaf of an any-hit packet query: the rays of `rays` that one of
    /// primitives `first .. first + count` blocks before their `tmax`.
    #[inline(always)]
    pub(super) fn packet_leaf_any<L: Lanes>(&self, first: u32, count: u32, mixed: bool, rays: u64, p: &Packet) -> u64 {
        let mut blocked = 0u64;
        if mixed {
            for k in bits(rays) {
                let (o, d) = p.ray(k);
                if (first..first + count).any(|i| self.intersect_one(i as usize, o, d, p.tmax[k]) < p.tmax[k]) {
                    blocked |= 1 << k;
                }
            }
            return blocked;
        }
        if few_rays::<L>(rays, count) {
            for k in bits(rays) {
                let (o, d) = p.ray(k);
                if self.leaf_blocks::<L::Four>(first, count, o, d, p.tmax[k]) {
                    blocked |= 1 << k;
                }
            }
            return blocked;
        }
        for (_, triangle) in self.leaf_triangles(first, count) {
            let triangle = &triangle;
            for (s, lanes) in groups::<L>(rays & !blocked) {
                blocked |= ((p.triangle_blocks_lanes::<L>(s, triangle) & lanes) as u64) << s;
            }
            if blocked == rays {
                break;
            }
        }
        blocked
    }
}

/// Whether a hit at `t` on primitive `id` comes before the best so far,
/// (`best_t`, `best_id`; u32::MAX while there is none): closer, or as close
/// and of a lower index. Ties (two primitives met at the same distance,
/// such as faces that coincide or a ray through a shared edge) so go to
/// the lowest index, as when testing every primitive in order, whatever
/// order a traversal meets them in.
#[inline(always)]
pub(super) fn comes_before(t: f32, id: u32, best_t: f32, best_id: u32) -> bool {
    t < best_t || (t == best_t && best_id != u32::MAX && id < best_id)
}

/// The bound to test a primitive against, given the best hit so far: past
/// `best_t` by one ulp once there is a hit, so that a primitive met at the
/// same distance is reported (primitive tests take an open bound).
#[inline(always)]
pub(super) fn test_bound(best_t: f32, best_id: u32) -> f32 {
    if best_id == u32::MAX { best_t } else { next_up(best_t) }
}

/// The least f32 above `x` (`f32::next_up`, which needs a newer Rust than
/// the crate's minimum).
#[inline(always)]
fn next_up(x: f32) -> f32 {
    if x.is_nan() || x == f32::INFINITY {
        x
    } else if x == 0.0 {
        f32::from_bits(1)
    } else if x > 0.0 {
        f32::from_bits(x.to_bits() + 1)
    } else {
        f32::from_bits(x.to_bits() - 1)
    }
}

/// Whether a leaf of `count` triangles is cheaper to test ray by ray (each
/// ray against the leaf's triangles four at a time, as one ray alone is
/// tested) than triangle by triangle against the groups of `L::WIDTH`
/// rays that hold `rays`. Camera rays meet leaves of a fine mesh a few at
/// a time (on the 1.1 M-triangle mesh of bench_bvh, half the leaves a
/// 64-ray packet visits are entered by six of its rays or fewer), which
/// leaves most lanes of a group idle. A ray's test is
/// weighed as four times a four-lane test: what it costs besides (the ray
/// splat into lanes, its hits read lane by lane) made a weight of 4 the
/// fastest of 1, 2, 4, 8 and never per ray. Both ways give each ray the
/// same hits, bit for bit (the same operations, and ties taken as
/// [`comes_before`] takes them).
#[inline(always)]
fn few_rays<L: Lanes>(rays: u64, count: u32) -> bool {
    let groups = groups::<L>(rays).count();
    rays.count_ones() as usize * blocks_of(count) * 4 <= count as usize * groups * (L::WIDTH / 4)
}

/// The set bits of a mask, lowest first.
#[inline(always)]
pub(super) fn bits(mut mask: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

/// The groups of `L::WIDTH` lanes that hold a ray of `mask`: each group's
/// first lane and its bits of `mask`.
#[inline(always)]
pub(super) fn groups<L: Lanes>(mut mask: u64) -> impl Iterator<Item = (usize, u32)> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let s = mask.trailing_zeros() as usize / L::WIDTH * L::WIDTH;
            let lanes = ((mask >> s) & lane_mask::<L>()) as u32;
            mask &= !(lane_mask::<L>() << s);
            (s, lanes)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::next_up;

    #[test]
    fn next_up_is_the_least_float_above() {
        assert_eq!(next_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_up(-1.0), -(1.0 - f32::EPSILON / 2.0));
        assert_eq!(next_up(0.0), f32::from_bits(1));
        assert_eq!(next_up(-0.0), f32::from_bits(1));
        assert_eq!(next_up(f32::MAX), f32::INFINITY);
        assert_eq!(next_up(f32::INFINITY), f32::INFINITY);
        assert!(next_up(f32::NAN).is_nan());
        for x in [3.7e-3f32, 12.5, 1e30] {
            let y = next_up(x);
            assert!(y > x && ((x + y) / 2.0 == x || (x + y) / 2.0 == y), "{x}");
        }
    }
}
