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
//! patches closer than [`NEAR`] × (sum of their radii), F_ij is averaged over
//! 4×4 points on each patch (equal-area sub-pieces) instead. Visibility
//! multiplies it: one ray between the centres for distant pairs, the fraction
//! of 4 unblocked rays between points of both patches for near ones. Both use
//! the same segments from either end, so A_i F_ij = A_j F_ji holds for
//! what the rays see too.
//!
//! Links follow Hanrahan, Salzman and Aupperle, "A Rapid Hierarchical
//! Radiosity Algorithm" (SIGGRAPH 1991), with patches gathering from
//! clusters as in the seed: each patch walks the hierarchy from the root;
//! a node wholly behind the patch is skipped; a cluster j far enough —
//! the patch lies outside twice its bounding radius and its estimated form
//! factor A_j / (π d²) (d: distance to its centre) is below the link
//! threshold — becomes one link; otherwise its children are visited, down to
//! single patches. A cluster link's factor is the Monte Carlo estimate
//! A_j · (1/M) Σ_m cos φi cos φk V / (π r²) over M = 4 of its patches k
//! chosen with probability ∝ area (stratified), an unbiased estimate of
//! Σ_k F_ik over the cluster's patches (each taken at its centre).

use super::hierarchy::{Hierarchy, mix};
use super::patches::Patch;
use crate::geometry::{Geometry, Ray, offset_origin};
use glam::Vec3;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Pairs closer than NEAR × (radius_i + radius_j) are integrated over
/// points of both patches.
pub const NEAR: f32 = 2.0;
/// Patches a cluster link's factor is estimated from.
pub const CLUSTER_SAMPLES: usize = 16;
/// Rays for the visibility of a near pair.
pub const NEAR_RAYS: usize = 4;
const QUAD_N: usize = 4;

/// One source a patch gathers from: a node id (patch or cluster) and the
/// form factor to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    pub source: u32,
    pub factor: f32,
}

/// Every patch's links, in one array: patch i's are
/// `links[offsets[i]..offsets[i + 1]]`.
#[derive(Clone, Debug, Default)]
pub struct Links {
    pub offsets: Vec<u32>,
    pub links: Vec<Link>,
    /// How many links go to single patches (the rest go to clusters).
    pub to_patches: usize,
}

impl Links {
    pub fn of(&self, receiver: usize) -> &[Link] {
        &self.links[self.offsets[receiver] as usize..self.offsets[receiver + 1] as usize]
    }
    pub fn bytes(&self) -> usize {
        self.offsets.capacity() * 4 + self.links.capacity() * size_of::<Link>()
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

/// The unoccluded form factor F_ij from patch i to patch j (see the module
/// documentation): at i's centre when far, averaged over both when near.
pub fn form_factor(pi: &Patch, pj: &Patch) -> f32 {
    let d = pj.center - pi.center;
    // All of j behind i, or i behind j: nothing passes.
    if pi.normal.dot(d) + pj.radius <= 0.0 || -pj.normal.dot(d) + pi.radius <= 0.0 {
        return 0.0;
    }
    if !is_near(pi, pj) {
        return point_factor(pi.center, pi.normal, pj.center, pj.normal, pj.area);
    }
    let (a, na) = quad_points(pi);
    let (b, nb) = quad_points(pj);
    let piece = pj.area / nb as f32;
    let mut sum = 0.0;
    for x in &a[..na] {
        for y in &b[..nb] {
            sum += point_factor(*x, pi.normal, *y, pj.normal, piece);
        }
    }
    sum / na as f32
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
    let (pi, pj) = (&patches[i], &patches[j]);
    if !is_near(pi, pj) {
        return segment_clear(geometry, pi.center, pi.normal, pj.center, pj.normal) as u32 as f32;
    }
    let (lo, hi) = (i.min(j), i.max(j));
    let (a, b) = (&patches[lo], &patches[hi]);
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

/// Builds every patch's links (in parallel; the result does not depend on
/// the number of threads). `threshold`: see the module documentation; with
/// threshold 0 every link goes to a single patch, the full O(N²) solution.
pub fn build(
    patches: &[Patch],
    hierarchy: &Hierarchy,
    geometry: &Geometry,
    threshold: f32,
    seed: u64,
) -> Links {
    let n = patches.len();
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
        seed,
        cdf: &cdf,
    };
    let mut out = Links {
        offsets: Vec::with_capacity(n + 1),
        links: Vec::new(),
        to_patches: 0,
    };
    out.offsets.push(0);
    // In chunks, so that the per-patch vectors do not all live at once.
    for chunk in (0..n).collect::<Vec<_>>().chunks(4096) {
        let lists: Vec<Vec<Link>> = chunk
            .par_iter()
            .map(|&i| ctx.links_of(i, &mut Vec::new()))
            .collect();
        for list in lists {
            out.to_patches += list.iter().filter(|l| (l.source as usize) < n).count();
            out.links.extend(list);
            out.offsets.push(out.links.len() as u32);
        }
    }
    out.links.shrink_to_fit();
    out
}

struct Context<'a> {
    patches: &'a [Patch],
    hierarchy: &'a Hierarchy,
    geometry: &'a Geometry,
    threshold: f32,
    seed: u64,
    cdf: &'a [f64],
}

impl Context<'_> {
    fn links_of(&self, i: usize, stack: &mut Vec<u32>) -> Vec<Link> {
        let n = self.patches.len() as u32;
        let pi = &self.patches[i];
        let mut links = Vec::new();
        stack.clear();
        stack.push(self.hierarchy.root);
        while let Some(node) = stack.pop() {
            if node < n {
                let j = node as usize;
                if j == i {
                    continue;
                }
                let f = form_factor(pi, &self.patches[j]);
                if f > 0.0 {
                    let v = visibility(self.geometry, self.patches, i, j, self.seed);
                    if v > 0.0 {
                        links.push(Link {
                            source: node,
                            factor: f * v,
                        });
                    }
                }
                continue;
            }
            let c = &self.hierarchy.clusters[(node - n) as usize];
            let d = c.center - pi.center;
            if pi.normal.dot(d) + c.radius <= 0.0 {
                continue;
            }
            let dist2 = d.length_squared();
            let far = dist2 > 4.0 * c.radius * c.radius;
            if far && c.area < self.threshold * PI * dist2 {
                let f = self.cluster_factor(i, node, c);
                if f > 0.0 {
                    links.push(Link {
                        source: node,
                        factor: f,
                    });
                }
                continue;
            }
            let first = c.first_child as usize;
            stack
                .extend_from_slice(&self.hierarchy.children[first..first + c.child_count as usize]);
        }
        links
    }

    fn cluster_factor(&self, i: usize, node: u32, c: &super::hierarchy::Cluster) -> f32 {
        let pi = &self.patches[i];
        let (lo, hi) = (self.cdf[c.start as usize], self.cdf[c.end as usize]);
        let key = mix(self.seed ^ mix(((i as u64) << 32) | node as u64));
        let mut sum = 0.0;
        for m in 0..CLUSTER_SAMPLES {
            let u = (m as f64
                + (mix(key.wrapping_add(m as u64)) >> 11) as f64 / (1u64 << 53) as f64)
                / CLUSTER_SAMPLES as f64;
            let target = lo + u * (hi - lo);
            // The patch k whose area interval holds `target`.
            let k = (self.cdf[c.start as usize + 1..=c.end as usize]
                .partition_point(|&x| x <= target)
                + c.start as usize)
                .min(c.end as usize - 1);
            let pk = &self.patches[k];
            let g = point_factor(pi.center, pi.normal, pk.center, pk.normal, 1.0);
            if g > 0.0 && segment_clear(self.geometry, pi.center, pi.normal, pk.center, pk.normal) {
                sum += g;
            }
        }
        c.area * sum / CLUSTER_SAMPLES as f32
    }
}

/// Whether any of 16 cosine-distributed rays from the patch's centre hits a
/// surface. A patch side that sees nothing exchanges (almost) no light —
/// Σ_j F_ij is the fraction of cosine-distributed rays that hit — so such
/// sides (the outside of a closed room) are dropped before linking.
pub fn sees_anything(geometry: &Geometry, p: &Patch, key: u64) -> bool {
    let h = mix(key);
    let (ox, oy) = (
        (h & 0xffff) as f32 / 65536.0,
        ((h >> 16) & 0xffff) as f32 / 65536.0,
    );
    let origin_for = |d: Vec3| offset_origin(p.center, p.normal, d);
    for a in 0..4 {
        for b in 0..4 {
            let u = glam::Vec2::new(
                ((a as f32 + ox) / 4.0).fract(),
                ((b as f32 + oy) / 4.0).fract(),
            );
            let disk = crate::sampling::concentric_disk(u);
            let z = (1.0 - disk.length_squared()).max(0.0).sqrt();
            let d = crate::sampling::to_world(Vec3::new(disk.x, disk.y, z), p.normal);
            let ray = Ray::new(origin_for(d), d);
            if geometry.intersect(&ray, f32::INFINITY).is_some() {
                return true;
            }
        }
    }
    false
}
