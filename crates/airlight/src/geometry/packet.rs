//! Packets of up to 64 coherent rays traced together through the 8-wide BVH
//! (`bvh.rs`), for camera rays of neighbouring pixels and shadow rays from
//! them toward one light.
//!
//! Each node is fetched once for the whole packet. Its eight child boxes
//! are first tested, four at a time, against the packet as a whole by
//! interval arithmetic (the range of origins and of reciprocal directions,
//! Boulos et al., "Packet-based Whitted and distribution ray tracing",
//! 2007), which drops children that no ray of the packet can enter without
//! testing any ray. A child that passes
//! is then tested ray by ray, a group of rays at a time (four, eight or
//! sixteen, the width of the [`Lanes`]), when it is visited (so that the
//! rays' nearest hits found meanwhile cull it), and only the rays that
//! enter it go on.
//! Leaves test their triangles against a group of rays at a time with the
//! same arithmetic, operation for operation, as the one-ray
//! [`intersect_triangle`](super::intersect_triangle) (shadow rays: as
//! [`triangle_blocks`](super::triangle_blocks)), so a ray's hit distance,
//! or blocked-or-not, is the same bits whichever way it is traced. A leaf
//! that only a few of the packet's rays enter is tested ray by ray instead,
//! as one ray alone tests it (`batch.rs`): on a mesh whose triangles are
//! about a pixel in size, many leaves are.
//!
//! All rays of a packet share their direction's sign on each axis (the
//! caller groups rays so), which makes the near plane of every box the same
//! for all of them. The arithmetic is written once over [`Lanes`]
//! (`lanes.rs`).

use super::bvh::{Bvh, COUNT_MASK, FAR_SCALE, LEAF_MIXED, Node, Stack, far_row, is_triangle_leaf};
use super::lanes::Lanes;
use glam::Vec3;

/// The most rays a packet holds: one bit each in a `u64` mask.
pub const PACKET: usize = 64;

/// Up to [`PACKET`] rays in structure of arrays, all with the same direction
/// signs, with each ray's nearest hit so far (`tmax`, and `id`, u32::MAX
/// for none). Lanes past `len` hold copies of lane 0 and are never active.
#[repr(C, align(64))]
pub struct Packet {
    pub origin: [[f32; PACKET]; 3],
    pub dir: [[f32; PACKET]; 3],
    /// Reciprocal directions, zeros replaced as in [`super::bvh::BoxRay`].
    inv_dir: [[f32; PACKET]; 3],
    pub tmax: [f32; PACKET],
    pub id: [u32; PACKET],
    pub len: usize,
    /// The row of each axis's near plane in a node's bounds.
    near: [usize; 3],
    /// Ranges over the packet's rays of origin and reciprocal direction per
    /// axis, and the largest tmax.
    origin_lo: [f32; 3],
    origin_hi: [f32; 3],
    inv_lo: [f32; 3],
    inv_hi: [f32; 3],
    tmax_hi: f32,
}

/// The reciprocal of a direction component, zero replaced by a tiny value
/// of the same sign (so that no 0·∞ appears): what single-ray box tests use.
#[inline]
pub fn reciprocal(d: f32) -> f32 {
    1.0 / if d.abs() < 1e-30 { 1e-30f32.copysign(d) } else { d }
}

/// Which octant a direction points into: bit a set when its reciprocal on
/// axis a is negative. Rays of one packet must share it.
#[inline]
pub fn octant(dir: Vec3) -> usize {
    (0..3).fold(0, |o, a| o | ((reciprocal_is_negative(dir[a]) as usize) << a))
}

/// Whether [`reciprocal`]`(d) < 0`, read from the sign without dividing:
/// true for every negative d (−0 included, whose reciprocal is −10³⁰)
/// except −∞ (whose reciprocal is −0) and NaN.
#[inline]
fn reciprocal_is_negative(d: f32) -> bool {
    d.is_sign_negative() && d != f32::NEG_INFINITY && !d.is_nan()
}

impl Packet {
    /// A packet of `rays` (origin, direction, tmax), at most [`PACKET`] of
    /// them, all in one [`octant`]. Inlined, as [`Packet::fill`], so that it
    /// runs on the caller's lanes (a render's packets are mostly one a call).
    #[inline(always)]
    pub fn new(rays: impl ExactSizeIterator<Item = (Vec3, Vec3, f32)>) -> Box<Packet> {
        let len = rays.len();
        assert!((1..=PACKET).contains(&len), "a packet holds 1 to {PACKET} rays, not {len}");
        let mut p = Box::new(Packet {
            origin: [[0.0; PACKET]; 3],
            dir: [[0.0; PACKET]; 3],
            inv_dir: [[0.0; PACKET]; 3],
            tmax: [0.0; PACKET],
            id: [u32::MAX; PACKET],
            len,
            near: [0; 3],
            origin_lo: [f32::INFINITY; 3],
            origin_hi: [f32::NEG_INFINITY; 3],
            inv_lo: [f32::INFINITY; 3],
            inv_hi: [f32::NEG_INFINITY; 3],
            tmax_hi: 0.0,
        });
        p.fill(rays);
        p
    }

    /// Refills the packet with new rays (the same contract as [`Packet::new`]),
    /// reusing its storage.
    #[inline(always)]
    pub fn fill(&mut self, rays: impl ExactSizeIterator<Item = (Vec3, Vec3, f32)>) {
        let len = rays.len();
        assert!((1..=PACKET).contains(&len), "a packet holds 1 to {PACKET} rays, not {len}");
        self.len = len;
        for (i, (o, d, tmax)) in rays.enumerate() {
            for a in 0..3 {
                self.origin[a][i] = o[a];
                self.dir[a][i] = d[a];
            }
            self.tmax[i] = tmax;
        }
        // Lanes past `len` copy lane 0, so that the loops below may run over
        // all lanes (in whole vectors): a copy changes no range.
        for a in 0..3 {
            let (o, d) = (self.origin[a][0], self.dir[a][0]);
            self.origin[a][len..].fill(o);
            self.dir[a][len..].fill(d);
        }
        let tmax = self.tmax[0];
        self.tmax[len..].fill(tmax);
        self.id = [u32::MAX; PACKET];
        for a in 0..3 {
            for i in 0..PACKET {
                self.inv_dir[a][i] = reciprocal(self.dir[a][i]);
            }
            self.origin_lo[a] = self.origin[a].iter().fold(f32::INFINITY, |m, &x| m.min(x));
            self.origin_hi[a] = self.origin[a].iter().fold(f32::NEG_INFINITY, |m, &x| m.max(x));
            self.inv_lo[a] = self.inv_dir[a].iter().fold(f32::INFINITY, |m, &x| m.min(x));
            self.inv_hi[a] = self.inv_dir[a].iter().fold(f32::NEG_INFINITY, |m, &x| m.max(x));
        }
        self.tmax_hi = self.tmax.iter().fold(f32::NEG_INFINITY, |m, &x| m.max(x));
        let oct = octant(Vec3::new(self.dir[0][0], self.dir[1][0], self.dir[2][0]));
        debug_assert!((0..len).all(|i| octant(self.ray(i).1) == oct), "rays of a packet must share their octant");
        self.near = std::array::from_fn(|a| if oct & (1 << a) == 0 { a } else { a + 3 });
    }

    /// The mask of all the packet's rays.
    pub fn all(&self) -> u64 {
        if self.len == PACKET { u64::MAX } else { (1u64 << self.len) - 1 }
    }

    /// Ray `i`'s origin and direction.
    pub fn ray(&self, i: usize) -> (Vec3, Vec3) {
        let o = Vec3::new(self.origin[0][i], self.origin[1][i], self.origin[2][i]);
        let d = Vec3::new(self.dir[0][i], self.dir[1][i], self.dir[2][i]);
        (o, d)
    }

    /// Of the rays in `mask`, those whose segment [0, tmax] enters child
    /// `c`'s box of `node`: the single-ray test, `L::WIDTH` rays at a time.
    #[inline(always)]
    fn enter<L: Lanes, const W: usize>(&self, node: &Node<W>, c: usize, mask: u64) -> u64 {
        let mut out = 0;
        let mut groups = mask;
        while groups != 0 {
            let s = groups.trailing_zeros() as usize / L::WIDTH * L::WIDTH;
            let bits = (mask >> s) & lane_mask::<L>();
            groups &= !(lane_mask::<L>() << s);
            let slab = |row: usize, a: usize| {
                L::splat(node.bounds[row][c]).sub(L::load(&self.origin[a][s..])).mul(L::load(&self.inv_dir[a][s..]))
            };
            let n = [slab(self.near[0], 0), slab(self.near[1], 1), slab(self.near[2], 2)];
            let f = [
                slab(far_row(self.near[0], 0), 0),
                slab(far_row(self.near[1], 1), 1),
                slab(far_row(self.near[2], 2), 2),
            ];
            let tnear = n[0].max(n[1]).max(n[2].max(L::splat(0.0)));
            let tfar = f[0].min(f[1]).min(f[2].min(L::load(&self.tmax[s..]))).mul(L::splat(FAR_SCALE));
            out |= ((tnear.le(tfar) as u64) & bits) << s;
        }
        out
    }

    /// Which of the four children `at..at + 4` of `node` some ray of the
    /// packet may enter (bit c for child at + c), and a lower bound on
    /// every ray's entry distance into each: interval arithmetic over the
    /// packet's ranges of origins and reciprocal directions. Rounding is monotonic, so the bounds hold
    /// the values each ray's own test computes, and no child that a ray
    /// enters is dropped.
    #[inline(always)]
    fn children<L: Lanes, const W: usize>(&self, node: &Node<W>, at: usize) -> (u32, [f32; 4]) {
        debug_assert_eq!(L::WIDTH, 4, "one lane per child");
        let range = |row: usize, a: usize| {
            let plane = L::load(&node.bounds[row][at..]);
            let (d_lo, d_hi) = (plane.sub(L::splat(self.origin_hi[a])), plane.sub(L::splat(self.origin_lo[a])));
            let (i_lo, i_hi) = (L::splat(self.inv_lo[a]), L::splat(self.inv_hi[a]));
            let (p0, p1, p2, p3) = (d_lo.mul(i_lo), d_lo.mul(i_hi), d_hi.mul(i_lo), d_hi.mul(i_hi));
            (p0.min(p1).min(p2.min(p3)), p0.max(p1).max(p2.max(p3)))
        };
        let n = [range(self.near[0], 0).0, range(self.near[1], 1).0, range(self.near[2], 2).0];
        let f = [
            range(far_row(self.near[0], 0), 0).1,
            range(far_row(self.near[1], 1), 1).1,
            range(far_row(self.near[2], 2), 2).1,
        ];
        let tnear = n[0].max(n[1]).max(n[2].max(L::splat(0.0)));
        let tfar = f[0].min(f[1]).min(f[2].min(L::splat(self.tmax_hi))).mul(L::splat(FAR_SCALE));
        let t = tnear.to_array();
        (tnear.le(tfar), [t[0], t[1], t[2], t[3]])
    }

    /// Möller–Trumbore's terms for rays `s..s + L::WIDTH` against one
    /// triangle ([`triangle_terms`]).
    #[inline(always)]
    fn triangle_terms<L: Lanes>(&self, s: usize, triangle: &[Vec3; 3]) -> [L; 4] {
        let d = [L::load(&self.dir[0][s..]), L::load(&self.dir[1][s..]), L::load(&self.dir[2][s..])];
        let o = [L::load(&self.origin[0][s..]), L::load(&self.origin[1][s..]), L::load(&self.origin[2][s..])];
        // Each component read on its own: copying the 12-byte vectors whole
        // and reloading them as 16 bytes stalled store forwarding.
        let [v0, e1, e2] =
            [&triangle[0], &triangle[1], &triangle[2]].map(|e| [L::splat(e.x), L::splat(e.y), L::splat(e.z)]);
        triangle_terms(d, o, v0, e1, e2)
    }

    /// Möller–Trumbore against rays `s..s + L::WIDTH`, operation for operation as
    /// [`super::intersect_triangle`]: the mask of lanes with a hit at t > 0
    /// (no upper bound applied) and the lanes' t.
    #[inline(always)]
    pub fn triangle_lanes<L: Lanes>(&self, s: usize, triangle: &[Vec3; 3]) -> (u32, L) {
        triangle_hits(self.triangle_terms::<L>(s, triangle))
    }

    /// Of rays `s..s + L::WIDTH`, those the triangle blocks before their
    /// `tmax`, operation for operation as [`super::triangle_blocks`] (no
    /// division).
    #[inline(always)]
    pub fn triangle_blocks_lanes<L: Lanes>(&self, s: usize, triangle: &[Vec3; 3]) -> u32 {
        triangle_blocks_mask(self.triangle_terms::<L>(s, triangle), L::load(&self.tmax[s..]))
    }
}

/// Möller–Trumbore's terms, operation for operation as
/// [`super::intersect_triangle`], lane by lane (rays in the lanes and one
/// triangle splat, or one ray splat and triangles in the lanes): the
/// determinant and the numerators of u, v and t (each still to be divided
/// by it).
#[inline(always)]
pub(super) fn triangle_terms<L: Lanes>(d: [L; 3], o: [L; 3], v0: [L; 3], e1: [L; 3], e2: [L; 3]) -> [L; 4] {
    let pvec = cross(&d, &e2);
    let det = dot(&e1, &pvec);
    let tvec = [o[0].sub(v0[0]), o[1].sub(v0[1]), o[2].sub(v0[2])];
    let qvec = cross(&tvec, &e1);
    [det, dot(&tvec, &pvec), dot(&d, &qvec), dot(&e2, &qvec)]
}

// Functions rather than closures: a closure is compiled without the
// target features of the function it is written in, and where it is not
// inlined its AVX lanes become calls.
#[inline(always)]
fn cross<L: Lanes>(a: &[L; 3], b: &[L; 3]) -> [L; 3] {
    [a[1].mul(b[2]).sub(b[1].mul(a[2])), a[2].mul(b[0]).sub(b[2].mul(a[0])), a[0].mul(b[1]).sub(b[0].mul(a[1]))]
}

#[inline(always)]
fn dot<L: Lanes>(a: &[L; 3], b: &[L; 3]) -> L {
    a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]))
}

/// From [`triangle_terms`], as [`super::triangle_blocks`] decides (no
/// division): the mask of lanes whose triangle blocks the segment (0, tmax).
#[inline(always)]
pub(super) fn triangle_blocks_mask<L: Lanes>([det, u, v, t]: [L; 4], tmax: L) -> u32 {
    let abs_det = det.abs();
    let ok_det = !abs_det.lt(L::splat(1e-20)) & lane_mask::<L>() as u32;
    let (u, v, t) = (u.flip_sign(det), v.flip_sign(det), t.flip_sign(det));
    let ok_u = L::splat(0.0).le(u) & u.le(abs_det);
    let miss_v = v.lt(L::splat(0.0)) | abs_det.lt(u.add(v));
    let ok_t = L::splat(0.0).lt(t) & t.lt(tmax.mul(abs_det));
    ok_det & ok_u & !miss_v & ok_t
}

/// From [`triangle_terms`], as [`super::intersect_triangle`] decides: the
/// mask of lanes with a hit at t > 0 (no upper bound applied) and their t.
#[inline(always)]
pub(super) fn triangle_hits<L: Lanes>([det, u, v, t]: [L; 4]) -> (u32, L) {
    let ok_det = !det.abs().lt(L::splat(1e-20)) & lane_mask::<L>() as u32;
    let inv_det = L::splat(1.0).div(det);
    let u = u.mul(inv_det);
    let ok_u = L::splat(0.0).le(u) & u.le(L::splat(1.0));
    let v = v.mul(inv_det);
    let miss_v = v.lt(L::splat(0.0)) | L::splat(1.0).lt(u.add(v));
    let t = t.mul(inv_det);
    let ok_t = L::splat(0.0).lt(t);
    (ok_det & ok_u & !miss_v & ok_t, t)
}

/// The mask of one group of `L::WIDTH` lanes.
#[inline(always)]
pub fn lane_mask<L: Lanes>() -> u64 {
    (1u64 << L::WIDTH) - 1
}

/// Asks the processor to bring the cache lines of `value` closer (a hint:
/// no effect on results; nothing on targets without it).
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        let p = value as *const T as *const i8;
        let lines = std::mem::size_of::<T>().div_ceil(64);
        for l in 0..lines {
            // SAFETY: a prefetch never faults and reads nothing the program
            // sees; the addresses lie within `value` (SSE is x86-64 baseline).
            unsafe { std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.wrapping_add(64 * l)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// A deferred visit: child `slot` of node `node`, for the rays in `mask`.
#[derive(Clone, Copy)]
struct Entry {
    node: u32,
    slot: u32,
    mask: u64,
}

impl<const W: usize> Bvh<W> {
    /// Traces the rays of `mask` in `packet` through the tree. `leaf(first,
    /// count, mixed, rays, packet)` tests a leaf's primitives against the
    /// rays `rays` (those that enter its box), updates their `tmax` and `id`
    /// for a nearest-hit query, and returns the rays that are done (for an
    /// any-hit query: blocked), which the traversal then drops. With
    /// `NEAREST_FIRST`, children are visited nearest first by the packet's
    /// interval bound, so that a nearest hit found early culls the rest;
    /// else in their order in the node, which suits an any-hit query, whose
    /// answer no order changes (shadow rays 1.10× as fast so as sorted:
    /// bench_bvh, 1.1 M triangles, four side-by-side pairs).
    /// `prefetch_leaf(first, count)` starts fetching the blocks of a leaf
    /// of triangles alone when the leaf is entered.
    #[inline(always)]
    pub fn packet<L: Lanes, const NEAREST_FIRST: bool>(
        &self,
        packet: &mut Packet,
        mask: u64,
        mut leaf: impl FnMut(u32, u32, bool, u64, &mut Packet) -> u64,
        prefetch_leaf: impl Fn(u32, u32),
    ) {
        let mut alive = mask & packet.all();
        let mut stack = Stack::new();
        // The root is an inner node whose children all rays may enter.
        let mut expand = Some((0usize, alive));
        loop {
            if let Some((index, rays)) = expand.take() {
                let node = &self.nodes[index];
                let mut bits = 0;
                let mut tnear = [0.0f32; W];
                for q in 0..W / 4 {
                    let (b, t) = packet.children::<L::Four, W>(node, 4 * q);
                    bits |= b << (4 * q);
                    tnear[4 * q..4 * q + 4].copy_from_slice(&t);
                }
                // Push the farthest first, so that the nearest is popped first.
                let mut order = [(0usize, 0.0f32); W];
                let mut n = 0;
                let mut b = bits;
                while b != 0 {
                    let c = b.trailing_zeros() as usize;
                    b &= b - 1;
                    let mut i = n;
                    while NEAREST_FIRST && i > 0 && order[i - 1].1 < tnear[c] {
                        order[i] = order[i - 1];
                        i -= 1;
                    }
                    order[i] = (c, tnear[c]);
                    n += 1;
                }
                for &(c, _) in &order[..n] {
                    stack.push(Entry { node: index as u32, slot: c as u32, mask: rays });
                    // Start fetching what the child holds, which is most
                    // often not in cache yet, while the nearer ones run.
                    if node.count[c] == 0 {
                        prefetch(&self.nodes[node.child[c] as usize]);
                    } else if is_triangle_leaf(node.count[c]) {
                        prefetch_leaf(node.child[c], node.count[c]);
                    }
                }
            }
            if alive == 0 {
                return;
            }
            let Some(e) = stack.pop() else { return };
            let parent = &self.nodes[e.node as usize];
            let slot = e.slot as usize;
            let rays = packet.enter::<L, W>(parent, slot, e.mask & alive);
            if rays == 0 {
                continue;
            }
            let count = parent.count[slot];
            if count != 0 {
                alive &= !leaf(parent.child[slot], count & COUNT_MASK, count & LEAF_MIXED != 0, rays, packet);
            } else {
                expand = Some((parent.child[slot] as usize, rays));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sign_test_is_the_reciprocal_test() {
        let special = [0.0, -0.0, 1e-45, -1e-45, 1e-31, -1e-31, 1.0, -1.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        let mut state = 0x9e37_79b9u32;
        let random = (0..1_000_000).map(|_| {
            // xorshift32 over all bit patterns: every sign, exponent and NaN.
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            f32::from_bits(state)
        });
        for d in special.into_iter().chain(random) {
            assert_eq!(reciprocal_is_negative(d), reciprocal(d) < 0.0, "{d:e} ({:#x})", d.to_bits());
            assert_eq!(reciprocal_is_negative(-d), reciprocal(-d) < 0.0, "{:e}", -d);
        }
    }
}
