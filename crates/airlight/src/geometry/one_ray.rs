//! One ray through the BVH: its nearest hit and whether anything blocks
//! it, with the box tests and a leaf's triangles in SIMD lanes (eight at a
//! time where the processor has AVX, found at run time, and a leaf of four
//! triangles or fewer four at a time with SSE; without AVX, boxes
//! and nearest hits four at a time with SSE and shadow rays' triangles one
//! by one; a portable loop for tests). Every lane type does the same IEEE
//! operations as the one-triangle functions, so the answers do not depend
//! on the processor.

use super::accel::Geometry;
use super::batch::{comes_before, test_bound};
use super::bvh::{BoxRay, Bvh8};
#[cfg(target_arch = "x86_64")]
use super::lanes::{Avx8, has_avx};
use super::lanes::{LaneWidth, Lanes, NativeLanes, Scalar4};
use super::packet::{triangle_blocks_mask, triangle_hits, triangle_terms};
use super::shape::triangle_blocks;
use glam::Vec3;

impl Geometry {
    /// The nearest (t, primitive) in the tree on the segment (0, tmax),
    /// with the box tests eight at a time where the processor has AVX.
    #[inline]
    pub(super) fn nearest_in_tree(
        &self,
        lanes: LaneWidth,
        bvh: &Bvh8,
        o: Vec3,
        d: Vec3,
        tmax: f32,
    ) -> Option<(f32, u32)> {
        match lanes {
            LaneWidth::Portable => self.nearest_in_tree_with::<Scalar4>(bvh, o, d, tmax, |first, count, best| {
                self.leaf_nearest::<Scalar4>(first, count, o, d, best)
            }),
            LaneWidth::Four => self.nearest_in_tree_with::<NativeLanes>(bvh, o, d, tmax, |first, count, best| {
                self.leaf_nearest::<NativeLanes>(first, count, o, d, best)
            }),
            // SAFETY: the processor has AVX (asserted).
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Eight | LaneWidth::Sixteen => {
                assert!(has_avx(), "this processor has no AVX");
                unsafe { self.nearest_in_tree_avx(bvh, o, d, tmax) }
            }
            #[cfg(not(target_arch = "x86_64"))]
            LaneWidth::Eight | LaneWidth::Sixteen => unreachable!("never available here"),
        }
    }

    /// [`Geometry::nearest_in_tree`] compiled for AVX.
    ///
    /// # Safety
    /// The processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn nearest_in_tree_avx(&self, bvh: &Bvh8, o: Vec3, d: Vec3, tmax: f32) -> Option<(f32, u32)> {
        // A closure is compiled without the function's AVX, so the leaf's
        // lanes go through a function of its own that has it.
        #[target_feature(enable = "avx")]
        unsafe fn leaf(g: &Geometry, first: u32, count: u32, o: Vec3, d: Vec3, best: (f32, u32)) -> Option<(f32, u32)> {
            // A leaf of four triangles or fewer fits SSE lanes, which
            // load and compute half what AVX ones do (the same IEEE
            // operations, so the same hits).
            if count <= 4 {
                g.leaf_nearest::<super::lanes::Sse4>(first, count, o, d, best)
            } else {
                g.leaf_nearest::<Avx8>(first, count, o, d, best)
            }
        }
        // SAFETY: the processor has AVX (this function's contract).
        self.nearest_in_tree_with::<Avx8>(bvh, o, d, tmax, |first, count, best| unsafe {
            leaf(self, first, count, o, d, best)
        })
    }

    /// The tree's nearest hit with box tests on lanes `B`, leaves of
    /// triangles alone tested by `triangles(first, count, best)`.
    #[inline(always)]
    fn nearest_in_tree_with<B: Lanes>(
        &self,
        bvh: &Bvh8,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        triangles: impl Fn(u32, u32, (f32, u32)) -> Option<(f32, u32)>,
    ) -> Option<(f32, u32)> {
        let box_ray = BoxRay::new(o.to_array(), d.to_array());
        bvh.closest::<B>(
            &box_ray,
            tmax,
            |first, count, mixed, (mut best_t, mut best_id)| {
                if !mixed {
                    return triangles(first, count, (best_t, best_id));
                }
                let mut found = None;
                for i in first..first + count {
                    let t = self.intersect_one(i as usize, o, d, test_bound(best_t, best_id));
                    if comes_before(t, i, best_t, best_id) {
                        (best_t, best_id) = (t, i);
                        found = Some((t, i));
                    }
                }
                found
            },
            |first, count| self.prefetch_triangles(first, count),
        )
    }

    /// Whether a primitive in the tree blocks the segment, on the given
    /// lanes (as [`Geometry::occluded_on`]).
    #[inline]
    pub(super) fn blocked_in_tree(&self, lanes: LaneWidth, bvh: &Bvh8, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        match lanes {
            LaneWidth::Portable => self.occluded_bvh::<Scalar4>(bvh, origin, dir, tmax),
            LaneWidth::Four => self.occluded_bvh::<NativeLanes>(bvh, origin, dir, tmax),
            // SAFETY: the processor has AVX (asserted).
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Eight | LaneWidth::Sixteen => {
                assert!(has_avx(), "this processor has no AVX");
                unsafe { self.occluded_bvh_avx(bvh, origin, dir, tmax) }
            }
            #[cfg(not(target_arch = "x86_64"))]
            LaneWidth::Eight | LaneWidth::Sixteen => unreachable!("never available here"),
        }
    }

    /// [`Geometry::occluded_bvh`] compiled for AVX.
    ///
    /// # Safety
    /// The processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn occluded_bvh_avx(&self, bvh: &Bvh8, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        #[target_feature(enable = "avx")]
        unsafe fn leaf(g: &Geometry, first: u32, count: u32, o: Vec3, d: Vec3, tmax: f32) -> bool {
            // As for nearest hits: SSE lanes for leaves of four or fewer.
            if count <= 4 {
                g.leaf_blocks::<super::lanes::Sse4>(first, count, o, d, tmax)
            } else {
                g.leaf_blocks::<Avx8>(first, count, o, d, tmax)
            }
        }
        // SAFETY: the processor has AVX (this function's contract).
        self.occluded_bvh_with::<Avx8>(bvh, origin, dir, tmax, |first, count| unsafe {
            leaf(self, first, count, origin, dir, tmax)
        })
    }

    /// Whether one of the `count` triangles in blocks from `first` blocks
    /// the segment, `L::WIDTH` at a time, each lane operation for
    /// operation as [`triangle_blocks`].
    #[inline(always)]
    pub(super) fn leaf_blocks<L: Lanes>(&self, first: u32, count: u32, o: Vec3, d: Vec3, tmax: f32) -> bool {
        let (d4, o4) = (splat::<L>(d), splat::<L>(o));
        let mut left = count as usize;
        for group in self.blocks_of_leaf(first, count).chunks(L::WIDTH.div_ceil(4)) {
            let n = left.min(L::WIDTH);
            left -= n;
            let [v0, e1, e2] = L::triangle_lanes(group);
            let blocked = triangle_blocks_mask(triangle_terms(d4, o4, v0, e1, e2), L::splat(tmax));
            if blocked & ((1u32 << n) - 1) != 0 {
                return true;
            }
        }
        false
    }

    /// Whether a primitive in the tree blocks the segment, with the box
    /// tests `B::WIDTH` at a time.
    #[inline(always)]
    pub(super) fn occluded_bvh<B: Lanes>(&self, bvh: &Bvh8, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        self.occluded_bvh_with::<B>(bvh, origin, dir, tmax, |first, count| {
            self.leaf_triangles(first, count).any(|(_, [v0, e1, e2])| triangle_blocks(v0, e1, e2, origin, dir, tmax))
        })
    }

    #[inline(always)]
    fn occluded_bvh_with<B: Lanes>(
        &self,
        bvh: &Bvh8,
        origin: Vec3,
        dir: Vec3,
        tmax: f32,
        triangles: impl Fn(u32, u32) -> bool,
    ) -> bool {
        let box_ray = BoxRay::new(origin.to_array(), dir.to_array());
        bvh.any::<B>(&box_ray, tmax, |first, count, mixed| {
            if !mixed {
                return triangles(first, count);
            }
            (first..first + count).any(|i| self.intersect_one(i as usize, origin, dir, tmax) < tmax)
        })
    }

    /// Of the `count` triangles in blocks from `first` (a leaf of
    /// triangles alone), the nearest hit that comes before `best` (as
    /// [`comes_before`] orders them), if any: `L::WIDTH` triangles at a
    /// time in SIMD lanes, each lane operation for operation as
    /// [`intersect_triangle`](super::intersect_triangle), and the lanes'
    /// hits then taken in index order against the bound the one-triangle
    /// loop would use, so that the answer is that loop's, bit for bit. A
    /// ray across the inside of a 1.1 M-triangle mesh tests about 19
    /// triangles in 4 leaves.
    #[inline(always)]
    pub(super) fn leaf_nearest<L: Lanes>(
        &self,
        first: u32,
        count: u32,
        o: Vec3,
        d: Vec3,
        best: (f32, u32),
    ) -> Option<(f32, u32)> {
        let (mut best_t, mut best_id) = best;
        let mut found = None;
        let (d4, o4) = (splat::<L>(d), splat::<L>(o));
        let mut left = count as usize;
        for group in self.blocks_of_leaf(first, count).chunks(L::WIDTH.div_ceil(4)) {
            let n = left.min(L::WIDTH);
            left -= n;
            let [v0, e1, e2] = L::triangle_lanes(group);
            let (hits, t) = triangle_hits(triangle_terms(d4, o4, v0, e1, e2));
            let t = t.to_array();
            let mut m = hits & ((1u32 << n) - 1);
            while m != 0 {
                let k = m.trailing_zeros() as usize;
                m &= m - 1;
                let (t, i) = (t[k], group[k / 4].ids[k % 4]);
                if t < test_bound(best_t, best_id) && comes_before(t, i, best_t, best_id) {
                    (best_t, best_id) = (t, i);
                    found = Some((t, i));
                }
            }
        }
        found
    }
}

/// A vector in lanes, the same in each. (Functions rather than closures
/// here: a closure is compiled without the target features of the
/// function it is written in, and where it is not inlined its AVX lanes
/// become calls.)
#[inline(always)]
fn splat<L: Lanes>(v: Vec3) -> [L; 3] {
    [L::splat(v.x), L::splat(v.y), L::splat(v.z)]
}
