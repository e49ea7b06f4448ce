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
//! The patches are binned in a hash grid of cells of size R.

use super::patches::Patch;
use glam::{IVec3, Vec3};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A hash grid over patch centres.
#[derive(Clone, Debug, Default)]
pub struct Lookup {
    radius: f32,
    cells: HashMap<IVec3, (u32, u32), BuildHasherDefault<CellHasher>>,
    ids: Vec<u32>,
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
        Lookup { radius, cells, ids: keyed.into_iter().map(|(_, i)| i).collect() }
    }

    pub fn radius(&self) -> f32 {
        self.radius
    }

    pub fn bytes(&self) -> usize {
        self.ids.capacity() * 4 + self.cells.capacity() * (size_of::<IVec3>() + 8 + 8)
    }

    /// The kernel average of `value(i)` over the patches around `p` on the
    /// side whose normal is `n` (see the module documentation); None when no
    /// patch is near.
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
        let r = self.radius;
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
        let mut total = T::default();
        let mut weight = 0.0;
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
                        let d = patch.center - p;
                        let facing = 2.0 * n.dot(patch.normal) - 1.0;
                        if facing <= 0.0 || n.dot(d).abs() > 0.5 * r {
                            continue;
                        }
                        let dist = d.length();
                        if dist >= r || !keep(i as usize) {
                            continue;
                        }
                        let w = (1.0 - dist / r) * facing;
                        total = total + value(i as usize) * w;
                        weight += w;
                    }
                }
            }
        }
        (weight > 0.0).then(|| total * (1.0 / weight))
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

    #[test]
    fn the_grid_takes_every_patch_that_testing_all_of_them_takes() {
        // Patches on axis-aligned and slanted planes through a box, queried
        // at random points near them with their normals: the grid, which
        // skips cells, must give what testing every patch gives.
        let mut s = Sampler::for_pixel(11, 0, 0);
        let r = 0.3;
        let normals = [Vec3::X, Vec3::Y, -Vec3::Z, Vec3::new(1.0, 2.0, -0.5).normalize()];
        let mut patches = Vec::new();
        for (k, &n) in normals.iter().enumerate() {
            let (t, b) = crate::sampling::basis(n);
            for _ in 0..400 {
                let center = n * (0.4 * k as f32) + (t * (s.next() - 0.5) + b * (s.next() - 0.5)) * 3.0;
                let shape = PatchShape { origin: center, e1: t * 0.1, e2: b * 0.1, triangle: false };
                patches.push(Patch { center, normal: n, area: 0.01, radius: 0.07, material: 0, object: 0, shape });
            }
        }
        let lookup = Lookup::build(&patches, r);
        let mut compared = 0;
        for _ in 0..4000 {
            let source = &patches[(s.next() * patches.len() as f32) as usize % patches.len()];
            let n = if s.next() < 0.8 { source.normal } else { uniform_sphere(s.next2()) };
            let p = source.center + uniform_sphere(s.next2()) * (0.4 * r * s.next());
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
