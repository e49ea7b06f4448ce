//! The links along which patches gather light.
//!
//! Form factors are in [`super::factors`].
//!
//! Links follow Hanrahan, Salzman and Aupperle, "A Rapid Hierarchical
//! Radiosity Algorithm" (SIGGRAPH 1991), with clusters (Madams's k-means
//! hierarchy) as sources: refinement starts from (root, root); a pair where
//! one side lies wholly behind the other is dropped (`behind`); two
//! patches are linked by their form factor; otherwise the pair is linked as
//! it stands when both ends are acceptable, and else the end that is not
//! (the larger, if neither is) is replaced by its children. A source
//! cluster is acceptable when the receiver lies outside twice the sum of
//! their bounding radii and its estimated form factor A_j/(π d²) (d between
//! centres) is below the link threshold; a receiver is acceptable when it
//! is a patch or, with `receiver_share` > 0, a flat cluster passing the
//! same test with threshold × receiver_share (its irradiance is then handed
//! down to its patches). A link with a cluster at either end has the Monte
//! Carlo factor A_s · (1/M) Σ_m cos φ cos φ' V / (π r²) over M =
//! [`CLUSTER_SAMPLES`] pairs of patch centres drawn ∝ area from both ends
//! (stratified): an unbiased estimate of the area-weighted mean, over the
//! receiver's patches, of Σ_k F_ik over the source's patches.

use super::factors::{form_factor, point_factor, segment_clear, visibility};
use super::hierarchy::{Hierarchy, mix};
use super::patches::Patch;
use crate::geometry::Geometry;
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Patch pairs a cluster link's factor is estimated from.
pub const CLUSTER_SAMPLES: usize = 8;

/// One source a node gathers from: a node id (patch or cluster) and the
/// form factor to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    pub source: u32,
    pub factor: f32,
}

/// Every node's links, stored compactly for the per-frame gather, which
/// streams them all once per bounce and so is bound by memory bandwidth:
/// factors as bfloat16 (the upper half of an f32, rounded to nearest:
/// relative error ≤ 2⁻⁸ per link, unbiased, so it averages out over a
/// receiver's hundreds of links), source ids as u16 when there are fewer
/// than 65,536 nodes, else u32. Node r's links are entries
/// `offsets[r]..offsets[r + 1]` (patches first, then clusters), sources
/// increasing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Links {
    pub offsets: Vec<u32>,
    sources: Sources,
    factors: Vec<u16>,
    /// How many links join two single patches.
    pub patch_to_patch: usize,
}

#[derive(Clone, Debug, PartialEq)]
enum Sources {
    Narrow(Vec<u16>),
    Wide(Vec<u32>),
}

impl Default for Sources {
    fn default() -> Self {
        Sources::Narrow(Vec::new())
    }
}

/// f32 → bfloat16 bits, rounded to nearest even (finite, non-negative input).
#[inline]
pub fn to_bf16(x: f32) -> u16 {
    let bits = x.to_bits();
    let round = 0x7fff + ((bits >> 16) & 1);
    ((bits + round) >> 16) as u16
}

#[inline]
pub fn from_bf16(b: u16) -> f32 {
    f32::from_bits((b as u32) << 16)
}

/// Σ b(source) · factor over one receiver's links, in four running sums
/// (links 4k, 4k + 1, 4k + 2, 4k + 3, the last few in the first) added at
/// the end as (s0 + s1) + (s2 + s3): one running sum made every add wait for
/// the one before, and the gather ran at the adder's latency. The order is
/// fixed by the links alone, so the answer does not depend on the threads.
#[inline(always)]
fn weighted_sum<S: Copy>(sources: &[S], factors: &[u16], b: &[glam::Vec3A], index: impl Fn(S) -> usize) -> glam::Vec3A {
    let mut sums = [glam::Vec3A::ZERO; 4];
    let (quads, rest) = (sources.chunks_exact(4), factors.chunks_exact(4));
    let (tail_sources, tail_factors) = (quads.remainder(), rest.remainder());
    for (sources, factors) in quads.zip(rest) {
        for j in 0..4 {
            sums[j] += b[index(sources[j])] * from_bf16(factors[j]);
        }
    }
    for (&src, &f) in tail_sources.iter().zip(tail_factors) {
        sums[0] += b[index(src)] * from_bf16(f);
    }
    (sums[0] + sums[1]) + (sums[2] + sums[3])
}

impl Links {
    /// Total number of links.
    pub fn len(&self) -> usize {
        self.factors.len()
    }

    pub fn is_empty(&self) -> bool {
        self.factors.is_empty()
    }

    /// Node `receiver`'s links, decoded.
    pub fn of(&self, receiver: usize) -> impl ExactSizeIterator<Item = Link> + '_ {
        let range = self.offsets[receiver] as usize..self.offsets[receiver + 1] as usize;
        range.map(move |k| Link {
            source: match &self.sources {
                Sources::Narrow(s) => s[k] as u32,
                Sources::Wide(s) => s[k],
            },
            factor: from_bf16(self.factors[k]),
        })
    }

    /// Σ F · b(source) over node `receiver`'s links: the gather's inner loop.
    #[inline]
    pub fn gather(&self, receiver: usize, b: &[glam::Vec3A]) -> glam::Vec3A {
        let range = self.offsets[receiver] as usize..self.offsets[receiver + 1] as usize;
        let factors = &self.factors[range.clone()];
        match &self.sources {
            Sources::Narrow(s) => weighted_sum(&s[range], factors, b, |src| src as usize),
            Sources::Wide(s) => weighted_sum(&s[range], factors, b, |src| src as usize),
        }
    }

    pub fn bytes(&self) -> usize {
        let sources = match &self.sources {
            Sources::Narrow(s) => s.capacity() * 2,
            Sources::Wide(s) => s.capacity() * 4,
        };
        self.offsets.capacity() * 4 + sources + self.factors.capacity() * 2
    }
}

/// Receivers are refined in blocks of about this many patches (subtrees
/// of the hierarchy), each packed before the next starts, so that the
/// unpacked (receiver, link) pairs of only one block are held at a time.
const BLOCK_PATCHES: u32 = 1 << 15;

/// Builds the links of every node (in parallel; the result does not depend
/// on the number of threads). `threshold`: see the module documentation;
/// with threshold 0 every link joins two single patches, the full O(N²)
/// solution.
///
/// Refinement runs once per block of receivers: a subtree T of the
/// hierarchy, in left-to-right order. Every link of a receiver in T comes
/// from a pair whose receiver is in T or above it, so a refinement from
/// (root, root) that follows only the child toward T when it splits a
/// receiver above T finds exactly T's links (and repeats only the few pairs
/// above T). The links are the same, bit for bit, as one refinement over
/// all receivers, and are packed block by block.
pub fn build(
    patches: &[Patch],
    hierarchy: &Hierarchy,
    geometry: &Geometry,
    threshold: f32,
    receiver_share: f32,
    seed: u64,
) -> Links {
    build_in_blocks(patches, hierarchy, geometry, threshold, receiver_share, seed, BLOCK_PATCHES)
}

/// [`build`] with blocks of at most `block_patches` patches.
fn build_in_blocks(
    patches: &[Patch],
    hierarchy: &Hierarchy,
    geometry: &Geometry,
    threshold: f32,
    receiver_share: f32,
    seed: u64,
    block_patches: u32,
) -> Links {
    let n = patches.len();
    let nodes = n + hierarchy.clusters.len();
    // Prefix sums of area, for picking a cluster's patches ∝ area.
    let mut cdf = Vec::with_capacity(n + 1);
    let mut acc = 0.0f64;
    cdf.push(0.0);
    for p in patches {
        acc += p.area as f64;
        cdf.push(acc);
    }
    let ctx = Context { patches, hierarchy, geometry, threshold, receiver_share, seed, cdf: &cdf };
    let narrow = nodes <= u16::MAX as usize + 1;
    let mut packer = Packer {
        n,
        offsets: Vec::with_capacity(nodes + 1),
        sources: if narrow { Sources::Narrow(Vec::new()) } else { Sources::Wide(Vec::new()) },
        factors: Vec::new(),
        patch_to_patch: 0,
        next: 0,
    };
    packer.offsets.push(0);
    // Links received by clusters, kept aside until every patch's are
    // packed (node order: patches first, then clusters).
    let mut cluster_pairs: Vec<(u32, Link)> = Vec::new();
    if n > 0 {
        for block in ctx.blocks(block_patches) {
            let mut pairs = Vec::new();
            ctx.refine(hierarchy.root, hierarchy.root, Some(block), &mut pairs);
            // (receiver, source) pairs are unique, so this order is one
            // whatever the threads. Sources increase within each receiver,
            // so that gathering walks the radiosity array forward.
            pairs.sort_unstable_by_key(|&(r, l)| (r, l.source));
            let split = pairs.partition_point(|&(r, _)| (r as usize) < n);
            cluster_pairs.extend_from_slice(&pairs[split..]);
            pairs.truncate(split);
            packer.pack(&pairs, ctx.node(block).end);
        }
        cluster_pairs.sort_unstable_by_key(|&(r, l)| (r, l.source));
        packer.pack(&cluster_pairs, nodes as u32);
    }
    let Packer { mut offsets, mut sources, mut factors, patch_to_patch, .. } = packer;
    // Grown by doubling; give back the slack (a few hundred MB at 1M patches).
    offsets.shrink_to_fit();
    factors.shrink_to_fit();
    match &mut sources {
        Sources::Narrow(s) => s.shrink_to_fit(),
        Sources::Wide(s) => s.shrink_to_fit(),
    }
    Links { offsets, sources, factors, patch_to_patch }
}

/// Appends sorted (receiver, link) pairs to the packed form.
struct Packer {
    n: usize,
    offsets: Vec<u32>,
    sources: Sources,
    factors: Vec<u16>,
    patch_to_patch: usize,
    /// The next receiver whose offset is to be written.
    next: u32,
}

impl Packer {
    /// Packs `pairs` (sorted, receivers from `self.next` on, below `end`)
    /// and closes receivers up to `end`.
    fn pack(&mut self, pairs: &[(u32, Link)], end: u32) {
        let mut k = 0;
        for r in self.next..end {
            while k < pairs.len() && pairs[k].0 == r {
                let link = pairs[k].1;
                if (r as usize) < self.n && (link.source as usize) < self.n {
                    self.patch_to_patch += 1;
                }
                match &mut self.sources {
                    Sources::Narrow(s) => s.push(link.source as u16),
                    Sources::Wide(s) => s.push(link.source),
                }
                self.factors.push(to_bf16(link.factor));
                k += 1;
            }
            self.offsets.push(self.factors.len() as u32);
        }
        debug_assert_eq!(k, pairs.len(), "pairs outside the block");
        self.next = end;
    }
}

/// A node's shape, for refinement: a patch seen as a flat cluster of one.
#[derive(Clone, Copy)]
struct Node {
    center: Vec3,
    radius: f32,
    area: f32,
    normal: Vec3,
    cone_cos: f32,
    half_thickness: f32,
    start: u32,
    end: u32,
    leaf: bool,
}

/// Receiving clusters must be this flat: their patches take one irradiance.
const COHERENT: f32 = 0.95;
/// Pairs holding more patches than this together are refined in parallel.
const PARALLEL: u32 = 2048;

struct Context<'a> {
    patches: &'a [Patch],
    hierarchy: &'a Hierarchy,
    geometry: &'a Geometry,
    threshold: f32,
    receiver_share: f32,
    seed: u64,
    cdf: &'a [f64],
}

impl Context<'_> {
    fn node(&self, id: u32) -> Node {
        let n = self.patches.len() as u32;
        if id < n {
            let p = &self.patches[id as usize];
            Node {
                center: p.center,
                radius: p.radius,
                area: p.area,
                normal: p.normal,
                cone_cos: 1.0,
                half_thickness: 0.0,
                start: id,
                end: id + 1,
                leaf: true,
            }
        } else {
            let c = &self.hierarchy.clusters[(id - n) as usize];
            Node {
                center: c.center,
                radius: c.radius,
                area: c.area,
                normal: c.normal,
                cone_cos: c.cone_cos,
                half_thickness: c.half_thickness,
                start: c.start,
                end: c.end,
                leaf: false,
            }
        }
    }

    fn children(&self, id: u32) -> &[u32] {
        let c = &self.hierarchy.clusters[id as usize - self.patches.len()];
        let first = c.first_child as usize;
        &self.hierarchy.children[first..first + c.child_count as usize]
    }

    /// The hierarchy's subtrees holding at most `most` patches whose
    /// parents hold more, left to right: their patch ranges tile 0..n in
    /// order.
    fn blocks(&self, most: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = vec![self.hierarchy.root];
        while let Some(id) = stack.pop() {
            let node = self.node(id);
            if node.leaf || node.end - node.start <= most {
                out.push(id);
            } else {
                stack.extend(self.children(id).iter().rev());
            }
        }
        out
    }

    /// Whether node `x`'s patches include all of `block`'s.
    fn covers(&self, x: &Node, block: &Node) -> bool {
        x.start <= block.start && block.end <= x.end
    }

    /// Links receiver `r` to source `s`, or their parts to each other
    /// (Hanrahan, Salzman and Aupperle's Refine, with clusters). With
    /// `block`, only the links of receivers in that subtree (and of
    /// receivers above it whose leftmost block it is) are made; `r` must
    /// then lie in the block or above it.
    fn refine(&self, r: u32, s: u32, block: Option<u32>, out: &mut Vec<(u32, Link)>) {
        let (a, b) = (self.node(r), self.node(s));
        if r == s && a.leaf {
            return;
        }
        if behind(&a, &b) || behind(&b, &a) {
            return;
        }
        // Above the block (a strict ancestor of it): r's own links belong
        // to the block holding its first patch; splitting r follows the
        // child toward the block only.
        let above = block.filter(|&t| t != r).map(|t| self.node(t));
        if a.leaf && b.leaf {
            let (i, j) = (r as usize, s as usize);
            let f = form_factor(&self.patches[i], &self.patches[j]);
            if f > 0.0 {
                let v = visibility(self.geometry, self.patches, i, j, self.seed);
                if v > 0.0 {
                    out.push((r, Link { source: s, factor: f * v }));
                }
            }
            return;
        }
        let d2 = a.center.distance_squared(b.center);
        let sep = a.radius + b.radius;
        let limit = self.threshold * PI * d2;
        let separated = d2 > 4.0 * sep * sep;
        let receiver_ok = a.leaf || (a.cone_cos >= COHERENT && a.area < limit * self.receiver_share && separated);
        let source_ok = b.leaf || (b.area < limit && separated);
        if receiver_ok && source_ok {
            if above.is_none_or(|t| t.start == a.start) {
                let f = self.cluster_factor(r, &a, s, &b);
                if f > 0.0 {
                    out.push((r, Link { source: s, factor: f }));
                }
            }
            return;
        }
        let split_receiver = if !receiver_ok && !source_ok { a.area > b.area } else { !receiver_ok };
        if let (true, Some(t)) = (split_receiver, above) {
            let toward = self.children(r).iter().copied().find(|&k| self.covers(&self.node(k), &t));
            if let Some(k) = toward {
                self.refine(k, s, block, out);
            }
            return;
        }
        // Below the block's top the restriction no longer matters.
        let block = if above.is_some() { block } else { None };
        let kids = self.children(if split_receiver { r } else { s });
        let pair = |k: u32| if split_receiver { (k, s) } else { (r, k) };
        if (a.end - a.start) + (b.end - b.start) > PARALLEL {
            let parts: Vec<Vec<(u32, Link)>> = kids
                .par_iter()
                .map(|&k| {
                    let mut v = Vec::new();
                    let (x, y) = pair(k);
                    self.refine(x, y, block, &mut v);
                    v
                })
                .collect();
            for p in parts {
                out.extend(p);
            }
        } else {
            for &k in kids {
                let (x, y) = pair(k);
                self.refine(x, y, block, out);
            }
        }
    }

    /// The patch under node `node` whose area interval holds the fraction
    /// `u` of the node's area: the first i in start..end with
    /// cdf[i + 1] > target (the last when none is). Searched from the
    /// index that equal areas would give, stepping to the answer: a
    /// cluster's patches have nearly equal areas, so this takes a step or
    /// two where a binary search over a large cluster took twenty cache
    /// misses (it was the costliest part of compiling at 100k patches).
    fn pick(&self, node: &Node, u: f64) -> usize {
        pick(self.cdf, node.start as usize, node.end as usize, u)
    }

    /// A_s · (1/M) Σ_m G(x_m, y_m) V(x_m, y_m), x_m and y_m patch centres
    /// drawn ∝ area from r and s (stratified): an unbiased estimate of the
    /// area-weighted mean over r's patches of Σ_{k ∈ s} F_ik.
    fn cluster_factor(&self, r: u32, a: &Node, s: u32, b: &Node) -> f32 {
        let key = mix(self.seed ^ mix(((r as u64) << 32) | s as u64));
        let m_count = CLUSTER_SAMPLES;
        let mut sum = 0.0;
        for m in 0..m_count {
            let h = mix(key.wrapping_add(m as u64));
            let frac = |bits: u64| (bits & 0x1f_ffff) as f64 / (1u64 << 21) as f64;
            let ua = (m as f64 + frac(h)) / m_count as f64;
            let ub = (((3 * m + 1) % m_count) as f64 + frac(h >> 21)) / m_count as f64;
            let x = &self.patches[self.pick(a, ua)];
            let y = &self.patches[self.pick(b, ub)];
            let g = point_factor(x.center, x.normal, y.center, y.normal, 1.0);
            if g > 0.0 && segment_clear(self.geometry, x.center, x.normal, y.center, y.normal) {
                sum += g;
            }
        }
        b.area * sum / m_count as f32
    }
}

/// See [`Context::pick`]: the patch in start..end (start < end) whose
/// interval of the prefix sums `cdf` holds the fraction `u` of their span.
fn pick(cdf: &[f64], start: usize, end: usize, u: f64) -> usize {
    let (lo, hi) = (cdf[start], cdf[end]);
    let target = lo + u * (hi - lo);
    let guess = start + ((u * (end - start) as f64) as usize);
    let mut i = guess.clamp(start, end - 1);
    while i > start && cdf[i] > target {
        i -= 1;
    }
    while i < end - 1 && cdf[i + 1] <= target {
        i += 1;
    }
    i
}

/// Whether every point of `b` lies behind (or on) every patch of `a`:
/// n_x · (y − x) ≤ 0 for all patches x of a with normal n_x and points y of
/// b. Bounded by n̄·(c_b − c_a) + (b's extent along n̄) + a's half
/// thickness + |n_x − n̄|·(distance + radii), |n_x − n̄|² ≤ 2 − 2·cone_cos.
fn behind(a: &Node, b: &Node) -> bool {
    let d = b.center - a.center;
    let flat_and_parallel = b.cone_cos >= 0.9999 && a.normal.dot(b.normal).abs() >= 0.9999;
    let extent = if flat_and_parallel { b.half_thickness } else { b.radius };
    let spread = (2.0 - 2.0 * a.cone_cos).max(0.0).sqrt();
    let bound = a.normal.dot(d) + extent + a.half_thickness + spread * (d.length() + a.radius + b.radius);
    bound <= 1e-5 * (d.length() + a.radius + b.radius)
}

#[cfg(test)]
mod tests;
