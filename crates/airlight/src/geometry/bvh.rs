//! A wide BVH traversed with SIMD box tests: nodes of eight children (made
//! from obvhs's binary tree in `collapse.rs`) whose boxes are stored as
//! structure of arrays, so that one node is four cache lines and its eight
//! slab tests are a handful of AVX instructions (or twice as many SSE ones
//! where the processor has no AVX; every lane type does the same IEEE
//! operations, so the hits do not depend on the processor).
//!
//! Why eight children rather than four: a ray descends half as many levels,
//! and each level is a wait on memory when the tree and triangles exceed
//! the cache. On a 1.1 M-triangle mesh, one ray at a time, incoherent rays
//! across its inside ran 1.32× as fast with eight as with four and out of
//! it 1.20×, camera and shadow rays 1.27× and 1.29×, and packets of
//! coherent rays 1.17× and 1.11× (bench_bvh, 6 side-by-side pairs;
//! BENCHMARKS.md has the figures). The width is a parameter of the types
//! so that tests can compare trees of both widths.
//!
//! Why not obvhs's own traversal of its compressed 8-wide BVH: on a 1.1 M
//! triangle mesh it reached 1.6 M rays/s per core, its cost in decoding the
//! quantised child boxes one by one (BENCHMARKS.md has the figures).

use super::lanes::Lanes;

/// W children's boxes and links. A child slot is a leaf if its count is
/// non-zero (`child` is then the first primitive, or the first block of a
/// leaf of triangles alone once [`Bvh::relink_triangle_leaves`] has
/// linked it, and `count & COUNT_MASK` the number of primitives), an inner
/// node if its count is zero, and empty if its box is empty (min = +∞,
/// max = −∞, which no ray hits).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node<const W: usize> {
    /// min x, min y, min z, max x, max y, max z, each for W children.
    pub(super) bounds: [[f32; W]; 6],
    pub(super) child: [u32; W],
    pub(super) count: [u32; W],
}

/// Set in a leaf's count when one of its primitives is not a triangle, so
/// that the caller takes its general path.
pub const LEAF_MIXED: u32 = 1 << 31;
pub(super) const COUNT_MASK: u32 = !LEAF_MIXED;

/// Entries the traversal stack holds: W − 1 per level below the root, plus
/// one (`Bvh::MAX_DEPTH`).
pub(super) const STACK_SIZE: usize = 256;

impl<const W: usize> Node<W> {
    pub(super) const EMPTY: Self = Node {
        bounds: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
        child: [u32::MAX; W],
        count: [0; W],
    };
}

/// The wide tree. Primitive indices in leaves are positions in the order
/// the collapse returns with it (until leaves are relinked to blocks).
#[derive(Clone, Debug)]
pub struct Bvh<const W: usize> {
    pub(super) nodes: Vec<Node<W>>,
    pub(super) depth: usize,
}

/// The tree the geometry uses: eight children a node.
pub type Bvh8 = Bvh<8>;

/// A ray prepared for box tests: which bound is near on each axis, the
/// origin, and the reciprocal direction with zeros replaced by tiny values
/// (so that no 0·∞ appears and every slab distance is a number).
#[derive(Clone, Copy)]
pub struct BoxRay {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    /// Index into `bounds` of the near plane on each axis (0..3 or 3..6).
    near: [usize; 3],
}

impl BoxRay {
    #[inline]
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Self {
        let mut inv_dir = [0.0; 3];
        let mut near = [0; 3];
        for a in 0..3 {
            inv_dir[a] = super::packet::reciprocal(dir[a]);
            near[a] = if inv_dir[a] >= 0.0 { a } else { a + 3 };
        }
        BoxRay { origin, inv_dir, near }
    }
}

/// Grows the far slab distance by a few ulps so that rounding never culls a
/// box the ray grazes (Ize, "Robust BVH ray traversal", 2013).
pub(super) const FAR_SCALE: f32 = 1.0 + 4.0 * f32::EPSILON;

/// The entry distances of the W children and a bit mask of those the ray
/// segment [0, tmax] enters, `B::WIDTH` children at a time (eight in one
/// AVX register, or four in an SSE one). Every lane type does the same
/// IEEE operations, so the answer does not depend on the processor.
#[inline(always)]
fn hit<B: Lanes, const W: usize>(node: &Node<W>, ray: &BoxRay, tmax: f32) -> (u32, [f32; W]) {
    debug_assert_eq!(W % B::WIDTH, 0, "whole lane groups per node");
    let mut mask = 0;
    let mut out = [0.0f32; W];
    let mut at = 0;
    while at < W {
        let n = [
            slab::<B, W>(node, ray, at, ray.near[0], 0),
            slab::<B, W>(node, ray, at, ray.near[1], 1),
            slab::<B, W>(node, ray, at, ray.near[2], 2),
        ];
        let f = [
            slab::<B, W>(node, ray, at, far_row(ray.near[0], 0), 0),
            slab::<B, W>(node, ray, at, far_row(ray.near[1], 1), 1),
            slab::<B, W>(node, ray, at, far_row(ray.near[2], 2), 2),
        ];
        let tnear = n[0].max(n[1]).max(n[2].max(B::splat(0.0)));
        let tfar = f[0].min(f[1]).min(f[2].min(B::splat(tmax))).mul(B::splat(FAR_SCALE));
        mask |= tnear.le(tfar) << at;
        out[at..at + B::WIDTH].copy_from_slice(tnear.to_array().as_ref());
        at += B::WIDTH;
    }
    (mask, out)
}

/// The distances at which the ray crosses the planes of bounds row `row`
/// (axis `axis`) of children `at .. at + B::WIDTH`. A function, not a
/// closure: a closure is compiled without the target features of the
/// function it is written in, and where LLVM does not inline it (with the
/// crate in one codegen unit it did not) every lane operation in it
/// becomes a call: rays one at a time through a mesh ran 5× slower so.
#[inline(always)]
fn slab<B: Lanes, const W: usize>(node: &Node<W>, ray: &BoxRay, at: usize, row: usize, axis: usize) -> B {
    B::load(&node.bounds[row][at..]).sub(B::splat(ray.origin[axis])).mul(B::splat(ray.inv_dir[axis]))
}

/// The row of the far plane on an axis, given the near plane's row.
#[inline(always)]
pub(super) fn far_row(near: usize, axis: usize) -> usize {
    if near == axis { axis + 3 } else { axis }
}

/// A stack entry: a child link and the distance at which the ray enters it.
#[derive(Clone, Copy)]
struct Entry {
    child: u32,
    count: u32,
    tnear: f32,
}

/// A traversal stack, left uninitialised: zeroing it per ray (2 KB then,
/// with four children a node; 3 KB now) cost more than the traversal of a
/// coherent ray. (Per packet it was 4 KB, which callgrind counted as 7.6%
/// of the instructions of a direct render's batches but which took no
/// measurable time.)
pub(super) struct Stack<T: Copy> {
    entries: [std::mem::MaybeUninit<T>; STACK_SIZE],
    top: usize,
}

impl<T: Copy> Stack<T> {
    #[inline(always)]
    pub(super) fn new() -> Self {
        Stack { entries: [std::mem::MaybeUninit::uninit(); STACK_SIZE], top: 0 }
    }

    /// Pushes an entry; the tree's depth (checked at build, `Bvh::MAX_DEPTH`)
    /// bounds the entries, and an overflow panics rather than corrupts.
    #[inline(always)]
    pub(super) fn push(&mut self, e: T) {
        self.entries[self.top] = std::mem::MaybeUninit::new(e);
        self.top += 1;
    }

    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.top == 0 {
            return None;
        }
        self.top -= 1;
        // SAFETY: every slot below `top` was written by `push`.
        Some(unsafe { self.entries[self.top].assume_init() })
    }
}

impl<const W: usize> Bvh<W> {
    /// The deepest tree the traversal stack can hold.
    pub const MAX_DEPTH: usize = (STACK_SIZE - 1) / (W - 1);

    /// The (first primitive, count) of every leaf of triangles alone (not
    /// marked [`LEAF_MIXED`]), in the order the nodes are laid out.
    pub(super) fn triangle_leaves(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.nodes.iter().flat_map(|node| {
            (0..W).filter(|&c| is_triangle_leaf(node.count[c])).map(|c| (node.child[c], node.count[c]))
        })
    }

    /// Links every leaf of triangles alone to `link(first, count)` in place
    /// of its first primitive, leaves in the order of
    /// [`Bvh::triangle_leaves`].
    pub(super) fn relink_triangle_leaves(&mut self, mut link: impl FnMut(u32, u32) -> u32) {
        for node in &mut self.nodes {
            for c in 0..W {
                if is_triangle_leaf(node.count[c]) {
                    node.child[c] = link(node.child[c], node.count[c]);
                }
            }
        }
    }

    /// Levels of nodes, the root's included.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// The nearest hit on the segment (0, tmax): `leaf(first, count, mixed,
    /// best)` tests a leaf's primitives and returns its nearest hit that
    /// comes before `best` = (t, primitive) — closer, or as close with a
    /// lower primitive index (u32::MAX while there is none) —, if any.
    /// Returns the nearest (t, primitive), of equal distances the lowest
    /// index, so that the answer does not depend on the order of visits.
    /// `prefetch_leaf(first, count)` starts fetching the blocks of a leaf
    /// of triangles alone when the leaf is found ahead of its visit (a
    /// mixed leaf's link is a primitive, not a block, so none is asked): incoherent rays wait on
    /// memory most of their time, and rays across the inside of a 1.1 M
    /// triangle mesh ran 1.2× as fast so (child nodes are fetched ahead too).
    #[inline]
    pub fn closest<B: Lanes>(
        &self,
        ray: &BoxRay,
        tmax: f32,
        mut leaf: impl FnMut(u32, u32, bool, (f32, u32)) -> Option<(f32, u32)>,
        prefetch_leaf: impl Fn(u32, u32),
    ) -> Option<(f32, u32)> {
        let mut best: Option<(f32, u32)> = None;
        let mut best_t = tmax;
        let mut stack = Stack::new();
        let mut current = Entry { child: 0, count: 0, tnear: 0.0 };
        loop {
            if current.count != 0 {
                let mixed = current.count & LEAF_MIXED != 0;
                let best_id = best.map_or(u32::MAX, |b| b.1);
                if let Some(hit) = leaf(current.child, current.count & COUNT_MASK, mixed, (best_t, best_id)) {
                    best_t = hit.0;
                    best = Some(hit);
                }
            } else {
                let node = &self.nodes[current.child as usize];
                let (mask, tnear) = hit::<B, W>(node, ray, best_t);
                if mask != 0 {
                    // The next child: the nearest of those entered, the
                    // others pushed, each prefetched. One or two children
                    // entered, the common cases, take no sort: the step from
                    // a node to its child is a chain of dependent loads.
                    // (Inline here: as a function taking the stack by
                    // reference, LLVM zeroed the 3 KB stack for every ray.)
                    let entry = |c: usize| {
                        let e = Entry { child: node.child[c], count: node.count[c], tnear: tnear[c] };
                        if e.count == 0 {
                            super::packet::prefetch(&self.nodes[e.child as usize]);
                        } else if is_triangle_leaf(e.count) {
                            prefetch_leaf(e.child, e.count);
                        }
                        e
                    };
                    let first = entry(mask.trailing_zeros() as usize);
                    let rest = mask & (mask - 1);
                    if rest == 0 {
                        current = first;
                        continue;
                    }
                    let second = entry(rest.trailing_zeros() as usize);
                    let mut bits = rest & (rest - 1);
                    if bits == 0 {
                        // Of equal distances the later child first, as below.
                        let (near, far) = if first.tnear < second.tnear { (first, second) } else { (second, first) };
                        stack.push(far);
                        current = near;
                        continue;
                    }
                    // Three or more: by decreasing distance, the nearest last.
                    let mut hits = [first; W];
                    let mut n = 1;
                    let mut e = second;
                    loop {
                        let mut i = n;
                        while i > 0 && hits[i - 1].tnear < e.tnear {
                            hits[i] = hits[i - 1];
                            i -= 1;
                        }
                        hits[i] = e;
                        n += 1;
                        if bits == 0 {
                            break;
                        }
                        let c = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        e = entry(c);
                    }
                    for e in &hits[..n - 1] {
                        stack.push(*e);
                    }
                    current = hits[n - 1];
                    continue;
                }
            }
            // Pop the next child the ray may still reach before its best hit.
            loop {
                let Some(e) = stack.pop() else { return best };
                if e.tnear <= best_t {
                    current = e;
                    break;
                }
            }
        }
    }

    /// Whether `leaf(first, count, mixed)` finds a hit in any leaf that the
    /// segment (0, tmax) enters; stops at the first.
    #[inline]
    pub fn any<B: Lanes>(&self, ray: &BoxRay, tmax: f32, mut leaf: impl FnMut(u32, u32, bool) -> bool) -> bool {
        let mut stack = Stack::new();
        stack.push(Entry { child: 0, count: 0, tnear: 0.0 });
        while let Some(current) = stack.pop() {
            if current.count != 0 {
                if leaf(current.child, current.count & COUNT_MASK, current.count & LEAF_MIXED != 0) {
                    return true;
                }
                continue;
            }
            let node = &self.nodes[current.child as usize];
            let (mut bits, _) = hit::<B, W>(node, ray, tmax);
            while bits != 0 {
                let c = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                stack.push(Entry { child: node.child[c], count: node.count[c], tnear: 0.0 });
            }
        }
        false
    }
}

/// Whether a child slot's count is that of a leaf of triangles alone.
pub(super) fn is_triangle_leaf(count: u32) -> bool {
    count != 0 && count & LEAF_MIXED == 0
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geometry::batch::comes_before;
    use crate::geometry::collapse::{CollapseCosts, collapse};
    use crate::geometry::lanes::{NativeLanes, Scalar4};
    use crate::geometry::shape::intersect_triangle;
    use glam::{Vec3, Vec3A};
    use obvhs::bvh2::Bvh2;
    use obvhs::{BvhBuildParams, triangle::Triangle};
    use std::time::Duration;

    /// Numbers in [0, 1) from a fixed xorshift sequence.
    fn uniform(state: &mut u32) -> f32 {
        *state ^= *state << 13;
        *state ^= *state >> 17;
        *state ^= *state << 5;
        (*state >> 8) as f32 / (1u32 << 24) as f32
    }

    /// `count` small triangles scattered through the unit cube (drawn from
    /// `seed`) and the binary tree over them, whose leaves hold at most
    /// `leaf_size` each.
    pub(in crate::geometry) fn scene(seed: u32, count: usize, leaf_size: u32) -> (Bvh2, Vec<[Vec3; 3]>) {
        let mut state = seed;
        let mut point = |scale: f32| Vec3::new(uniform(&mut state), uniform(&mut state), uniform(&mut state)) * scale;
        let triangles: Vec<Triangle> = (0..count)
            .map(|_| {
                let v0 = point(1.0);
                let (a, b) = (point(0.3) - 0.15, point(0.3) - 0.15);
                Triangle { v0: v0.into(), v1: Vec3A::from(v0 + a), v2: Vec3A::from(v0 + b) }
            })
            .collect();
        let params = BvhBuildParams { max_prims_per_leaf: leaf_size, ..BvhBuildParams::medium_build() };
        let bvh2 = obvhs::bvh2::builder::build_bvh2(&triangles, params, &mut Duration::default());
        (bvh2, triangles.iter().map(|t| [t.v0, t.v1, t.v2].map(Vec3::from)).collect())
    }

    /// The nearest hit of all triangles on (0, ∞), ties to the lowest index.
    fn nearest_of_all(triangles: &[[Vec3; 3]], o: Vec3, d: Vec3) -> Option<(f32, u32)> {
        let mut best = None;
        for (i, [v0, v1, v2]) in triangles.iter().enumerate() {
            let t = intersect_triangle(*v0, *v1 - *v0, *v2 - *v0, o, d, 0.0, f32::INFINITY);
            if t < best.map_or(f32::INFINITY, |b: (f32, u32)| b.0) {
                best = Some((t, i as u32));
            }
        }
        best
    }

    /// The tree's nearest hit, with box tests on lanes `B`.
    fn nearest<B: Lanes, const W: usize>(
        bvh: &Bvh<W>,
        triangles: &[[Vec3; 3]],
        o: Vec3,
        d: Vec3,
    ) -> Option<(f32, u32)> {
        let ray = BoxRay::new(o.to_array(), d.to_array());
        let leaf = |first: u32, count: u32, _mixed: bool, (mut best_t, mut best_id): (f32, u32)| {
            let mut found = None;
            for i in first..first + count {
                let [v0, v1, v2] = triangles[i as usize];
                let t = intersect_triangle(v0, v1 - v0, v2 - v0, o, d, 0.0, f32::INFINITY);
                if comes_before(t, i, best_t, best_id) {
                    (best_t, best_id) = (t, i);
                    found = Some((t, i));
                }
            }
            found
        };
        bvh.closest::<B>(&ray, f32::INFINITY, leaf, |_, _| {})
    }

    /// Whether the tree finds a triangle on (0, tmax), box tests on lanes `B`.
    fn blocked<B: Lanes, const W: usize>(bvh: &Bvh<W>, triangles: &[[Vec3; 3]], o: Vec3, d: Vec3, tmax: f32) -> bool {
        let ray = BoxRay::new(o.to_array(), d.to_array());
        bvh.any::<B>(&ray, tmax, |first, count, _| {
            (first..first + count).any(|i| {
                let [v0, v1, v2] = triangles[i as usize];
                intersect_triangle(v0, v1 - v0, v2 - v0, o, d, 0.0, tmax) < tmax
            })
        })
    }

    /// Every tree width and lane type against a test of every triangle:
    /// the same nearest hit (distance and triangle) and the same answer to
    /// "is the segment blocked", over rays from inside and around the cube.
    fn check<B: Lanes, const W: usize>(bvh2: &Bvh2, triangles: &[[Vec3; 3]]) -> usize {
        let (bvh, order) = collapse::<W>(bvh2, |_| true, &CollapseCosts::MESH);
        let triangles: Vec<_> = order.iter().map(|&i| triangles[i as usize]).collect();
        let triangles = &triangles[..];
        assert!(bvh.depth() <= Bvh::<W>::MAX_DEPTH);
        let mut state = 0x9e37_79b9;
        let mut hits = 0;
        for _ in 0..3000 {
            let o = Vec3::new(uniform(&mut state), uniform(&mut state), uniform(&mut state)) * 1.4 - 0.2;
            let d = (Vec3::new(uniform(&mut state), uniform(&mut state), uniform(&mut state)) * 2.0 - 1.0).normalize();
            let expected = nearest_of_all(triangles, o, d);
            assert_eq!(nearest::<B, W>(&bvh, triangles, o, d), expected, "W = {W}, ray {o} {d}");
            let tmax = uniform(&mut state) * 1.5;
            let expected_blocked = triangles
                .iter()
                .any(|[v0, v1, v2]| intersect_triangle(*v0, *v1 - *v0, *v2 - *v0, o, d, 0.0, tmax) < tmax);
            assert_eq!(
                blocked::<B, W>(&bvh, triangles, o, d, tmax),
                expected_blocked,
                "W = {W}, ray {o} {d} to {tmax}"
            );
            hits += expected.is_some() as usize;
        }
        hits
    }

    /// Binary trees of one triangle a leaf (as the geometry builds them)
    /// and of up to eight (whose leaves the collapse keeps whole).
    #[test]
    fn trees_of_four_and_eight_find_what_a_test_of_every_triangle_finds() {
        for leaf_size in [1, 8] {
            let (bvh2, triangles) = scene(0x1234_5678, 1000, leaf_size);
            let hits = check::<Scalar4, 4>(&bvh2, &triangles);
            // Enough rays hit and miss for the comparison to mean something.
            assert!((500..2500).contains(&hits), "{hits} of 3000 rays hit");
            check::<NativeLanes, 4>(&bvh2, &triangles);
            check::<Scalar4, 8>(&bvh2, &triangles);
            check::<NativeLanes, 8>(&bvh2, &triangles);
            #[cfg(target_arch = "x86_64")]
            {
                use crate::geometry::lanes::{Avx8, has_avx};
                if has_avx() {
                    #[target_feature(enable = "avx")]
                    unsafe fn with_avx(bvh2: &Bvh2, triangles: &[[Vec3; 3]]) {
                        check::<Avx8, 8>(bvh2, triangles);
                    }
                    // SAFETY: the processor has AVX (checked above).
                    unsafe { with_avx(&bvh2, &triangles) };
                } else {
                    eprintln!("AVX lanes skipped: this processor has no AVX");
                }
            }
        }
    }
}
