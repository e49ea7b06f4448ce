//! A leaf's triangles as blocks of four in structure of arrays: each of
//! the nine floats of (v0, e1, e2) for four triangles side by side, so
//! that one ray's lanes load them as they are (nine loads a block) where
//! triangles stored one after another had to be gathered and transposed
//! in registers (twelve loads and nineteen shuffles for four). The tree's
//! leaves of triangles alone link to their first block; each block names
//! its triangles' primitives. (Embree's Triangle4 leaves are laid out so.)

use super::bvh::Bvh8;
use super::records::{Prim, Record};
use glam::Vec3;

/// Up to four triangles of one leaf: lane k holds triangle k. A leaf's
/// last block repeats its last triangle in the lanes past the leaf's end
/// (so every lane computes on numbers; the callers drop those lanes).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(super) struct TriangleBlock {
    /// v0.x, v0.y, v0.z, e1.x, e1.y, e1.z, e2.x, e2.y, e2.z, each for four
    /// triangles.
    pub(super) rows: [[f32; 4]; 9],
    /// Each lane's primitive (an index into the geometry's records).
    pub(super) ids: [u32; 4],
}

impl TriangleBlock {
    /// Triangles of a leaf, one to four of them as (primitive, [v0, e1, e2]).
    fn new(triangles: &[(u32, [Vec3; 3])]) -> Self {
        debug_assert!((1..=4).contains(&triangles.len()), "one to four triangles a block");
        let mut block = TriangleBlock { rows: [[0.0; 4]; 9], ids: [0; 4] };
        for k in 0..4 {
            let (id, vectors) = triangles[k.min(triangles.len() - 1)];
            block.ids[k] = id;
            for (v, vector) in vectors.iter().enumerate() {
                for a in 0..3 {
                    block.rows[3 * v + a][k] = vector[a];
                }
            }
        }
        block
    }

    /// Lane `k`'s triangle as [v0, e1, e2].
    #[inline(always)]
    pub(super) fn triangle(&self, k: usize) -> [Vec3; 3] {
        let r = &self.rows;
        [
            Vec3::new(r[0][k], r[1][k], r[2][k]),
            Vec3::new(r[3][k], r[4][k], r[5][k]),
            Vec3::new(r[6][k], r[7][k], r[8][k]),
        ]
    }
}

/// The blocks of a leaf of `count` triangles.
#[inline(always)]
pub(super) fn blocks_of(count: u32) -> usize {
    count.div_ceil(4) as usize
}

/// Puts the triangles of every leaf of triangles alone into blocks, in
/// the order the tree's nodes are laid out (so a subtree's blocks lie
/// together too), and links those leaves to their first block.
/// `records` are in the tree's primitive order.
pub(super) fn into_blocks(bvh: &mut Bvh8, records: &[Record]) -> Vec<TriangleBlock> {
    let count = bvh.triangle_leaves().map(|(_, count)| blocks_of(count)).sum();
    let mut blocks = super::pages::vec_in_huge_pages(count);
    let mut leaf = Vec::with_capacity(8);
    bvh.relink_triangle_leaves(|first, count| {
        let at = blocks.len() as u32;
        leaf.clear();
        leaf.extend((first..first + count).map(|i| match records[i as usize].prim {
            Prim::Triangle { v0, e1, e2 } => (i, [v0, e1, e2]),
            _ => unreachable!("a leaf of triangles alone holds only triangles"),
        }));
        blocks.extend(leaf.chunks(4).map(TriangleBlock::new));
        at
    });
    debug_assert_eq!(blocks.len(), count);
    blocks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_holds_its_triangles_and_repeats_the_last_past_the_end() {
        let triangle = |i: u32| {
            let f = i as f32;
            [Vec3::new(f, f + 0.5, -f), Vec3::new(2.0 * f, 0.25, 1.0), Vec3::new(-1.0, f * f, 3.0)]
        };
        for len in 1..=4u32 {
            let leaf: Vec<_> = (0..len).map(|i| (10 + i, triangle(i))).collect();
            let block = TriangleBlock::new(&leaf);
            for k in 0..4u32 {
                let expected = k.min(len - 1);
                assert_eq!(block.triangle(k as usize), triangle(expected), "{len} triangles, lane {k}");
                assert_eq!(block.ids[k as usize], 10 + expected, "{len} triangles, lane {k}");
            }
        }
        assert_eq!((blocks_of(1), blocks_of(4), blocks_of(5), blocks_of(8), blocks_of(9)), (1, 1, 2, 2, 3));
    }
}
