//! A density grid: voxel values interpolated trilinearly inside a box,
//! vacuum outside, with a coarse grid of maxima for tracking.
//!
//! **Convention (Mitsuba 3's `gridvolume`).** In voxel coordinates the box
//! is [0, n]³ (n per axis) and voxel (i, j, k) is the cube
//! [i, i+1]×[j, j+1]×[k, k+1]; its value sits at the cube's centre
//! (i + ½, j + ½, k + ½). Between centres the density is trilinear; between
//! the outermost centres and the box's faces it is extended (clamped), so
//! a one-voxel grid is constant in its box. Outside the box it is 0.
//!
//! Along a ray the trilinear interpolant is a polynomial of degree at most
//! 3 in t between two consecutive planes through voxel centres (each of the
//! three factors is linear in t), so two Gauss–Legendre points per such
//! piece integrate it exactly ([`DensityGrid::integral`]).
//!
//! The majorant grid (as in pbrt-v4's `MajorantGrid`, Pharr, Jakob and
//! Humphreys, "Physically Based Rendering", 4th ed., 2023, §11.4) holds in
//! each of its coarse cells the largest value of the voxels whose values
//! enter the interpolation anywhere in that cell: a bound of the density
//! there, because a trilinear interpolant lies between the smallest and
//! largest of its eight corners. Tracking walks these cells along the ray
//! by a DDA (Amanatides and Woo, "A Fast Voxel Traversal Algorithm for Ray
//! Tracing", 1987) and skips the empty ones at no cost.

use glam::{Affine3A, IVec3, Vec3};

/// Majorant cells per axis by default (at most the voxel count).
pub const MAJORANT_RESOLUTION: usize = 16;

/// Voxel values in a box, placed in the world by an affine transform.
#[derive(Clone, PartialEq)]
pub struct DensityGrid {
    resolution: [usize; 3],
    /// x fastest, then y, then z.
    values: Vec<f32>,
    /// World → voxel coordinates (the box is [0, n]³ there).
    voxel_from_world: Affine3A,
    world_from_voxel: Affine3A,
    majorants: Vec<f32>,
    majorant_resolution: [usize; 3],
    max_value: f32,
    /// A hash of the values, so that the debug text (a render's
    /// fingerprint) changes with them.
    checksum: u64,
}

impl std::fmt::Debug for DensityGrid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DensityGrid")
            .field("resolution", &self.resolution)
            .field("max_value", &self.max_value)
            .field("checksum", &format_args!("{:016x}", self.checksum))
            .field("world_from_voxel", &self.world_from_voxel)
            .finish_non_exhaustive()
    }
}

impl DensityGrid {
    /// A grid of `values` (x fastest; finite and non-negative, as many as
    /// the resolution says) filling the box [min, max] of its local space,
    /// placed by `world_from_local`. None if the values do not fit, the
    /// box is empty or the transform cannot be inverted.
    pub fn new(
        resolution: [usize; 3],
        values: Vec<f32>,
        min: Vec3,
        max: Vec3,
        world_from_local: Affine3A,
    ) -> Option<Self> {
        let count = resolution.iter().try_fold(1usize, |n, &r| n.checked_mul(r))?;
        if count == 0 || values.len() != count || values.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return None;
        }
        let size = max - min;
        if !(size.is_finite() && size.cmpgt(Vec3::ZERO).all()) {
            return None;
        }
        let n = Vec3::new(resolution[0] as f32, resolution[1] as f32, resolution[2] as f32);
        let local_from_voxel = Affine3A::from_scale_rotation_translation(size / n, glam::Quat::IDENTITY, min);
        let world_from_voxel = world_from_local * local_from_voxel;
        let det = world_from_voxel.matrix3.determinant();
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        let mut grid = DensityGrid {
            resolution,
            values,
            voxel_from_world: world_from_voxel.inverse(),
            world_from_voxel,
            majorants: Vec::new(),
            majorant_resolution: [1; 3],
            max_value: 0.0,
            checksum: 0,
        };
        grid.max_value = grid.values.iter().copied().fold(0.0, f32::max);
        // FNV-1a over the values' bits, a word at a time.
        grid.checksum = grid
            .values
            .iter()
            .fold(0xcbf2_9ce4_8422_2325u64, |h, v| (h ^ v.to_bits() as u64).wrapping_mul(0x0000_0100_0000_01b3));
        grid.set_majorant_resolution(MAJORANT_RESOLUTION);
        Some(grid)
    }

    pub fn resolution(&self) -> [usize; 3] {
        self.resolution
    }

    /// The largest voxel value.
    pub fn max_value(&self) -> f32 {
        self.max_value
    }

    /// The box's eight corners in world space.
    pub fn corners(&self) -> [Vec3; 8] {
        let n = self.extent();
        std::array::from_fn(|i| {
            let c = Vec3::new(
                if i & 1 == 0 { 0.0 } else { n.x },
                if i & 2 == 0 { 0.0 } else { n.y },
                if i & 4 == 0 { 0.0 } else { n.z },
            );
            self.world_from_voxel.transform_point3(c)
        })
    }

    /// Bytes the grid holds (values and majorants).
    pub fn bytes(&self) -> usize {
        (self.values.len() + self.majorants.len()) * size_of::<f32>()
    }

    /// Rebuilds the majorant grid with up to `cells` cells per axis (1: one
    /// global majorant, for comparison).
    pub fn set_majorant_resolution(&mut self, cells: usize) {
        let m = self.resolution.map(|n| n.clamp(1, cells.max(1)));
        let mut majorants = vec![0.0f32; m[0] * m[1] * m[2]];
        for z in 0..m[2] {
            for y in 0..m[1] {
                for x in 0..m[0] {
                    // The voxels whose values enter the interpolation in
                    // the cell [lo, hi] (voxel coordinates): centres within
                    // one voxel of it.
                    let range = |axis: usize, c: usize| {
                        let n = self.resolution[axis];
                        let lo = c as f64 * n as f64 / m[axis] as f64;
                        let hi = (c + 1) as f64 * n as f64 / m[axis] as f64;
                        let first = ((lo - 0.5).floor().max(0.0)) as usize;
                        let last = (((hi - 0.5).floor() + 1.0).max(0.0) as usize).min(n - 1);
                        first..=last
                    };
                    let mut most = 0.0f32;
                    for k in range(2, z) {
                        for j in range(1, y) {
                            for i in range(0, x) {
                                most = most.max(self.value(i, j, k));
                            }
                        }
                    }
                    majorants[(z * m[1] + y) * m[0] + x] = most;
                }
            }
        }
        self.majorants = majorants;
        self.majorant_resolution = m;
    }

    #[inline]
    fn value(&self, i: usize, j: usize, k: usize) -> f32 {
        self.values[(k * self.resolution[1] + j) * self.resolution[0] + i]
    }

    fn extent(&self) -> Vec3 {
        Vec3::new(self.resolution[0] as f32, self.resolution[1] as f32, self.resolution[2] as f32)
    }

    /// The density at world point `p` (module notes).
    #[inline]
    pub fn density(&self, p: Vec3) -> f32 {
        self.density_voxel(self.voxel_from_world.transform_point3(p))
    }

    /// The density at voxel coordinates `v`.
    #[inline]
    fn density_voxel(&self, v: Vec3) -> f32 {
        let n = self.extent();
        if !(v.cmpge(Vec3::ZERO).all() && v.cmple(n).all()) {
            return 0.0;
        }
        let u = v - 0.5;
        let base = u.floor();
        trilinear(&self.cell_values(base.as_ivec3()), u - base)
    }

    /// The values at the eight corners of cell `c` of the interpolant (the
    /// cell whose low corner is the centre of voxel `c`), clamped to the
    /// grid at its faces, x fastest.
    #[inline]
    fn cell_values(&self, c: IVec3) -> [f32; 8] {
        let clamp = |x: i32, axis: usize| (x.max(0) as usize).min(self.resolution[axis] - 1);
        let (i0, j0, k0) = (clamp(c.x, 0), clamp(c.y, 1), clamp(c.z, 2));
        let (i1, j1, k1) = (clamp(c.x + 1, 0), clamp(c.y + 1, 1), clamp(c.z + 1, 2));
        [
            self.value(i0, j0, k0),
            self.value(i1, j0, k0),
            self.value(i0, j1, k0),
            self.value(i1, j1, k0),
            self.value(i0, j0, k1),
            self.value(i1, j0, k1),
            self.value(i0, j1, k1),
            self.value(i1, j1, k1),
        ]
    }

    /// The part of [t0, t1] of the line o + t·d inside the box, if any.
    pub fn clip(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Option<(f32, f32)> {
        let (vo, vd) = self.to_voxel(o, d);
        clip_box(vo, vd, self.extent(), t0, t1)
    }

    fn to_voxel(&self, o: Vec3, d: Vec3) -> (Vec3, Vec3) {
        (self.voxel_from_world.transform_point3(o), self.voxel_from_world.transform_vector3(d))
    }

    /// ∫ density dt over [t0, t1] of o + t·d, exact for the trilinear
    /// interpolant up to rounding (module notes); t1 may be infinite.
    pub fn integral(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> f64 {
        let (vo, vd) = self.to_voxel(o, d);
        let Some((a, b)) = clip_box(vo, vd, self.extent(), t0, t1) else { return 0.0 };
        // Gauss–Legendre, two points: ±1/√3 about the middle.
        const NODE: f64 = 0.577_350_269_189_625_8;
        let mut sum = 0.0f64;
        walk(vo, vd, a, b, Vec3::ONE, Vec3::splat(0.5), |s0, s1, cell| {
            let (mid, half) = (0.5 * (s0 as f64 + s1 as f64), 0.5 * (s1 as f64 - s0 as f64));
            // Both points lie in `cell`: its corners are read once.
            let (corners, low) = (self.cell_values(cell), cell.as_vec3());
            let at = |t: f64| trilinear(&corners, (vo + vd * t as f32 - 0.5) - low) as f64;
            sum += half * (at(mid - half * NODE) + at(mid + half * NODE));
            true
        });
        sum
    }

    /// Calls `f(t0, t1, bound)` for each stretch of [t0, t1] of o + t·d
    /// inside one majorant cell, in order, with the cell's bound of the
    /// density; nothing outside the box. Stops when `f` returns false.
    pub fn majorant_segments(&self, o: Vec3, d: Vec3, t0: f32, t1: f32, mut f: impl FnMut(f32, f32, f32) -> bool) {
        let (vo, vd) = self.to_voxel(o, d);
        let Some((a, b)) = clip_box(vo, vd, self.extent(), t0, t1) else { return };
        let m = self.majorant_resolution;
        let cell = self.extent() / Vec3::new(m[0] as f32, m[1] as f32, m[2] as f32);
        walk(vo, vd, a, b, cell, Vec3::ZERO, |s0, s1, c| {
            let at = |axis: usize| (c[axis].max(0) as usize).min(m[axis] - 1);
            let bound = self.majorants[(at(2) * m[1] + at(1)) * m[0] + at(0)];
            f(s0, s1, bound)
        });
    }
}

/// The trilinear interpolation of a cell's `corners` (x fastest) at
/// offset `f` from its low corner.
#[inline]
fn trilinear(corners: &[f32; 8], f: Vec3) -> f32 {
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let [c000, c100, c010, c110, c001, c101, c011, c111] = *corners;
    let (x00, x10) = (lerp(c000, c100, f.x), lerp(c010, c110, f.x));
    let (x01, x11) = (lerp(c001, c101, f.x), lerp(c011, c111, f.x));
    lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z)
}

/// The part of [t0, t1] of o + t·d inside the box [0, n], by slabs.
fn clip_box(o: Vec3, d: Vec3, n: Vec3, t0: f32, t1: f32) -> Option<(f32, f32)> {
    let (mut lo, mut hi) = (t0, t1);
    for axis in 0..3 {
        if d[axis] == 0.0 {
            if o[axis] < 0.0 || o[axis] > n[axis] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d[axis];
        let (a, b) = ((0.0 - o[axis]) * inv, (n[axis] - o[axis]) * inv);
        lo = lo.max(a.min(b));
        hi = hi.min(a.max(b));
    }
    (lo < hi).then_some((lo, hi))
}

/// Walks [a, b] of o + t·d (finite) through the lattice of cells of size
/// `cell` whose planes sit at `phase` + k·`cell`, calling `f(t0, t1, cell
/// index)` for each piece in order, until `f` returns false.
fn walk(o: Vec3, d: Vec3, a: f32, b: f32, cell: Vec3, phase: Vec3, mut f: impl FnMut(f32, f32, IVec3) -> bool) {
    let start = o + d * a;
    let mut index = ((start - phase) / cell).floor().as_ivec3();
    let mut next = [f32::INFINITY; 3];
    let mut delta = [f32::INFINITY; 3];
    let mut step = [0i32; 3];
    for axis in 0..3 {
        if d[axis] == 0.0 {
            continue;
        }
        step[axis] = if d[axis] > 0.0 { 1 } else { -1 };
        let plane = phase[axis] + (index[axis] + i32::from(d[axis] > 0.0)) as f32 * cell[axis];
        next[axis] = (plane - o[axis]) / d[axis];
        delta[axis] = cell[axis] / d[axis].abs();
    }
    let mut t = a;
    // Each axis crosses at most its count of planes: a guard against a
    // rounding loop, never reached on a finite segment.
    let mut guard = 4 + (((b - a) * d.abs() / cell).ceil().element_sum() as u64).min(1 << 40);
    while t < b && guard > 0 {
        guard -= 1;
        let axis = if next[0] <= next[1] && next[0] <= next[2] {
            0
        } else if next[1] <= next[2] {
            1
        } else {
            2
        };
        let end = next[axis].min(b);
        if end > t && !f(t, end, index) {
            return;
        }
        t = t.max(end);
        index[axis] += step[axis];
        next[axis] += delta[axis];
    }
}

#[cfg(test)]
mod tests;
