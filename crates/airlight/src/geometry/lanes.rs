//! Several f32 lanes and the arithmetic the packet traversal (`packet.rs`)
//! does on them, written once over the [`Lanes`] trait and given by four
//! types: [`Scalar4`], a loop over four floats (any target, and the tests);
//! `Sse4`, four lanes in an SSE register (the x86-64 baseline); `Avx8`,
//! eight lanes in an AVX register, and `Avx16`, sixteen in an AVX-512
//! register, for processors that have them (found at run time). Every
//! operation is a single IEEE operation per lane (no fused multiply-add),
//! so the four give the same bits.

use super::blocks::TriangleBlock;

/// `WIDTH` f32 lanes and the operations the traversal needs. Comparisons
/// give a mask (bit i for lane i) and, like Rust's scalar comparisons, are
/// false when either side is NaN.
pub trait Lanes: Copy {
    /// How many lanes: 4, 8 or 16.
    const WIDTH: usize;
    /// Four lanes with the same arithmetic, for a node's four child boxes.
    type Four: Lanes;
    fn splat(x: f32) -> Self;
    /// Lanes from `s[0..WIDTH]`.
    fn load(s: &[f32]) -> Self;
    /// The lanes as an array of `WIDTH` floats.
    type Array: Copy + AsRef<[f32]> + std::ops::Index<usize, Output = f32>;
    fn to_array(self) -> Self::Array;
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, o: Self) -> Self;
    fn div(self, o: Self) -> Self;
    /// `self.min(o)` where neither is NaN.
    fn min(self, o: Self) -> Self;
    /// `self.max(o)` where neither is NaN.
    fn max(self, o: Self) -> Self;
    fn abs(self) -> Self;
    /// `self` with its sign flipped in the lanes where `sign_of`'s sign bit
    /// is set (exact: a multiplication by ±1 without rounding).
    fn flip_sign(self, sign_of: Self) -> Self;
    fn lt(self, o: Self) -> u32;
    fn le(self, o: Self) -> u32;
    fn eq(self, o: Self) -> u32;

    /// Triangles' (v0, e1, e2) in lanes from 1 to `WIDTH / 4` blocks of
    /// four: lane k from lane k % 4 of `blocks[k / 4]`, and the lanes past
    /// the blocks given repeating the last block (the caller drops their
    /// answers). SSE and AVX lanes load the blocks' rows as they are.
    #[inline(always)]
    fn triangle_lanes(blocks: &[TriangleBlock]) -> [[Self; 3]; 3] {
        let mut rows = [[0.0f32; 16]; 9];
        for k in 0..Self::WIDTH {
            let block = &blocks[(k / 4).min(blocks.len() - 1)];
            for (row, lanes) in rows.iter_mut().zip(&block.rows) {
                row[k] = lanes[k % 4];
            }
        }
        // Written out rather than built by closures, which are compiled
        // without the target features of the function they are inlined in.
        [
            [Self::load(&rows[0]), Self::load(&rows[1]), Self::load(&rows[2])],
            [Self::load(&rows[3]), Self::load(&rows[4]), Self::load(&rows[5])],
            [Self::load(&rows[6]), Self::load(&rows[7]), Self::load(&rows[8])],
        ]
    }

    /// Writes lane i to `out[i]` where bit i of `mask` is set, leaving the
    /// rest of `out[..WIDTH]` as it is.
    #[inline(always)]
    fn store_where(self, mask: u32, out: &mut [f32]) {
        let lanes = self.to_array();
        let mut m = mask;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            out[i] = lanes[i];
        }
    }

    /// Writes `value` to `out[i]` where bit i of `mask` is set.
    #[inline(always)]
    fn fill_where(mask: u32, value: u32, out: &mut [u32]) {
        let mut m = mask;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            out[i] = value;
        }
    }
}

/// The portable lanes: a loop over four f32s.
#[derive(Clone, Copy, Debug)]
pub struct Scalar4([f32; 4]);

impl Scalar4 {
    #[inline(always)]
    fn map2(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        Scalar4(std::array::from_fn(|i| f(self.0[i], o.0[i])))
    }

    #[inline(always)]
    fn mask(self, o: Self, f: impl Fn(f32, f32) -> bool) -> u32 {
        (0..4).fold(0, |m, i| m | ((f(self.0[i], o.0[i]) as u32) << i))
    }
}

impl Lanes for Scalar4 {
    const WIDTH: usize = 4;
    type Four = Scalar4;
    type Array = [f32; 4];
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Scalar4([x; 4])
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        Scalar4([s[0], s[1], s[2], s[3]])
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 4] {
        self.0
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.map2(o, |a, b| a + b)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.map2(o, |a, b| a - b)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        self.map2(o, |a, b| a * b)
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        self.map2(o, |a, b| a / b)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        self.map2(o, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.map2(o, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Scalar4(self.0.map(f32::abs))
    }
    #[inline(always)]
    fn flip_sign(self, sign_of: Self) -> Self {
        self.map2(sign_of, |a, b| f32::from_bits(a.to_bits() ^ (b.to_bits() & 0x8000_0000)))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> u32 {
        self.mask(o, |a, b| a < b)
    }
    #[inline(always)]
    fn le(self, o: Self) -> u32 {
        self.mask(o, |a, b| a <= b)
    }
    #[inline(always)]
    fn eq(self, o: Self) -> u32 {
        self.mask(o, |a, b| a == b)
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx8, Avx16, Sse4, has_avx, has_avx512};

#[cfg(target_arch = "x86_64")]
mod x86;

/// The four-lane type this target's packets use without AVX.
#[cfg(target_arch = "x86_64")]
pub type NativeLanes = Sse4;
#[cfg(not(target_arch = "x86_64"))]
pub type NativeLanes = Scalar4;

/// The lanes a packet query runs on. Queries take the widest this
/// processor has ([`LaneWidth::widest`]); tests and benchmarks name one to
/// compare them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaneWidth {
    /// `Scalar4`: the portable loop over four floats.
    Portable,
    /// `NativeLanes`: four lanes in an SSE register on x86-64.
    Four,
    /// `Avx8`: eight lanes, where the processor has AVX.
    Eight,
    /// `Avx16`: sixteen lanes, where the processor has AVX-512.
    Sixteen,
}

impl LaneWidth {
    pub const ALL: [LaneWidth; 4] = [LaneWidth::Portable, LaneWidth::Four, LaneWidth::Eight, LaneWidth::Sixteen];

    /// Whether this processor has the instructions these lanes need.
    pub fn available(self) -> bool {
        match self {
            LaneWidth::Portable | LaneWidth::Four => true,
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Eight => has_avx(),
            #[cfg(target_arch = "x86_64")]
            LaneWidth::Sixteen => has_avx512(),
            #[cfg(not(target_arch = "x86_64"))]
            LaneWidth::Eight | LaneWidth::Sixteen => false,
        }
    }

    /// The widest lanes this processor has (the answer is cached by std).
    #[inline]
    pub fn widest() -> Self {
        [LaneWidth::Sixteen, LaneWidth::Eight].into_iter().find(|w| w.available()).unwrap_or(LaneWidth::Four)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values that probe the edge cases: signed zeros, infinities, NaN,
    /// denormals, and ordinary numbers.
    const VALUES: [f32; 8] = [0.0, -0.0, 1.5, -2.25, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-40];

    /// Every operation of `L` against the scalar lanes, on all pairs of
    /// [`VALUES`], bit for bit.
    fn same_as_scalar<L: Lanes>() {
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let lane_bits = ((1u64 << L::WIDTH) - 1) as u32;
        for (i, &a) in VALUES.iter().enumerate() {
            // Each lane a different b (of the first eight): a rotation of the values.
            let b: [f32; 16] = std::array::from_fn(|k| VALUES[(i + k) % 8]);
            let (x, y) = (L::splat(a), L::load(&b));
            for (k, &b) in b.iter().take(L::WIDTH).enumerate() {
                let (s, t) = (Scalar4::splat(a), Scalar4::splat(b));
                let lane = |v: L| v.to_array()[k].to_bits();
                let one = |v: Scalar4| v.to_array()[0].to_bits();
                assert_eq!(lane(x.add(y)), one(s.add(t)), "{a} + {b}");
                assert_eq!(lane(x.sub(y)), one(s.sub(t)), "{a} - {b}");
                assert_eq!(lane(x.mul(y)), one(s.mul(t)), "{a} * {b}");
                assert_eq!(lane(x.flip_sign(y)), one(s.flip_sign(t)), "{a} flipped by the sign of {b}");
                assert_eq!(lane(y.flip_sign(x)), one(t.flip_sign(s)), "{b} flipped by the sign of {a}");
                let flipped = if b.is_sign_negative() { -a } else { a };
                assert_eq!(one(s.flip_sign(t)), flipped.to_bits(), "{a} flipped by the sign of {b}");
                let (q, r) = (x.div(y).to_array()[k], s.div(t).to_array()[0]);
                assert!(q.to_bits() == r.to_bits() || (q.is_nan() && r.is_nan()), "{a} / {b}");
                if !a.is_nan() && !b.is_nan() {
                    assert_eq!(lane(x.min(y)), one(s.min(t)), "min({a}, {b})");
                    assert_eq!(lane(x.max(y)), one(s.max(t)), "max({a}, {b})");
                }
                assert_eq!(x.lt(y) >> k & 1, s.lt(t) & 1, "{a} < {b}");
                assert_eq!(x.le(y) >> k & 1, s.le(t) & 1, "{a} <= {b}");
                assert_eq!(x.eq(y) >> k & 1, s.eq(t) & 1, "{a} == {b}");
            }
            assert_eq!(bits(y.abs().to_array().as_ref()), bits(&b.map(f32::abs)[..L::WIDTH]));
            assert_eq!(x.lt(y) >> L::WIDTH, 0, "no bits past the lanes");
            // Masked stores: the mask's lanes written, every other slot kept.
            for mask in [0u32, 1, 0b1010_0101_1100_0011, u32::MAX] {
                let mask = mask & lane_bits;
                let (mut out, mut ids) = ([7.0f32; 16], [9u32; 16]);
                y.store_where(mask, &mut out);
                L::fill_where(mask, 3, &mut ids);
                for k in 0..16 {
                    let on = mask >> k & 1 == 1;
                    assert_eq!(
                        out[k].to_bits(),
                        if on { b[k] } else { 7.0 }.to_bits(),
                        "store, lane {k}, mask {mask:b}"
                    );
                    assert_eq!(ids[k], if on { 3 } else { 9 }, "fill, lane {k}, mask {mask:b}");
                }
            }
        }
        triangles_in_lanes::<L>();
    }

    /// Triangles into lanes: every float moved bit for bit, lanes past
    /// the blocks given repeating the last block, for every block count.
    fn triangles_in_lanes<L: Lanes>() {
        let float = |k: usize, row: usize| match (k + row) % 5 {
            0 => VALUES[(k + 3 * row) % 8],
            _ => (100 * k + row) as f32 + 0.25,
        };
        let blocks: Vec<TriangleBlock> = (0..L::WIDTH.div_ceil(4))
            .map(|b| TriangleBlock {
                rows: std::array::from_fn(|row| std::array::from_fn(|k| float(4 * b + k, row))),
                ids: [0; 4],
            })
            .collect();
        for len in 1..=blocks.len() {
            let lanes = L::triangle_lanes(&blocks[..len]);
            for (v, vector) in lanes.iter().enumerate() {
                for (a, axis) in vector.iter().enumerate() {
                    for k in 0..L::WIDTH {
                        let block = (k / 4).min(len - 1);
                        let want = float(4 * block + k % 4, 3 * v + a);
                        assert_eq!(
                            axis.to_array()[k].to_bits(),
                            want.to_bits(),
                            "{len} blocks: lane {k}, vector {v}, axis {a}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn portable_lanes_take_triangles_as_they_are_stored() {
        triangles_in_lanes::<Scalar4>();
    }

    #[test]
    fn native_lanes_compute_what_scalar_lanes_compute() {
        same_as_scalar::<NativeLanes>();
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx_lanes_compute_what_scalar_lanes_compute() {
        if !has_avx() {
            eprintln!("skipped: this processor has no AVX");
            return;
        }
        #[target_feature(enable = "avx")]
        unsafe fn check() {
            same_as_scalar::<Avx8>();
        }
        // SAFETY: the processor has AVX (checked above).
        unsafe { check() }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx512_lanes_compute_what_scalar_lanes_compute() {
        if !has_avx512() {
            eprintln!("skipped: this processor has no AVX-512");
            return;
        }
        #[target_feature(enable = "avx512f")]
        unsafe fn check() {
            same_as_scalar::<Avx16>();
        }
        // SAFETY: the processor has AVX-512F (checked above).
        unsafe { check() }
    }
}
