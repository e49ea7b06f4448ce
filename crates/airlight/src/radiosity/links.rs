//! Form factors and the links along which patches gather light.
//!
//! The form factor from a patch i to a patch j is the seed's
//!
//!   F_ij = cos φi · cos φj / (π r²) · A_j,
//!
//! the differential-area-to-area form factor at i's centre (Cohen and
//! Wallace, "Radiosity and Realistic Image Synthesis", 1993, §4): the
//! fraction of the light leaving a small area at i that reaches j, and, by
//! reciprocity, the irradiance at i from j per unit radiosity of j:
//! E_i = Σ_j F_ij B_j. It holds when r is large beside the patches; for
//! patches closer than [`NEAR`] × (sum of their radii), [`form_factor`]
//! uses the exact point-to-polygon factor ([`point_polygon_factor`])
//! averaged over 6×6 equal-area points, symmetrised over both directions.
//! Visibility multiplies it: one ray between the centres for distant pairs,
//! the fraction of [`NEAR_RAYS`] unblocked rays between points of both
//! patches for near ones; both directions test the same segments, so
//! A_i F_ij = A_j F_ji holds for what the rays see too.
//!
//! Links follow Hanrahan, Salzman and Aupperle, "A Rapid Hierarchical
//! Radiosity Algorithm" (SIGGRAPH 1991), with clusters (the seed's k-means
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

use super::hierarchy::{Hierarchy, mix};
use super::patches::Patch;
use crate::geometry::{Geometry, offset_origin};
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Pairs closer than NEAR × (radius_i + radius_j) are integrated over
/// points of the patches instead of taken at their centres.
pub const NEAR: f32 = 2.0;
/// Patches a cluster link's factor is estimated from.
pub const CLUSTER_SAMPLES: usize = 8;
/// Rays for the visibility of a near pair.
pub const NEAR_RAYS: usize = 4;
const QUAD_N: usize = 6;

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
        let mut sum = glam::Vec3A::ZERO;
        match &self.sources {
            Sources::Narrow(s) => {
                for (&src, &f) in s[range].iter().zip(factors) {
                    sum += b[src as usize] * from_bf16(f);
                }
            }
            Sources::Wide(s) => {
                for (&src, &f) in s[range].iter().zip(factors) {
                    sum += b[src as usize] * from_bf16(f);
                }
            }
        }
        sum
    }

    pub fn bytes(&self) -> usize {
        let sources = match &self.sources {
            Sources::Narrow(s) => s.capacity() * 2,
            Sources::Wide(s) => s.capacity() * 4,
        };
        self.offsets.capacity() * 4 + sources + self.factors.capacity() * 2
    }
}

/// The point-to-area form factor cos φi cos φj / (π r²) · A_j from the point
/// `x` with normal `n` to a small area `area` at `y` with normal `m`; zero
/// when either faces away.
#[inline]
pub fn point_factor(x: Vec3, n: Vec3, y: Vec3, m: Vec3, area: f32) -> f32 {
    let d = y - x;
    let r2 = d.length_squared();
    let ci = n.dot(d);
    let cj = -m.dot(d);
    if ci <= 0.0 || cj <= 0.0 || r2 == 0.0 {
        return 0.0;
    }
    ci * cj / (PI * r2 * r2) * area
}

fn quad_points(p: &Patch) -> ([Vec3; QUAD_N * QUAD_N], usize) {
    let mut v = Vec::with_capacity(QUAD_N * QUAD_N);
    p.shape.quadrature_points(QUAD_N, &mut v);
    let mut out = [p.center; QUAD_N * QUAD_N];
    out[..v.len()].copy_from_slice(&v);
    (out, v.len())
}

/// Whether a pair of patches is near enough to be integrated over points.
#[inline]
pub fn is_near(a: &Patch, b: &Patch) -> bool {
    a.center.distance(b.center) < NEAR * (a.radius + b.radius)
}

/// The exact unoccluded form factor from a point `x` with normal `n` to the
/// flat polygon `poly` whose front side faces along `m`, by Lambert's
/// contour formula (Cohen and Wallace 1993, §4.5; Baum, Rushmeier and
/// Winget 1989):
///
///   F = 1/(2π) · Σ_k γ_k · n · (R_k × R_{k+1}) / |R_k × R_{k+1}|,
///
/// R_k = v_k − x and γ_k the angle between R_k and R_{k+1}, after clipping
/// the polygon to the half space in front of x. Zero when x is behind the
/// polygon's front side.
pub fn point_polygon_factor(x: Vec3, n: Vec3, poly: &[Vec3], m: Vec3) -> f32 {
    if m.dot(x - poly[0]) <= 0.0 {
        return 0.0;
    }
    // Clip to n·(v − x) ≥ 0 (Sutherland–Hodgman against one plane).
    let mut clipped = [Vec3::ZERO; 8];
    let mut count = 0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (da, db) = (n.dot(a - x), n.dot(b - x));
        if da >= 0.0 {
            clipped[count] = a;
            count += 1;
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped[count] = a + (b - a) * (da / (da - db));
            count += 1;
        }
    }
    if count < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..count {
        let (a, b) = (clipped[k] - x, clipped[(k + 1) % count] - x);
        let c = a.cross(b);
        let len = c.length();
        if len <= 1e-12 * a.length() * b.length() {
            continue;
        }
        let gamma = len.atan2(a.dot(b));
        sum += gamma * n.dot(c) / len;
    }
    (sum / (2.0 * PI)).abs()
}

fn polygon(p: &Patch) -> ([Vec3; 4], usize) {
    let s = &p.shape;
    if s.triangle {
        ([s.origin, s.origin + s.e1, s.origin + s.e2, Vec3::ZERO], 3)
    } else {
        (
            [
                s.origin,
                s.origin + s.e1,
                s.origin + s.e1 + s.e2,
                s.origin + s.e2,
            ],
            4,
        )
    }
}

/// The unoccluded form factor F_ij from patch i to patch j (see the module
/// documentation): the point formula at i's centre when far; when near,
/// the mean of the two one-sided estimates F_ij and (A_j/A_i)·F_ji, each the
/// exact point-to-polygon factor averaged over 6×6 equal-area points of the
/// receiver. One side's integrand may jump (a floor patch half under a
/// block sees the block's face from one half only), where midpoint
/// quadrature errs by a few per cent; averaging halves that and makes the
/// near factors exactly reciprocal, A_i F_ij = A_j F_ji.
pub fn form_factor(pi: &Patch, pj: &Patch) -> f32 {
    let d = pj.center - pi.center;
    // All of j behind i, or i behind j: nothing passes.
    if pi.normal.dot(d) + pj.radius <= 0.0 || -pj.normal.dot(d) + pi.radius <= 0.0 {
        return 0.0;
    }
    if !is_near(pi, pj) {
        return point_factor(pi.center, pi.normal, pj.center, pj.normal, pj.area);
    }
    let forward = one_sided_factor(pi, pj);
    let backward = one_sided_factor(pj, pi);
    0.5 * (forward + backward * pj.area / pi.area)
}

fn one_sided_factor(pi: &Patch, pj: &Patch) -> f32 {
    let (a, na) = quad_points(pi);
    let (poly, count) = polygon(pj);
    // The exact factor is to the patch's polygon; scale to its stated area
    // (they differ only for the tangent pieces of a sphere).
    let poly_area =
        if pj.shape.triangle { 0.5 } else { 1.0 } * pj.shape.e1.cross(pj.shape.e2).length();
    let scale = if poly_area > 0.0 {
        pj.area / poly_area
    } else {
        0.0
    };
    let mut sum = 0.0;
    for x in &a[..na] {
        sum += point_polygon_factor(*x, pi.normal, &poly[..count], pj.normal);
    }
    scale * sum / na as f32
}

/// Whether the segment between `x` (normal `n`) and `y` (normal `m`) is
/// free, each end lifted off its surface toward the other.
#[inline]
pub fn segment_clear(geometry: &Geometry, x: Vec3, n: Vec3, y: Vec3, m: Vec3) -> bool {
    let a = offset_origin(x, n, y - x);
    let b = offset_origin(y, m, x - y);
    let d = b - a;
    let len = d.length();
    if len == 0.0 {
        return true;
    }
    !geometry.occluded(a, d / len, len * (1.0 - 1e-4))
}

/// The visible fraction between patches i and j: one centre-to-centre ray
/// when far, [`NEAR_RAYS`] rays between points of both when near. Symmetric
/// in (i, j): both orders test the same segments.
pub fn visibility(geometry: &Geometry, patches: &[Patch], i: usize, j: usize, seed: u64) -> f32 {
    let (lo, hi) = (i.min(j), i.max(j));
    let (a, b) = (&patches[lo], &patches[hi]);
    if !is_near(a, b) {
        return segment_clear(geometry, a.center, a.normal, b.center, b.normal) as u32 as f32;
    }
    let key = mix(seed ^ mix(((lo as u64) << 32) | hi as u64));
    let mut clear = 0;
    for k in 0..NEAR_RAYS {
        let h = mix(key.wrapping_add(k as u64));
        let u = |bits: u64| (bits & 0xffff) as f32 / 65536.0;
        // Stratified in s on each patch, hashed in t.
        let s = (k as f32 + u(h)) / NEAR_RAYS as f32;
        let x = a.shape.point(s, u(h >> 16));
        let s2 = ((k * 3 + 1) % NEAR_RAYS) as f32 + u(h >> 32);
        let y = b.shape.point(s2 / NEAR_RAYS as f32, u(h >> 48));
        clear += segment_clear(geometry, x, a.normal, y, b.normal) as u32;
    }
    clear as f32 / NEAR_RAYS as f32
}

/// Builds the links of every node (in parallel; the result does not depend
/// on the number of threads). `threshold`: see the module documentation;
/// with threshold 0 every link joins two single patches, the full O(N²)
/// solution.
pub fn build(
    patches: &[Patch],
    hierarchy: &Hierarchy,
    geometry: &Geometry,
    threshold: f32,
    receiver_share: f32,
    seed: u64,
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
    let ctx = Context {
        patches,
        hierarchy,
        geometry,
        threshold,
        receiver_share,
        seed,
        cdf: &cdf,
    };
    let mut pairs = Vec::new();
    if n > 0 {
        ctx.refine(hierarchy.root, hierarchy.root, &mut pairs);
    }
    // Group by receiver; the sort is stable and `pairs` comes out in one
    // order whatever the threads, so the links do too.
    // Sources in increasing order within each receiver, so that gathering
    // walks the radiosity array forward.
    pairs.sort_by_key(|&(r, l)| (r, l.source));
    let narrow = nodes <= u16::MAX as usize + 1;
    let mut offsets = Vec::with_capacity(nodes + 1);
    let mut wide = Vec::with_capacity(if narrow { 0 } else { pairs.len() });
    let mut small = Vec::with_capacity(if narrow { pairs.len() } else { 0 });
    let mut factors = Vec::with_capacity(pairs.len());
    let mut patch_to_patch = 0;
    offsets.push(0);
    let mut k = 0;
    for r in 0..nodes as u32 {
        while k < pairs.len() && pairs[k].0 == r {
            let link = pairs[k].1;
            if (r as usize) < n && (link.source as usize) < n {
                patch_to_patch += 1;
            }
            if narrow {
                small.push(link.source as u16);
            } else {
                wide.push(link.source);
            }
            factors.push(to_bf16(link.factor));
            k += 1;
        }
        offsets.push(factors.len() as u32);
    }
    Links {
        offsets,
        sources: if narrow {
            Sources::Narrow(small)
        } else {
            Sources::Wide(wide)
        },
        factors,
        patch_to_patch,
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

    /// Links receiver `r` to source `s`, or their parts to each other
    /// (Hanrahan, Salzman and Aupperle's Refine, with clusters).
    fn refine(&self, r: u32, s: u32, out: &mut Vec<(u32, Link)>) {
        let (a, b) = (self.node(r), self.node(s));
        if r == s && a.leaf {
            return;
        }
        if behind(&a, &b) || behind(&b, &a) {
            return;
        }
        if a.leaf && b.leaf {
            let (i, j) = (r as usize, s as usize);
            let f = form_factor(&self.patches[i], &self.patches[j]);
            if f > 0.0 {
                let v = visibility(self.geometry, self.patches, i, j, self.seed);
                if v > 0.0 {
                    out.push((
                        r,
                        Link {
                            source: s,
                            factor: f * v,
                        },
                    ));
                }
            }
            return;
        }
        let d2 = a.center.distance_squared(b.center);
        let sep = a.radius + b.radius;
        let limit = self.threshold * PI * d2;
        let separated = d2 > 4.0 * sep * sep;
        let receiver_ok =
            a.leaf || (a.cone_cos >= COHERENT && a.area < limit * self.receiver_share && separated);
        let source_ok = b.leaf || (b.area < limit && separated);
        if receiver_ok && source_ok {
            let f = self.cluster_factor(r, &a, s, &b);
            if f > 0.0 {
                out.push((
                    r,
                    Link {
                        source: s,
                        factor: f,
                    },
                ));
            }
            return;
        }
        let split_receiver = if !receiver_ok && !source_ok {
            a.area > b.area
        } else {
            !receiver_ok
        };
        let kids = self.children(if split_receiver { r } else { s });
        let pair = |k: u32| if split_receiver { (k, s) } else { (r, k) };
        if (a.end - a.start) + (b.end - b.start) > PARALLEL {
            let parts: Vec<Vec<(u32, Link)>> = kids
                .par_iter()
                .map(|&k| {
                    let mut v = Vec::new();
                    let (x, y) = pair(k);
                    self.refine(x, y, &mut v);
                    v
                })
                .collect();
            for p in parts {
                out.extend(p);
            }
        } else {
            for &k in kids {
                let (x, y) = pair(k);
                self.refine(x, y, out);
            }
        }
    }

    /// The patch under node `node` whose area interval holds the fraction
    /// `u` of the node's area.
    fn pick(&self, node: &Node, u: f64) -> usize {
        let (lo, hi) = (self.cdf[node.start as usize], self.cdf[node.end as usize]);
        let target = lo + u * (hi - lo);
        let range = &self.cdf[node.start as usize + 1..=node.end as usize];
        (node.start as usize + range.partition_point(|&x| x <= target)).min(node.end as usize - 1)
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

/// Whether every point of `b` lies behind (or on) every patch of `a`:
/// n_x · (y − x) ≤ 0 for all patches x of a with normal n_x and points y of
/// b. Bounded by n̄·(c_b − c_a) + (b's extent along n̄) + a's half
/// thickness + |n_x − n̄|·(distance + radii), |n_x − n̄|² ≤ 2 − 2·cone_cos.
fn behind(a: &Node, b: &Node) -> bool {
    let d = b.center - a.center;
    let flat_and_parallel = b.cone_cos >= 0.9999 && a.normal.dot(b.normal).abs() >= 0.9999;
    let extent = if flat_and_parallel {
        b.half_thickness
    } else {
        b.radius
    };
    let spread = (2.0 - 2.0 * a.cone_cos).max(0.0).sqrt();
    let bound =
        a.normal.dot(d) + extent + a.half_thickness + spread * (d.length() + a.radius + b.radius);
    bound <= 1e-5 * (d.length() + a.radius + b.radius)
}
