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
        let r = self.radius;
        let lo = ((p - r) / r).floor().as_ivec3();
        let hi = ((p + r) / r).floor().as_ivec3();
        let mut total = T::default();
        let mut weight = 0.0;
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    let Some(&(a, b)) = self.cells.get(&IVec3::new(x, y, z)) else {
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
                        if dist >= r {
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
