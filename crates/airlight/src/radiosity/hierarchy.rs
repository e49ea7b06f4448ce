//! The patch hierarchy: top-down k-means clustering.
//!
//! The seed clusters its patches into a hierarchy with k-means so that a
//! patch can gather from a distant group of patches as one source (after
//! Bunnell's dynamic AO and Macklin's bottom-up clustering). Here the tree is
//! built top-down: the patches of a node are split into [`BRANCHING`] groups
//! by k-means (k-means++ seeding, Arthur and Vassilvitskii 2007; then Lloyd
//! iterations) on the six numbers (position, w·normal), w being the node's
//! extent (the diagonal of its centres' bounding box), so that a cluster
//! holds patches that are close and face the same way (a cluster mixing a
//! bright floor with a dim wall, gathered as one mean radiosity, is what
//! makes the hierarchical answer err; on the Cornell box, w = extent gave
//! a third less error than w = extent/4 or 4 × extent); groups are split again until they hold at most
//! [`BRANCHING`] patches. Each split is seeded from its own patch range, so
//! the tree depends only on the patches and the seed.
//!
//! Node ids: 0..n are the patches (leaves), n + c is cluster c. The patches
//! are reordered so that every node covers a contiguous range of them.

use super::patches::Patch;
use glam::Vec3;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;

/// Children per cluster.
pub const BRANCHING: usize = 4;
/// Lloyd iterations per split, at most.
const LLOYD_ITERATIONS: usize = 8;
/// Largest number of patches a split fits its centres to; bigger nodes fit
/// to an evenly spaced subset, then assign every patch.
const FIT_SAMPLE: usize = 8192;

/// A group of patches treated as one source by distant receivers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cluster {
    /// Area-weighted centroid of its patches' centres.
    pub center: Vec3,
    /// Radius of a sphere around `center` holding all its patches.
    pub radius: f32,
    /// Total area of its patches.
    pub area: f32,
    /// Unit area-weighted mean of its patches' normals (any unit vector when
    /// they cancel out).
    pub normal: Vec3,
    /// The least cosine between `normal` and a patch's normal: 1 for a flat
    /// cluster, ≤ 0 for one whose patches face apart.
    pub cone_cos: f32,
    /// Half the thickness of the slab around the plane through `center`
    /// normal to `normal` that holds its patches (0 when they all lie in
    /// one plane).
    pub half_thickness: f32,
    /// Its children: `children[first..first + count]` of [`Hierarchy`].
    pub first_child: u32,
    pub child_count: u32,
    /// The patches under it: `start..end`.
    pub start: u32,
    pub end: u32,
}

/// The clusters above a set of patches.
#[derive(Clone, Debug, Default)]
pub struct Hierarchy {
    /// Parents come before their children, so walking the clusters backward
    /// visits children first (used to push radiosity up).
    pub clusters: Vec<Cluster>,
    /// Node ids of the clusters' children.
    pub children: Vec<u32>,
    /// The root's node id (a patch's own id when there is one patch).
    pub root: u32,
}

impl Hierarchy {
    pub fn bytes(&self) -> usize {
        self.clusters.capacity() * size_of::<Cluster>() + self.children.capacity() * 4
    }
}

/// Builds the hierarchy over `patches`, reordering them so that each node
/// covers a contiguous range.
pub fn build(patches: &mut Vec<Patch>, seed: u64) -> Hierarchy {
    let n = patches.len();
    let mut h = Hierarchy::default();
    if n == 0 {
        return h;
    }
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut builder = Builder { patches, order: &mut order, seed, h: &mut h };
    let root = builder.node(0, n);
    h.root = root;
    let reordered: Vec<Patch> = order.iter().map(|&i| patches[i as usize]).collect();
    *patches = reordered;
    // Bounds, bottom-up, from the patches now in place.
    for c in &mut h.clusters {
        let leaves = &patches[c.start as usize..c.end as usize];
        let area: f32 = leaves.iter().map(|p| p.area).sum();
        let weighted: Vec3 = leaves.iter().map(|p| p.center * p.area).sum();
        c.area = area;
        c.center = if area > 0.0 { weighted / area } else { leaves[0].center };
        c.radius = leaves.iter().map(|p| p.center.distance(c.center) + p.radius).fold(0.0, f32::max);
        let normal: Vec3 = leaves.iter().map(|p| p.normal * p.area).sum();
        c.normal = normal.normalize_or(Vec3::Z);
        c.cone_cos = leaves.iter().map(|p| p.normal.dot(c.normal)).fold(1.0, f32::min);
        c.half_thickness = leaves
            .iter()
            .map(|p| {
                let cos = p.normal.dot(c.normal).clamp(-1.0, 1.0);
                c.normal.dot(p.center - c.center).abs() + p.radius * (1.0 - cos * cos).sqrt()
            })
            .fold(0.0, f32::max);
    }
    h
}

struct Builder<'a> {
    patches: &'a [Patch],
    order: &'a mut Vec<u32>,
    seed: u64,
    h: &'a mut Hierarchy,
}

impl Builder<'_> {
    /// The node over `order[start..end]`; returns its id.
    fn node(&mut self, start: usize, end: usize) -> u32 {
        let n = self.patches.len() as u32;
        if end - start == 1 {
            return start as u32;
        }
        let index = self.h.clusters.len();
        self.h.clusters.push(Cluster {
            center: Vec3::ZERO,
            radius: 0.0,
            area: 0.0,
            normal: Vec3::Z,
            cone_cos: -1.0,
            half_thickness: 0.0,
            first_child: 0,
            child_count: 0,
            start: start as u32,
            end: end as u32,
        });
        let groups: Vec<(usize, usize)> =
            if end - start <= BRANCHING { (start..end).map(|i| (i, i + 1)).collect() } else { self.split(start, end) };
        let ids: Vec<u32> = groups.iter().map(|&(a, b)| self.node(a, b)).collect();
        let c = &mut self.h.clusters[index];
        c.first_child = self.h.children.len() as u32;
        c.child_count = ids.len() as u32;
        self.h.children.extend(ids);
        n + index as u32
    }

    /// Splits `order[start..end]` into up to BRANCHING contiguous groups.
    fn split(&mut self, start: usize, end: usize) -> Vec<(usize, usize)> {
        let ids = &self.order[start..end];
        let (lo, hi) = ids.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &i| {
            let c = self.patches[i as usize].center;
            (lo.min(c), hi.max(c))
        });
        let w = (hi - lo).length();
        let feature = |i: u32| {
            let p = &self.patches[i as usize];
            [p.center, p.normal * w]
        };
        let dist2 = |a: &[Vec3; 2], b: &[Vec3; 2]| a[0].distance_squared(b[0]) + a[1].distance_squared(b[1]);
        let points: Vec<[Vec3; 2]> = ids.iter().map(|&i| feature(i)).collect();
        let stride = points.len().div_ceil(FIT_SAMPLE);
        let fit: Vec<[Vec3; 2]> = points.iter().step_by(stride).copied().collect();
        let mut rng = Pcg32::seed_from_u64(mix(self.seed ^ mix(start as u64) ^ (end as u64)));

        // k-means++ seeding.
        let mut centres: Vec<[Vec3; 2]> = vec![fit[rng.random_range(0..fit.len())]];
        let mut d2: Vec<f32> = fit.iter().map(|p| dist2(p, &centres[0])).collect();
        while centres.len() < BRANCHING {
            let total: f64 = d2.iter().map(|&d| d as f64).sum();
            if total <= 0.0 {
                break;
            }
            let mut target = rng.random::<f64>() * total;
            let mut pick = fit.len() - 1;
            for (k, &d) in d2.iter().enumerate() {
                target -= d as f64;
                if target < 0.0 {
                    pick = k;
                    break;
                }
            }
            let c = fit[pick];
            for (d, p) in d2.iter_mut().zip(&fit) {
                *d = d.min(dist2(p, &c));
            }
            centres.push(c);
        }
        let nearest = |p: &[Vec3; 2], centres: &[[Vec3; 2]]| {
            let mut best = (f32::INFINITY, 0usize);
            for (k, c) in centres.iter().enumerate() {
                let d = dist2(p, c);
                if d < best.0 {
                    best = (d, k);
                }
            }
            best.1
        };
        // Lloyd iterations on the fitting set.
        let mut labels = vec![usize::MAX; fit.len()];
        for _ in 0..LLOYD_ITERATIONS {
            let mut changed = false;
            for (l, p) in labels.iter_mut().zip(&fit) {
                let k = nearest(p, &centres);
                changed |= *l != k;
                *l = k;
            }
            if !changed {
                break;
            }
            let mut sums = vec![([Vec3::ZERO; 2], 0u32); centres.len()];
            for (&l, p) in labels.iter().zip(&fit) {
                sums[l].0[0] += p[0];
                sums[l].0[1] += p[1];
                sums[l].1 += 1;
            }
            for (c, (s, count)) in centres.iter_mut().zip(sums) {
                if count > 0 {
                    *c = [s[0] / count as f32, s[1] / count as f32];
                }
            }
        }
        // Assign every patch and group the range by label (stable).
        let all: Vec<usize> = points.iter().map(|p| nearest(p, &centres)).collect();
        let mut counts = vec![0usize; centres.len()];
        for &l in &all {
            counts[l] += 1;
        }
        // One group, or one so big that the tree would grow deep: split
        // evenly instead, which bounds the depth by O(log n).
        let len = end - start;
        if counts.iter().any(|&c| c > len - len / 16) {
            return self.split_by_axis(start, end, hi - lo);
        }
        let mut tagged: Vec<(usize, u32)> = all.into_iter().zip(ids.iter().copied()).collect();
        tagged.sort_by_key(|&(l, _)| l);
        for (slot, (_, id)) in self.order[start..end].iter_mut().zip(&tagged) {
            *slot = *id;
        }
        let mut groups = Vec::new();
        let mut a = start;
        for c in counts.into_iter().filter(|&c| c > 0) {
            groups.push((a, a + c));
            a += c;
        }
        groups
    }

    /// Fallback when k-means cannot separate the patches (all at one point):
    /// equal parts along the widest axis.
    fn split_by_axis(&mut self, start: usize, end: usize, extent: Vec3) -> Vec<(usize, usize)> {
        let axis = extent.max_position();
        let patches = self.patches;
        self.order[start..end].sort_by(|&a, &b| {
            let (pa, pb) = (patches[a as usize].center, patches[b as usize].center);
            pa[axis].total_cmp(&pb[axis])
        });
        let len = end - start;
        (0..BRANCHING)
            .map(|k| (start + len * k / BRANCHING, start + len * (k + 1) / BRANCHING))
            .filter(|(a, b)| b > a)
            .collect()
    }
}

/// SplitMix64's finaliser: a bijective 64-bit mix (Steele, Lea and Flood 2014).
pub(crate) fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
