//! A 4-wide BVH traversed with SIMD box tests: obvhs builds a binary tree
//! (PLOC, reinsertion, SAH leaf collapse), which is flattened here into nodes
//! of four children whose boxes are stored as structure of arrays, so that
//! one node is two cache lines and its four slab tests are a handful of
//! SSE instructions (x86-64 always has SSE2; other targets use a scalar loop
//! with the same arithmetic).
//!
//! Why not obvhs's own traversal of its compressed 8-wide BVH: on a 1.1 M
//! triangle mesh it reached 1.6 M rays/s per core, its cost in decoding the
//! quantised child boxes one by one (BENCHMARKS.md has the figures).

use obvhs::bvh2::Bvh2;

/// Four children's boxes and links. A child slot is a leaf if its count is
/// non-zero (`child` is then the first primitive, `count & COUNT_MASK` the
/// number of primitives), an inner node if its count is zero, and empty if
/// its box is empty (min = +∞, max = −∞, which no ray hits).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node4 {
    /// min x, min y, min z, max x, max y, max z, each for four children.
    pub(super) bounds: [[f32; 4]; 6],
    pub(super) child: [u32; 4],
    pub(super) count: [u32; 4],
}

/// Set in a leaf's count when one of its primitives is not a triangle, so
/// that the caller takes its general path.
pub const LEAF_MIXED: u32 = 1 << 31;
pub(super) const COUNT_MASK: u32 = !LEAF_MIXED;

/// Entries the traversal stack holds: three per level below the root, plus one.
pub(super) const STACK_SIZE: usize = 192;
/// The deepest tree the stack can hold.
pub const MAX_DEPTH: usize = (STACK_SIZE - 1) / 3;

const EMPTY: Node4 = Node4 {
    bounds: [
        [f32::INFINITY; 4],
        [f32::INFINITY; 4],
        [f32::INFINITY; 4],
        [f32::NEG_INFINITY; 4],
        [f32::NEG_INFINITY; 4],
        [f32::NEG_INFINITY; 4],
    ],
    child: [u32::MAX; 4],
    count: [0; 4],
};

/// The flattened tree. Primitive indices in leaves are positions in the
/// obvhs tree's `primitive_indices` order.
#[derive(Clone, Debug)]
pub struct Bvh4 {
    pub(super) nodes: Vec<Node4>,
    depth: usize,
}

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

/// The entry distances of the four children and a bit mask of those the ray
/// segment [0, tmax] enters.
#[inline(always)]
fn hit4(node: &Node4, ray: &BoxRay, tmax: f32) -> (u32, [f32; 4]) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE and SSE2 are part of the x86-64 baseline; the loads read
    // the node's 16-byte aligned rows (the node is 64-byte aligned and each
    // row is 16 bytes).
    unsafe {
        use std::arch::x86_64::*;
        let b = &node.bounds;
        let slab = |row: usize, axis: usize| {
            let plane = _mm_load_ps(b[row].as_ptr());
            _mm_mul_ps(_mm_sub_ps(plane, _mm_set1_ps(ray.origin[axis])), _mm_set1_ps(ray.inv_dir[axis]))
        };
        let n = [slab(ray.near[0], 0), slab(ray.near[1], 1), slab(ray.near[2], 2)];
        let f = [slab(far_row(ray.near[0], 0), 0), slab(far_row(ray.near[1], 1), 1), slab(far_row(ray.near[2], 2), 2)];
        let tnear = _mm_max_ps(_mm_max_ps(n[0], n[1]), _mm_max_ps(n[2], _mm_setzero_ps()));
        let tfar = _mm_min_ps(_mm_min_ps(f[0], f[1]), _mm_min_ps(f[2], _mm_set1_ps(tmax)));
        let tfar = _mm_mul_ps(tfar, _mm_set1_ps(FAR_SCALE));
        let mask = _mm_movemask_ps(_mm_cmple_ps(tnear, tfar)) as u32;
        let mut out = [0.0f32; 4];
        _mm_storeu_ps(out.as_mut_ptr(), tnear);
        (mask, out)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let mut mask = 0;
        let mut out = [0.0f32; 4];
        for c in 0..4 {
            let mut tnear = 0.0f32;
            let mut tfar = tmax;
            for a in 0..3 {
                let n = (node.bounds[ray.near[a]][c] - ray.origin[a]) * ray.inv_dir[a];
                let f = (node.bounds[far_row(ray.near[a], a)][c] - ray.origin[a]) * ray.inv_dir[a];
                tnear = tnear.max(n);
                tfar = tfar.min(f);
            }
            if tnear <= tfar * FAR_SCALE {
                mask |= 1 << c;
            }
            out[c] = tnear;
        }
        (mask, out)
    }
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

/// The traversal stack, left uninitialised: zeroing 2 KB per ray cost more
/// than the traversal of a coherent ray.
struct Stack {
    entries: [std::mem::MaybeUninit<Entry>; STACK_SIZE],
    top: usize,
}

impl Stack {
    #[inline(always)]
    fn new() -> Self {
        Stack { entries: [std::mem::MaybeUninit::uninit(); STACK_SIZE], top: 0 }
    }

    /// Pushes an entry; the tree's depth (checked at build, `MAX_DEPTH`)
    /// bounds the entries, and an overflow panics rather than corrupts.
    #[inline(always)]
    fn push(&mut self, e: Entry) {
        self.entries[self.top] = std::mem::MaybeUninit::new(e);
        self.top += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<Entry> {
        if self.top == 0 {
            return None;
        }
        self.top -= 1;
        // SAFETY: every slot below `top` was written by `push`.
        Some(unsafe { self.entries[self.top].assume_init() })
    }
}

impl Bvh4 {
    /// Flattens an obvhs binary tree. Each node takes the two children of a
    /// binary node and then repeatedly splits its largest inner child into
    /// that child's two children, until it has four. Nodes are laid out
    /// depth first (a node, then the whole subtree of its first inner
    /// child, then of its second, …): against siblings side by side,
    /// incoherent rays out of a 1.1 M-triangle mesh ran 1.12× as fast and
    /// rays across its inside 1.05× (bench_bvh, 4 side-by-side pairs each),
    /// with the same tree and so the same hits.
    pub fn from_bvh2(bvh2: &Bvh2, mixed: impl Fn(u32, u32) -> bool) -> Self {
        let mut nodes = Vec::with_capacity(bvh2.nodes.len() / 2 + 1);
        nodes.push(EMPTY);
        let root = &bvh2.nodes[0];
        let mut depth = 1;
        if root.is_leaf() {
            set_child(&mut nodes[0], 0, bvh2, 0, u32::MAX, &mixed);
        } else {
            // Depth first, each node placed right after its parent's slot
            // is filled: (bvh2 node, the parent's node and child slot that
            // link to it, level).
            let mut work = vec![(0usize, None::<(usize, usize)>, 1usize)];
            while let Some((b2, parent, level)) = work.pop() {
                depth = depth.max(level);
                let slot = match parent {
                    None => 0,
                    Some((p, c)) => {
                        nodes.push(EMPTY);
                        let index = nodes.len() - 1;
                        nodes[p].child[c] = index as u32;
                        index
                    }
                };
                let mut kids: Vec<usize> = {
                    let f = bvh2.nodes[b2].first_index as usize;
                    vec![f, f + 1]
                };
                while kids.len() < 4 {
                    let widest = kids
                        .iter()
                        .enumerate()
                        .filter(|(_, k)| !bvh2.nodes[**k].is_leaf())
                        .max_by(|a, b| area(bvh2, *a.1).total_cmp(&area(bvh2, *b.1)))
                        .map(|(i, _)| i);
                    let Some(i) = widest else { break };
                    let f = bvh2.nodes[kids[i]].first_index as usize;
                    kids[i] = f;
                    kids.insert(i + 1, f + 1);
                }
                // Pushed last to first, so that the first child is placed next.
                for (c, &k) in kids.iter().enumerate().rev() {
                    if bvh2.nodes[k].is_leaf() {
                        set_child(&mut nodes[slot], c, bvh2, k, u32::MAX, &mixed);
                    } else {
                        set_child(&mut nodes[slot], c, bvh2, k, 0, &mixed);
                        work.push((k, Some((slot, c)), level + 1));
                    }
                }
            }
        }
        Bvh4 { nodes, depth }
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
    /// `prefetch_leaf(first, count)` starts fetching a leaf's primitives
    /// when the leaf is found ahead of its visit: incoherent rays wait on
    /// memory most of their time, and rays across the inside of a 1.1 M
    /// triangle mesh ran 1.2× as fast so (child nodes are fetched ahead too).
    #[inline]
    pub fn closest(
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
                let (mask, tnear) = hit4(node, ray, best_t);
                let mut hits = [Entry { child: 0, count: 0, tnear: 0.0 }; 4];
                let mut n = 0;
                let mut bits = mask;
                while bits != 0 {
                    let c = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    // Sorted by decreasing distance: the nearest goes on top.
                    let e = Entry { child: node.child[c], count: node.count[c], tnear: tnear[c] };
                    if e.count != 0 {
                        prefetch_leaf(e.child, e.count & COUNT_MASK);
                    } else {
                        super::packet::prefetch(&self.nodes[e.child as usize]);
                    }
                    let mut i = n;
                    while i > 0 && hits[i - 1].tnear < e.tnear {
                        hits[i] = hits[i - 1];
                        i -= 1;
                    }
                    hits[i] = e;
                    n += 1;
                }
                if n > 0 {
                    // The nearest child next; the others wait on the stack.
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
    pub fn any(&self, ray: &BoxRay, tmax: f32, mut leaf: impl FnMut(u32, u32, bool) -> bool) -> bool {
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
            let (mut bits, _) = hit4(node, ray, tmax);
            while bits != 0 {
                let c = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                stack.push(Entry { child: node.child[c], count: node.count[c], tnear: 0.0 });
            }
        }
        false
    }
}

fn area(bvh2: &Bvh2, node: usize) -> f32 {
    bvh2.nodes[node].aabb().half_area()
}

/// Fills child slot `c` of `node` from binary node `k`: an inner child at
/// `inner`, or (if `inner` is u32::MAX) a leaf.
fn set_child(node: &mut Node4, c: usize, bvh2: &Bvh2, k: usize, inner: u32, mixed: &impl Fn(u32, u32) -> bool) {
    let b = bvh2.nodes[k].aabb();
    for a in 0..3 {
        node.bounds[a][c] = b.min[a];
        node.bounds[a + 3][c] = b.max[a];
    }
    let n = &bvh2.nodes[k];
    if inner == u32::MAX {
        node.child[c] = n.first_index;
        let flag = if mixed(n.first_index, n.prim_count) { LEAF_MIXED } else { 0 };
        node.count[c] = n.prim_count | flag;
    } else {
        node.child[c] = inner;
        node.count[c] = 0;
    }
}
