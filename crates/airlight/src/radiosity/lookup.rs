//! Finding the patches around a point, for smooth shading.
//!
//! A camera ray's hit is shaded with a normalised kernel average of the
//! values at nearby patch centres (Shepard interpolation with a tent):
//!
//!   v(p) = Σ_i w_i v_i / Σ_i w_i,  w_i = (1 − |c_i − p| / R)₊ · s_i,
//!
//! over the patches i on the side facing the viewer: s_i = ((n·n_i − ½)/½)₊
//! rejects patches that face another way (across a corner), and centres more
//! than R/2 off the tangent plane at p are skipped (a parallel surface close
//! behind). R = 1.5 × patch size, so a point always has its own patch's
//! centre inside the kernel (a patch's centre is at most √½ × patch size
//! from its points), and the weights, hence the shading, vary continuously.
//! The patches are binned in a hash grid of cells of size R. On the first
//! query, a finer dense grid (cells of R/2) gets per cell the list of
//! patches within R of it, in the order the hash grid's cells give them:
//! a query then reads one list (a dozen patches on a wall) instead of
//! probing up to 27 cells, and sums the same terms in the same order, so
//! the answer is the same to the bit. Scenes with more than
//! [`MAX_NEAR_PATCHES`] patches, or whose grid would be too large, keep
//! probing.

use super::patches::Patch;
use glam::{I64Vec3, IVec3, Vec3};
use rayon::slice::ParallelSliceMut;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::OnceLock;

/// A hash grid over patch centres.
#[derive(Clone, Debug, Default)]
pub struct Lookup {
    radius: f32,
    cells: HashMap<IVec3, (u32, u32), BuildHasherDefault<CellHasher>>,
    ids: Vec<u32>,
    /// The candidate lists of [`Near`], made on the first query (only
    /// what renders needs them; compiling does not).
    near: OnceLock<Option<Near>>,
}

/// Lookups of more patches than this probe the grid's cells instead of
/// making candidate lists (about 400 bytes a patch: 50 MB here).
pub const MAX_NEAR_PATCHES: usize = 1 << 17;
/// Nor are lists made when their grid, dense over the patches' bounding
/// box, would have more cells than this (4 bytes each: 32 MB): an infinite
/// plane's outer rings reach far.
pub const MAX_NEAR_CELLS: usize = 1 << 23;

/// Per cell of a finer grid (side R/2), the patches whose centres lie
/// within R of the cell: every patch the kernel could take at a point in
/// it, listed in the order the probing of the coarse cells takes them. A
/// query is then one index into a dense grid and one short list (a dozen
/// patches on a flat wall) instead of up to 27 hash probes; the sum, term
/// by term in the same order, is the same to the bit.
#[derive(Clone, Debug, Default)]
struct Near {
    cell: f32,
    /// The grid's first cell and its size in cells.
    lo: IVec3,
    size: IVec3,
    /// Cell k's list is `ids[starts[k]..starts[k + 1]]`, cells in x-major order.
    starts: Vec<u32>,
    ids: Vec<u32>,
    /// Centre and normal of every patch, packed for the lists' gathers.
    points: Vec<(Vec3, Vec3)>,
}

impl Near {
    /// The lists for `ids`, the patches in the probing order; None when
    /// the grid would be too large.
    fn build(patches: &[Patch], ids: &[u32], radius: f32) -> Option<Near> {
        if patches.is_empty() || patches.len() > MAX_NEAR_PATCHES {
            return None;
        }
        let cell = 0.5 * radius;
        // Generous against rounding: a longer list costs little, a patch
        // left out would change the answer.
        let reach = radius * (1.0 + 1e-3);
        let span = |c: Vec3| (((c - reach) / cell).floor().as_ivec3(), ((c + reach) / cell).floor().as_ivec3());
        let (mut lo, mut hi) = (IVec3::MAX, IVec3::MIN);
        for p in patches {
            let (a, b) = span(p.center);
            (lo, hi) = (lo.min(a), hi.max(b));
        }
        let size = hi.as_dvec3() - lo.as_dvec3() + 1.0;
        let cells = size.element_product();
        if cells.is_nan() || cells > MAX_NEAR_CELLS as f64 {
            return None;
        }
        let size = size.as_ivec3();
        let index = |k: IVec3| {
            let k = k - lo;
            ((k.x * size.y + k.y) * size.z + k.z) as u32
        };
        let mut keyed: Vec<(u32, u32)> = Vec::new();
        for (rank, &i) in ids.iter().enumerate() {
            let c = patches[i as usize].center;
            let (a, b) = span(c);
            for x in a.x..=b.x {
                for y in a.y..=b.y {
                    for z in a.z..=b.z {
                        let key = IVec3::new(x, y, z);
                        let box_lo = key.as_vec3() * cell;
                        if c.clamp(box_lo, box_lo + cell).distance(c) < reach {
                            keyed.push((index(key), rank as u32));
                        }
                    }
                }
            }
        }
        keyed.par_sort_unstable();
        let mut starts = vec![0u32; size.element_product() as usize + 1];
        for &(k, _) in &keyed {
            starts[k as usize + 1] += 1;
        }
        for k in 1..starts.len() {
            starts[k] += starts[k - 1];
        }
        Some(Near {
            cell,
            lo,
            size,
            starts,
            ids: keyed.into_iter().map(|(_, rank)| ids[rank as usize]).collect(),
            points: patches.iter().map(|p| (p.center, p.normal)).collect(),
        })
    }

    /// The list of the cell that holds `p` (empty outside the grid).
    #[inline]
    fn list(&self, p: Vec3) -> &[u32] {
        // In i64: a far point's cell saturates i32.
        let (k, size) = ((p / self.cell).floor().as_i64vec3() - self.lo.as_i64vec3(), self.size.as_i64vec3());
        if k.cmplt(I64Vec3::ZERO).any() || k.cmpge(size).any() {
            return &[];
        }
        let k = ((k.x * size.y + k.y) * size.z + k.z) as usize;
        &self.ids[self.starts[k] as usize..self.starts[k + 1] as usize]
    }

    fn bytes(&self) -> usize {
        (self.ids.capacity() + self.starts.capacity()) * 4 + self.points.capacity() * size_of::<(Vec3, Vec3)>()
    }
}

impl Lookup {
    /// Bins `patches` for queries with kernel radius `radius`.
    pub fn build(patches: &[Patch], radius: f32) -> Lookup {
        let cell = |p: Vec3| (p / radius).floor().as_ivec3();
        let mut keyed: Vec<(IVec3, u32)> =
            patches.iter().enumerate().map(|(i, p)| (cell(p.center), i as u32)).collect();
        keyed.sort_by_key(|&(c, i)| (c.x, c.y, c.z, i));
        let mut cells = HashMap::default();
        let mut start = 0;
        while start < keyed.len() {
            let c = keyed[start].0;
            let mut end = start;
            while end < keyed.len() && keyed[end].0 == c {
                end += 1;
            }
            cells.insert(c, (start as u32, end as u32));
            start = end;
        }
        Lookup { radius, cells, ids: keyed.into_iter().map(|(_, i)| i).collect(), near: OnceLock::new() }
    }

    pub fn radius(&self) -> f32 {
        self.radius
    }

    pub fn bytes(&self) -> usize {
        self.ids.capacity() * 4
            + self.cells.capacity() * (size_of::<IVec3>() + 8 + 8)
            + self.near.get().and_then(Option::as_ref).map_or(0, Near::bytes)
    }

    /// The kernel average of `value(i)` over the patches around `p` on the
    /// side whose normal is `n` (see the module documentation); None when no
    /// patch is near. `patches` must be those the lookup was built from.
    pub fn interpolate<T>(&self, patches: &[Patch], p: Vec3, n: Vec3, value: impl Fn(usize) -> T) -> Option<T>
    where
        T: std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T> + Default,
    {
        self.interpolate_where(patches, p, n, |_| true, value)
    }

    /// [`Lookup::interpolate`] over the patches that `keep(i)` accepts (the
    /// radiosity integrator keeps those that `p` sees, so that light does
    /// not blend across a wall).
    pub fn interpolate_where<T>(
        &self,
        patches: &[Patch],
        p: Vec3,
        n: Vec3,
        keep: impl Fn(usize) -> bool,
        value: impl Fn(usize) -> T,
    ) -> Option<T>
    where
        T: std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T> + Default,
    {
        let mut total = T::default();
        let weight = self.each_weight(patches, p, n, keep, |i, w| total = std::mem::take(&mut total) + value(i) * w);
        (weight > 0.0).then(|| total * (1.0 / weight))
    }

    /// The kernel's terms at `p` as (patch, weight) pairs appended to `out`,
    /// and the factor 1/Σ w that normalises them; None (nothing appended)
    /// where no patch is near. Σ value(i)·w, summed in this order from
    /// zero, times the factor, is [`Lookup::interpolate`] to the bit.
    pub fn weights(&self, patches: &[Patch], p: Vec3, n: Vec3, out: &mut Vec<(u32, f32)>) -> Option<f32> {
        let before = out.len();
        let weight = self.each_weight(patches, p, n, |_| true, |i, w| out.push((i as u32, w)));
        if weight > 0.0 {
            Some(1.0 / weight)
        } else {
            out.truncate(before);
            None
        }
    }

    /// Calls `term(i, w)` for each patch the kernel takes at `p`, in the
    /// order of the coarse cells' probing, and returns Σ w.
    fn each_weight(
        &self,
        patches: &[Patch],
        p: Vec3,
        n: Vec3,
        keep: impl Fn(usize) -> bool,
        mut term: impl FnMut(usize, f32),
    ) -> f32 {
        let near = self.near.get_or_init(|| Near::build(patches, &self.ids, self.radius));
        let r = self.radius;
        let mut weight = 0.0;
        if let Some(near) = near {
            // Eight candidates at a time, their tests and weights computed
            // without branches (so the compiler can use vector lanes), then
            // their terms taken in order: the arithmetic of `take` below,
            // operation for operation, so the same bits.
            const LANES: usize = 8;
            for chunk in near.list(p).chunks(LANES) {
                let (mut c, mut m) = ([[0.0f32; LANES]; 3], [[0.0f32; LANES]; 3]);
                for (k, &i) in chunk.iter().enumerate() {
                    let (center, normal) = near.points[i as usize];
                    (c[0][k], c[1][k], c[2][k]) = (center.x, center.y, center.z);
                    (m[0][k], m[1][k], m[2][k]) = (normal.x, normal.y, normal.z);
                }
                let (mut w, mut ok) = ([0.0f32; LANES], [false; LANES]);
                for k in 0..LANES {
                    let d = Vec3::new(c[0][k], c[1][k], c[2][k]) - p;
                    let facing = 2.0 * n.dot(Vec3::new(m[0][k], m[1][k], m[2][k])) - 1.0;
                    let dist = d.length();
                    // `take`'s rejections, NaNs included.
                    let reject = (facing <= 0.0) | (n.dot(d).abs() > 0.5 * r) | (dist >= r);
                    ok[k] = !reject;
                    w[k] = (1.0 - dist / r) * facing;
                }
                for (k, &i) in chunk.iter().enumerate() {
                    if ok[k] && keep(i as usize) {
                        term(i as usize, w[k]);
                        weight += w[k];
                    }
                }
            }
            return weight;
        }
        // One patch's term: the tests and the arithmetic of the module
        // documentation, as the lists' lanes do it.
        let mut take = |i: u32, center: Vec3, normal: Vec3| {
            let d = center - p;
            let facing = 2.0 * n.dot(normal) - 1.0;
            if facing <= 0.0 || n.dot(d).abs() > 0.5 * r {
                return;
            }
            let dist = d.length();
            if dist >= r || !keep(i as usize) {
                return;
            }
            let w = (1.0 - dist / r) * facing;
            term(i as usize, w);
            weight += w;
        };
        let lo = ((p - r) / r).floor().as_ivec3();
        let hi = ((p + r) / r).floor().as_ivec3();
        // Cells that hold no centre the loop below could take are passed
        // over before their hash lookup: those wholly beyond the tangent slab
        // |n·(c − p)| ≤ R/2 (on a wall, one layer of the three across it) or
        // wholly beyond R. A margin keeps centres binned across a cell's edge
        // by rounding; the result is the same as testing every cell.
        let margin = 1e-3 * r;
        let slab = 0.5 * r + margin;
        let half_thickness = 0.5 * r * n.abs().element_sum();
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    let cell = IVec3::new(x, y, z);
                    let cell_lo = cell.as_vec3() * r;
                    let off_plane = n.dot(cell_lo + 0.5 * r - p);
                    if off_plane.abs() - half_thickness > slab {
                        continue;
                    }
                    let nearest = p.clamp(cell_lo, cell_lo + r);
                    if nearest.distance(p) >= r + margin {
                        continue;
                    }
                    let Some(&(a, b)) = self.cells.get(&cell) else {
                        continue;
                    };
                    for &i in &self.ids[a as usize..b as usize] {
                        let patch = &patches[i as usize];
                        take(i, patch.center, patch.normal);
                    }
                }
            }
        }
        weight
    }
}

/// FxHash-style hashing of grid cells (three multiplies and rotates): the
/// map's keys are small integer triples, for which SipHash is needlessly slow.
#[derive(Default)]
pub struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_i32(&mut self, v: i32) {
        self.write_u64(v as u32 as u64);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiosity::patches::PatchShape;
    use crate::sampling::{Sampler, uniform_sphere};

    /// The kernel average over every patch, without the grid.
    fn brute_force(patches: &[Patch], r: f32, p: Vec3, n: Vec3) -> Option<f32> {
        let (mut total, mut weight) = (0.0, 0.0);
        for (i, patch) in patches.iter().enumerate() {
            let d = patch.center - p;
            let facing = 2.0 * n.dot(patch.normal) - 1.0;
            if facing <= 0.0 || n.dot(d).abs() > 0.5 * r || d.length() >= r {
                continue;
            }
            let w = (1.0 - d.length() / r) * facing;
            total += i as f32 * w;
            weight += w;
        }
        (weight > 0.0).then(|| total / weight)
    }

    fn patch(center: Vec3, normal: Vec3, size: f32) -> Patch {
        let (t, b) = crate::sampling::basis(normal);
        let origin = center - (t + b) * (0.5 * size);
        let shape = PatchShape { origin, e1: t * size, e2: b * size, triangle: false };
        Patch { center, normal, area: size * size, radius: 0.71 * size, material: 0, object: 0, shape }
    }

    /// Patches on axis-aligned and slanted planes through a box.
    fn planes(s: &mut Sampler) -> Vec<Patch> {
        let normals = [Vec3::X, Vec3::Y, -Vec3::Z, Vec3::new(1.0, 2.0, -0.5).normalize()];
        let mut patches = Vec::new();
        for (k, &n) in normals.iter().enumerate() {
            let (t, b) = crate::sampling::basis(n);
            for _ in 0..400 {
                let center = n * (0.4 * k as f32) + (t * (s.next() - 0.5) + b * (s.next() - 0.5)) * 3.0;
                patches.push(patch(center, n, 0.1));
            }
        }
        patches
    }

    /// A query near a random patch: its normal mostly, sometimes any.
    fn query(s: &mut Sampler, patches: &[Patch], r: f32) -> (Vec3, Vec3) {
        let source = &patches[(s.next() * patches.len() as f32) as usize % patches.len()];
        let n = if s.next() < 0.8 { source.normal } else { uniform_sphere(s.next2()) };
        (source.center + uniform_sphere(s.next2()) * (0.4 * r * s.next()), n)
    }

    #[test]
    fn the_candidate_lists_give_what_probing_the_cells_gives_to_the_bit() {
        let mut s = Sampler::for_pixel(12, 0, 0);
        let r = 0.3;
        let patches = planes(&mut s);
        let lists = Lookup::build(&patches, r);
        let probing = Lookup { near: OnceLock::from(None), ..Lookup::build(&patches, r) };
        let value = |i: usize| Vec3::new(i as f32, (i * i % 97) as f32, 1.0 / (1.0 + i as f32));
        let mut taken = 0;
        let mut weights = Vec::new();
        for _ in 0..4000 {
            let (p, n) = query(&mut s, &patches, r);
            let a = lists.interpolate(&patches, p, n, value);
            let b = probing.interpolate(&patches, p, n, value);
            assert_eq!(a, b, "at {p}, normal {n}");
            // Every third patch "unseen": the integrator's visibility filter.
            let keep = |i: usize| !i.is_multiple_of(3);
            assert_eq!(
                lists.interpolate_where(&patches, p, n, keep, value),
                probing.interpolate_where(&patches, p, n, keep, value)
            );
            weights.clear();
            let scale = lists.weights(&patches, p, n, &mut weights);
            let summed = scale.map(|k| weights.iter().fold(Vec3::ZERO, |sum, &(i, w)| sum + value(i as usize) * w) * k);
            assert_eq!(summed, a);
            taken += a.is_some() as u32;
        }
        assert!(taken > 3000, "{taken}");
        assert!(lists.near.get().is_some_and(Option::is_some), "the lists were made and used");
        assert!(probing.bytes() < lists.bytes());
    }

    #[test]
    fn light_does_not_cross_a_thin_wall_or_come_from_a_surface_beyond_the_slab() {
        // A thin wall x = 0 lit on its +x side only (1 there, 0 on the -x
        // side, at the same centres), a floor y = 0 with the wall standing on
        // it (value 2), and behind the wall's dark side, 0.6 R away (beyond
        // the slab of R/2) and facing the same way, a bright sheet (value 5).
        let h = 0.1;
        let r = 1.5 * h;
        let mut patches = Vec::new();
        let mut values = Vec::new();
        for j in 0..20 {
            for k in 0..20 {
                let (y, z) = ((j as f32 + 0.5) * h, (k as f32 + 0.5) * h);
                for (x, n, v) in [(0.0, Vec3::X, 1.0), (0.0, -Vec3::X, 0.0), (0.6 * r, -Vec3::X, 5.0)] {
                    patches.push(patch(Vec3::new(x, y, z), n, h));
                    values.push(v);
                }
                patches.push(patch(Vec3::new(y - 1.0, 0.0, z), Vec3::Y, h));
                values.push(2.0);
            }
        }
        let lookup = Lookup::build(&patches, r);
        let at = |p: Vec3, n: Vec3| lookup.interpolate(&patches, p, n, |i| values[i]).unwrap();
        let mut s = Sampler::for_pixel(5, 0, 0);
        for _ in 0..500 {
            let (y, z) = (0.2 + 1.6 * s.next(), 0.2 + 1.6 * s.next());
            // On the wall's two faces: each its own side's light, exactly.
            assert!((at(Vec3::new(0.0, y, z), Vec3::X) - 1.0).abs() < 1e-6);
            assert_eq!(at(Vec3::new(0.0, y, z), -Vec3::X), 0.0);
            // On the floor by the foot of the wall, on either side of it.
            let x = (s.next() - 0.5) * r;
            assert!((at(Vec3::new(x, 0.0, z), Vec3::Y) - 2.0).abs() < 1e-6, "{x}");
        }
    }

    #[test]
    fn the_grid_takes_every_patch_that_testing_all_of_them_takes() {
        // Patches on axis-aligned and slanted planes through a box, queried
        // at random points near them with their normals: the grid, which
        // skips cells, must give what testing every patch gives, both when
        // probing the cells and from the candidate lists.
        let mut s = Sampler::for_pixel(11, 0, 0);
        let r = 0.3;
        let patches = planes(&mut s);
        let lists = Lookup::build(&patches, r);
        let probing = Lookup { near: OnceLock::from(None), ..Lookup::build(&patches, r) };
        let mut compared = 0;
        for k in 0..4000 {
            let (p, n) = query(&mut s, &patches, r);
            let lookup = if k % 2 == 0 { &lists } else { &probing };
            let grid = lookup.interpolate(&patches, p, n, |i| i as f32);
            let all = brute_force(&patches, r, p, n);
            match (grid, all) {
                (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-4 * b.abs().max(1.0), "{a} vs {b} at {p}"),
                (a, b) => assert_eq!(a.is_some(), b.is_some(), "at {p}: {a:?} vs {b:?}"),
            }
            compared += grid.is_some() as u32;
        }
        assert!(compared > 3000, "{compared}");
    }
}
