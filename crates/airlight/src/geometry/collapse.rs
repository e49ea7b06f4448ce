//! Nodes of W children made from a binary tree of one primitive a leaf,
//! choosing by dynamic programming which binary subtrees become leaves,
//! which inner nodes, and which are opened so that their children fill a
//! wide node's slots, each choice the cheapest by the surface area
//! heuristic (Ylitie, Karras and Laine, "Efficient incoherent ray
//! traversal on GPUs through compressed wide BVHs", 2017). A leaf's cost
//! counts the blocks of four triangles its lanes test, not its triangles,
//! since a block of one triangle costs as much as one of four.
//!
//! Against obvhs's own leaf collapse (which counts triangles) followed by
//! filling each wide node by opening its widest inner child, on a
//! 1.1 M-triangle mesh: 7.44 children a node instead of 4.14, a ray's
//! expected visits 13.7 nodes and 3.8 blocks instead of 14.2 and 4.6, and
//! incoherent rays one at a time 1.05–1.09× as fast (BENCHMARKS.md has the
//! figures).

use super::blocks::blocks_of;
use super::bvh::{Bvh, COUNT_MASK, LEAF_MIXED, Node};
use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;

/// What a ray's visit costs, in units of one inner node's box tests, per
/// unit of the visited box's area (its probability of being entered).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollapseCosts {
    /// A leaf's visit before its primitives: the jump and the lanes' setup.
    pub leaf: f32,
    /// One block of up to four triangles.
    pub block: f32,
    /// One primitive that is not a triangle (tested on its own).
    pub other: f32,
    /// The most triangles a leaf may hold.
    pub max_leaf: u32,
}

impl CollapseCosts {
    /// Leaves of up to eight triangles (two blocks, one AVX test); the
    /// leaf and block costs are rough shares of a ray's time (its inner
    /// nodes took 45% of it and its leaves 37%, 18.5 nodes and 4.1 leaves
    /// a ray, across the inside of a mesh). Costs of (0.5, 0.5) and
    /// (0.2, 1.0) and leaves of up to four traced as fast within the
    /// noise of one pass.
    pub const MESH: Self = CollapseCosts { leaf: 0.3, block: 0.6, other: 1.0, max_leaf: 8 };

    /// The cost of a leaf of `triangles` triangles and `others` other
    /// primitives (tested one by one where there are any).
    fn leaf_cost(&self, triangles: u32, others: u32) -> f32 {
        if others == 0 {
            self.leaf + self.block * blocks_of(triangles) as f32
        } else {
            self.leaf + self.other * (triangles + others) as f32
        }
    }
}

/// The cost of a binary subtree represented as at most i wide-tree roots
/// (leaves or inner nodes), for i = 1 ..= W, and how each was reached.
struct Choices<const W: usize> {
    /// `cost[n][i - 1]`: the cheapest forest of at most i roots for node n.
    cost: Vec<[f32; W]>,
    /// `how[n][i - 1]`: for i = 1, [`LEAF`] (always for a binary leaf) or
    /// [`INNER`]; for i > 1, 0 to take the forest of i − 1 roots, or k to
    /// give k roots to the first child and i − k to the second.
    how: Vec<[u8; W]>,
    /// For an inner node: the first child's share of the W slots.
    split: Vec<u8>,
}

const LEAF: u8 = 0;
const INNER: u8 = 1;

/// Collapses `bvh2` (whose leaves need not hold one primitive each, but
/// whose larger leaves are kept whole) into a tree of W-wide nodes.
/// Nodes are laid out depth first (a node, then the whole subtree of its
/// first inner child, then of its second, …): against siblings side by
/// side, incoherent rays out of a 1.1 M-triangle mesh ran 1.12× as fast
/// and rays across its inside 1.05× (bench_bvh, 4 side-by-side pairs
/// each, measured on four-wide trees). Returns the tree and the primitives'
/// order: leaf ranges index that order, whose entries are the caller's
/// primitive indices (`bvh2.primitive_indices` values).
/// `is_triangle(primitive)` tells triangles from other primitives.
pub(super) fn collapse<const W: usize>(
    bvh2: &Bvh2,
    is_triangle: impl Fn(u32) -> bool,
    costs: &CollapseCosts,
) -> (Bvh<W>, Vec<u32>) {
    let nodes = &bvh2.nodes;
    let mut order = Vec::with_capacity(bvh2.primitive_indices.len());
    let mut wide = super::pages::vec_in_huge_pages(nodes.len() / (2 * (W - 1)) + 1);
    wide.push(Node::EMPTY);
    if nodes[0].is_leaf() {
        let mixed = leaf(bvh2, 0, &is_triangle, &mut Vec::new(), &mut order);
        set_leaf(&mut wide[0], 0, bvh2, 0, 0, order.len() as u32, mixed);
        super::pages::move_to_huge_pages(&wide);
        return (Bvh { nodes: wide, depth: 1 }, order);
    }
    let mut choices = choose::<W>(bvh2, &is_triangle, costs);
    // The costs are spent; the records' reordering to come needs the room.
    choices.cost = Vec::new();
    let mut depth = 1;
    let mut roots = Vec::with_capacity(W);
    let mut subtree = Vec::new();
    // (binary node, the wide parent's node and slot that link to it, level).
    let mut work = vec![(0usize, None::<(usize, usize)>, 1usize)];
    while let Some((b2, parent, level)) = work.pop() {
        depth = depth.max(level);
        let slot = match parent {
            None => 0,
            Some((p, c)) => {
                wide.push(Node::EMPTY);
                let index = wide.len() - 1;
                wide[p].child[c] = index as u32;
                index
            }
        };
        roots.clear();
        let first = nodes[b2].first_index as usize;
        let k = choices.split[b2];
        expand(&choices, bvh2, first, k, &mut roots);
        expand(&choices, bvh2, first + 1, W as u8 - k, &mut roots);
        debug_assert!(roots.len() <= W);
        for (c, &r) in roots.iter().enumerate() {
            if choices.how[r][0] == LEAF {
                let start = order.len() as u32;
                let mixed = leaf(bvh2, r, &is_triangle, &mut subtree, &mut order);
                set_leaf(&mut wide[slot], c, bvh2, r, start, order.len() as u32 - start, mixed);
            }
        }
        // Pushed last to first, so that the first inner child is placed next.
        for (c, &r) in roots.iter().enumerate().rev() {
            if choices.how[r][0] != LEAF {
                set_bounds(&mut wide[slot], c, bvh2, r);
                wide[slot].count[c] = 0;
                work.push((r, Some((slot, c)), level + 1));
            }
        }
    }
    super::pages::move_to_huge_pages(&wide);
    (Bvh { nodes: wide, depth }, order)
}

/// The costs of every binary node's forests, children before parents.
fn choose<const W: usize>(bvh2: &Bvh2, is_triangle: &impl Fn(u32) -> bool, costs: &CollapseCosts) -> Choices<W> {
    let nodes = &bvh2.nodes;
    let n = nodes.len();
    let mut choices = Choices { cost: vec![[0.0; W]; n], how: vec![[0; W]; n], split: vec![0; n] };
    // The triangles under each node, or HAS_OTHERS if a primitive under it
    // is not one (such a subtree never becomes one leaf). (Four bytes a
    // node, as the order below: the build's peak memory is in these.)
    const HAS_OTHERS: u32 = u32::MAX;
    let mut triangles_under = vec![0u32; n];
    // Parents come before children in preorder, so its reverse is a postorder.
    let mut preorder: Vec<u32> = Vec::with_capacity(n);
    let mut stack = vec![0u32];
    while let Some(i) = stack.pop() {
        preorder.push(i);
        let node = &nodes[i as usize];
        if !node.is_leaf() {
            stack.extend([node.first_index, node.first_index + 1]);
        }
    }
    for i in preorder.into_iter().rev().map(|i| i as usize) {
        let node = &nodes[i];
        let area = node.aabb().half_area();
        if node.is_leaf() {
            let range = node.first_index as usize..(node.first_index + node.prim_count) as usize;
            let triangles = bvh2.primitive_indices[range].iter().filter(|&&p| is_triangle(p)).count() as u32;
            let others = node.prim_count - triangles;
            triangles_under[i] = if others == 0 { triangles } else { HAS_OTHERS };
            choices.cost[i] = [area * costs.leaf_cost(triangles, others); W];
            choices.how[i] = [LEAF; W];
            continue;
        }
        let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
        triangles_under[i] = match (triangles_under[l], triangles_under[r]) {
            (HAS_OTHERS, _) | (_, HAS_OTHERS) => HAS_OTHERS,
            // Saturating: a sum near u32::MAX is far past any leaf's size.
            (a, b) => a.saturating_add(b).min(HAS_OTHERS - 1),
        };
        // distribute[j]: the cheapest j + 1 roots shared between the
        // children, at least one each (so distribute[0] is none).
        let mut distribute = [(f32::INFINITY, 0u8); W];
        for (j, best) in distribute.iter_mut().enumerate().skip(1) {
            for k in 1..=j {
                let c = choices.cost[l][k - 1] + choices.cost[r][j - k];
                if c < best.0 {
                    *best = (c, k as u8);
                }
            }
        }
        let (children, split) = distribute[W - 1];
        choices.split[i] = split;
        // An inner node's box tests are the unit of cost.
        let inner = area + children;
        let triangles = triangles_under[i];
        let as_leaf = if triangles <= costs.max_leaf { area * costs.leaf_cost(triangles, 0) } else { f32::INFINITY };
        let mut cost = [0.0; W];
        let mut how = [0u8; W];
        (cost[0], how[0]) = if as_leaf <= inner { (as_leaf, LEAF) } else { (inner, INNER) };
        for j in 1..W {
            (cost[j], how[j]) = if cost[j - 1] <= distribute[j].0 { (cost[j - 1], 0) } else { distribute[j] };
        }
        choices.cost[i] = cost;
        choices.how[i] = how;
    }
    choices
}

/// Appends to `roots` the roots of node `n`'s cheapest forest of at most
/// `slots` of them.
fn expand<const W: usize>(choices: &Choices<W>, bvh2: &Bvh2, n: usize, slots: u8, roots: &mut Vec<usize>) {
    if slots == 1 || bvh2.nodes[n].is_leaf() {
        roots.push(n);
        return;
    }
    match choices.how[n][slots as usize - 1] {
        0 => expand(choices, bvh2, n, slots - 1, roots),
        k => {
            let first = bvh2.nodes[n].first_index as usize;
            expand(choices, bvh2, first, k, roots);
            expand(choices, bvh2, first + 1, slots - k, roots);
        }
    }
}

/// Appends the primitives under binary node `n` to `order`; returns
/// whether one of them is not a triangle. `stack` is scratch space.
fn leaf(
    bvh2: &Bvh2,
    n: usize,
    is_triangle: &impl Fn(u32) -> bool,
    stack: &mut Vec<usize>,
    order: &mut Vec<u32>,
) -> bool {
    let mut mixed = false;
    stack.clear();
    stack.push(n);
    while let Some(i) = stack.pop() {
        let node = &bvh2.nodes[i];
        if node.is_leaf() {
            let range = node.first_index as usize..(node.first_index + node.prim_count) as usize;
            for &p in &bvh2.primitive_indices[range] {
                mixed |= !is_triangle(p);
                order.push(p);
            }
        } else {
            // Second child pushed first, so that primitives keep the tree's order.
            stack.extend([node.first_index as usize + 1, node.first_index as usize]);
        }
    }
    mixed
}

fn set_bounds<const W: usize>(node: &mut Node<W>, c: usize, bvh2: &Bvh2, n: usize) {
    let b = bvh2.nodes[n].aabb();
    for a in 0..3 {
        node.bounds[a][c] = b.min[a];
        node.bounds[a + 3][c] = b.max[a];
    }
}

fn set_leaf<const W: usize>(node: &mut Node<W>, c: usize, bvh2: &Bvh2, n: usize, first: u32, count: u32, mixed: bool) {
    set_bounds(node, c, bvh2, n);
    node.child[c] = first;
    node.count[c] = count | if mixed { LEAF_MIXED } else { 0 };
}

/// A wide tree's shape and what a ray's visits cost by the surface area
/// heuristic: each `*_visits` sums a box's area (a leaf's times its blocks
/// or other primitives) over the root's, the expected number of such
/// visits by a ray that crosses the root box from a random direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeShape {
    pub inner_nodes: usize,
    pub leaves: usize,
    pub blocks: usize,
    /// Children (inner or leaves) per inner node.
    pub children_per_node: f64,
    /// Levels of inner nodes, the root's included.
    pub depth: usize,
    /// Inner nodes' box tests, the root's 1 included.
    pub inner_visits: f64,
    pub leaf_visits: f64,
    pub block_visits: f64,
    /// Primitives of leaves tested one by one (leaves with a primitive
    /// that is not a triangle).
    pub other_visits: f64,
}

impl TreeShape {
    pub(super) fn of<const W: usize>(bvh: &Bvh<W>) -> Self {
        let child_box = |node: &Node<W>, c: usize| {
            let corner = |r: usize| Vec3A::new(node.bounds[r][c], node.bounds[r + 1][c], node.bounds[r + 2][c]);
            Aabb::new(corner(0), corner(3))
        };
        let area = |node: &Node<W>, c: usize| child_box(node, c).half_area() as f64;
        let root_area = (0..W).fold(Aabb::empty(), |b, c| b.union(&child_box(&bvh.nodes[0], c))).half_area() as f64;
        let mut shape = TreeShape {
            inner_nodes: bvh.nodes.len(),
            leaves: 0,
            blocks: 0,
            children_per_node: 0.0,
            depth: bvh.depth,
            inner_visits: 0.0,
            leaf_visits: 0.0,
            block_visits: 0.0,
            other_visits: 0.0,
        };
        let mut children = 0;
        for node in &bvh.nodes {
            // Empty slots have min > max.
            for c in (0..W).filter(|&c| node.bounds[0][c] <= node.bounds[3][c]) {
                children += 1;
                let count = node.count[c] & COUNT_MASK;
                if count == 0 {
                    shape.inner_visits += area(node, c);
                } else {
                    shape.leaves += 1;
                    shape.leaf_visits += area(node, c);
                    if node.count[c] & LEAF_MIXED == 0 {
                        shape.blocks += blocks_of(count);
                        shape.block_visits += area(node, c) * blocks_of(count) as f64;
                    } else {
                        shape.other_visits += area(node, c) * count as f64;
                    }
                }
            }
        }
        shape.children_per_node = children as f64 / shape.inner_nodes as f64;
        shape.inner_visits = 1.0 + shape.inner_visits / root_area;
        shape.leaf_visits /= root_area;
        shape.block_visits /= root_area;
        shape.other_visits /= root_area;
        shape
    }
}

impl std::fmt::Display for TreeShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} inner nodes of {:.2} children, {} leaves in {} blocks, depth {}; visits per ray: {:.2} nodes, \
             {:.2} leaves, {:.2} blocks, {:.2} other primitives",
            self.inner_nodes,
            self.children_per_node,
            self.leaves,
            self.blocks,
            self.depth,
            self.inner_visits,
            self.leaf_visits,
            self.block_visits,
            self.other_visits
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::bvh::tests::scene;
    use super::*;

    /// Every 7th primitive is not a triangle, so that leaves of other
    /// primitives appear.
    fn is_triangle(i: u32) -> bool {
        i % 7 != 3
    }

    /// The expected cost of a ray's visits to a tree of this shape, in
    /// units of one inner node's box tests.
    fn cost(shape: &TreeShape, costs: &CollapseCosts) -> f64 {
        shape.inner_visits
            + costs.leaf as f64 * shape.leaf_visits
            + costs.block as f64 * shape.block_visits
            + costs.other as f64 * shape.other_visits
    }

    /// Triangles and other primitives under binary node `n`.
    fn counts(bvh2: &Bvh2, n: usize) -> (u32, u32) {
        let node = &bvh2.nodes[n];
        if node.is_leaf() {
            let range = node.first_index as usize..(node.first_index + node.prim_count) as usize;
            let triangles = bvh2.primitive_indices[range].iter().filter(|&&p| is_triangle(p)).count() as u32;
            return (triangles, node.prim_count - triangles);
        }
        let (a, b) = (counts(bvh2, node.first_index as usize), counts(bvh2, node.first_index as usize + 1));
        (a.0 + b.0, a.1 + b.1)
    }

    /// Every cut of binary node `n`'s subtree: the sets of nodes under it
    /// (itself included) that hold each of its leaves once.
    fn cuts(bvh2: &Bvh2, n: usize) -> Vec<Vec<usize>> {
        let mut all = vec![vec![n]];
        if !bvh2.nodes[n].is_leaf() {
            let first = bvh2.nodes[n].first_index as usize;
            for a in cuts(bvh2, first) {
                for b in cuts(bvh2, first + 1) {
                    all.push([a.clone(), b].concat());
                }
            }
        }
        all
    }

    /// The least cost, over the root's area, of binary node `n` as a wide
    /// inner node, found by trying every cut of its children into at most
    /// W roots and each root as a leaf (where it may be one) and as an
    /// inner node.
    fn least_by_search<const W: usize>(bvh2: &Bvh2, n: usize, costs: &CollapseCosts) -> f64 {
        let area = |n: usize| bvh2.nodes[n].aabb().half_area() as f64 / bvh2.nodes[0].aabb().half_area() as f64;
        let first = bvh2.nodes[n].first_index as usize;
        let (left, right) = (cuts(bvh2, first), cuts(bvh2, first + 1));
        let mut root_cost = std::collections::HashMap::new();
        let mut root = |r: usize| -> f64 {
            *root_cost.entry(r).or_insert_with(|| {
                let (triangles, others) = counts(bvh2, r);
                let leaf = if bvh2.nodes[r].is_leaf() || (others == 0 && triangles <= costs.max_leaf) {
                    area(r) * costs.leaf_cost(triangles, others) as f64
                } else {
                    f64::INFINITY
                };
                if bvh2.nodes[r].is_leaf() { leaf } else { leaf.min(least_by_search::<W>(bvh2, r, costs)) }
            })
        };
        let mut least = f64::INFINITY;
        for a in &left {
            for b in right.iter().filter(|b| a.len() + b.len() <= W) {
                least = least.min(a.iter().chain(b).map(|&r| root(r)).sum());
            }
        }
        area(n) + least
    }

    /// The cost the choice found for the root made an inner node, over
    /// the root's area.
    fn chosen_cost<const W: usize>(bvh2: &Bvh2, costs: &CollapseCosts) -> f64 {
        let choices = choose::<W>(bvh2, &is_triangle, costs);
        let first = bvh2.nodes[0].first_index as usize;
        let k = choices.split[0] as usize;
        let root_area = bvh2.nodes[0].aabb().half_area();
        (1.0 + (choices.cost[first][k - 1] + choices.cost[first + 1][W - k - 1]) / root_area) as f64
    }

    fn check<const W: usize>(leaf_size: u32, costs: &CollapseCosts) {
        let (bvh2, triangles) = scene(0x1234_5678, 1000, leaf_size);
        let (bvh, order) = collapse::<W>(&bvh2, is_triangle, costs);

        // Every primitive once, in its leaf's box.
        let mut seen = vec![false; triangles.len()];
        for &p in &order {
            assert!(!std::mem::replace(&mut seen[p as usize], true), "primitive {p} twice");
        }
        assert!(seen.iter().all(|&s| s), "a primitive is missing");
        for node in &bvh.nodes {
            for c in (0..W).filter(|&c| node.count[c] != 0) {
                let (first, count) = (node.child[c] as usize, (node.count[c] & COUNT_MASK) as usize);
                let primitives = &order[first..first + count];
                let mixed = primitives.iter().any(|&p| !is_triangle(p));
                assert_eq!(node.count[c] & LEAF_MIXED != 0, mixed, "the mixed mark");
                assert!(count <= leaf_size.max(costs.max_leaf) as usize, "a leaf of {count}");
                assert!(!mixed || count <= leaf_size as usize, "a collapsed leaf with other primitives");
                for &p in primitives {
                    for v in triangles[p as usize] {
                        for a in 0..3 {
                            assert!(node.bounds[a][c] <= v[a] && v[a] <= node.bounds[a + 3][c], "outside its leaf");
                        }
                    }
                }
            }
        }

        // The tree built costs what the choice said.
        let built = cost(&TreeShape::of(&bvh), costs);
        let chosen = chosen_cost::<W>(&bvh2, costs);
        assert!((built - chosen).abs() < 1e-4 * chosen, "built {built}, chosen {chosen}");
    }

    /// The choice's cost against what a search of every collapse finds
    /// least, on scenes small enough to search.
    fn check_least<const W: usize>(costs: &CollapseCosts) {
        for seed in 1..=20u32 {
            let (bvh2, _) = scene(seed.wrapping_mul(0x9e37_79b9), 14, 1);
            let (chosen, least) = (chosen_cost::<W>(&bvh2, costs), least_by_search::<W>(&bvh2, 0, costs));
            assert!((chosen - least).abs() < 1e-5 * least, "seed {seed}: chosen {chosen}, least {least}");
        }
    }

    #[test]
    fn the_collapse_keeps_every_primitive_and_costs_what_it_chose() {
        for leaf_size in [1, 8] {
            check::<8>(leaf_size, &CollapseCosts::MESH);
            check::<4>(leaf_size, &CollapseCosts::MESH);
            check::<8>(leaf_size, &CollapseCosts { max_leaf: 1, ..CollapseCosts::MESH });
        }
    }

    #[test]
    fn the_collapse_costs_the_least_of_every_collapse() {
        check_least::<8>(&CollapseCosts::MESH);
        check_least::<4>(&CollapseCosts::MESH);
        check_least::<8>(&CollapseCosts { max_leaf: 1, ..CollapseCosts::MESH });
        check_least::<4>(&CollapseCosts { leaf: 0.1, block: 2.0, other: 1.0, max_leaf: 8 });
    }
}
