//! Several f32 lanes and the arithmetic the packet traversal (`packet.rs`)
//! does on them, written once over the [`Lanes`] trait and given by four
//! types: [`Scalar4`], a loop over four floats (any target, and the tests);
//! `Sse4`, four lanes in an SSE register (the x86-64 baseline); `Avx8`,
//! eight lanes in an AVX register, and `Avx16`, sixteen in an AVX-512
//! register, for processors that have them (found at run time). Every
//! operation is a single IEEE operation per lane (no fused multiply-add),
//! so the four give the same bits.

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

    /// Triangles' stored (v0, e1, e2) in lanes, lane k from `group[k]`, and
    /// the lanes past the group's end repeating its last triangle (whose
    /// answers the caller drops): 1 to `WIDTH` triangles. The vector types
    /// transpose in registers; filling an array and loading it as vectors
    /// waited on store forwarding (a tenth of a ray's time across the
    /// inside of a mesh).
    #[inline(always)]
    fn triangles(group: &[[glam::Vec3; 3]]) -> [[Self; 3]; 3] {
        let mut rows = [[0.0f32; 16]; 9];
        for k in 0..Self::WIDTH {
            let triangle = &group[k.min(group.len() - 1)];
            for (v, vector) in triangle.iter().enumerate() {
                rows[3 * v][k] = vector.x;
                rows[3 * v + 1][k] = vector.y;
                rows[3 * v + 2][k] = vector.z;
            }
        }
        std::array::from_fn(|v| std::array::from_fn(|a| Self::load(&rows[3 * v + a])))
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
mod x86 {
    use super::Lanes;
    use std::arch::x86_64::*;

    /// Where triangle k of the group (its last for k past the end) starts:
    /// nine f32s, the x, y, z of v0, e1 and e2. Loads of four at 0, 4 and 5
    /// stay within them.
    #[inline(always)]
    fn triangle_floats(group: &[[glam::Vec3; 3]], k: usize) -> *const f32 {
        const { assert!(std::mem::size_of::<[glam::Vec3; 3]>() == 36) };
        group[k.min(group.len() - 1)].as_ptr().cast::<f32>()
    }

    /// Four floats from `at` of each triangle.
    #[inline(always)]
    unsafe fn rows4(t: &[*const f32; 4], at: usize) -> [__m128; 4] {
        unsafe {
            [
                _mm_loadu_ps(t[0].add(at)),
                _mm_loadu_ps(t[1].add(at)),
                _mm_loadu_ps(t[2].add(at)),
                _mm_loadu_ps(t[3].add(at)),
            ]
        }
    }

    /// The 4×4 transpose: lane k of output j is lane j of input k.
    #[inline(always)]
    unsafe fn transpose4([r0, r1, r2, r3]: [__m128; 4]) -> [__m128; 4] {
        unsafe {
            let (t0, t1) = (_mm_unpacklo_ps(r0, r1), _mm_unpacklo_ps(r2, r3));
            let (t2, t3) = (_mm_unpackhi_ps(r0, r1), _mm_unpackhi_ps(r2, r3));
            [_mm_movelh_ps(t0, t1), _mm_movehl_ps(t1, t0), _mm_movelh_ps(t2, t3), _mm_movehl_ps(t3, t2)]
        }
    }

    /// Lane 3 of each input, in order.
    #[inline(always)]
    unsafe fn fourth4([r0, r1, r2, r3]: [__m128; 4]) -> __m128 {
        unsafe { _mm_movehl_ps(_mm_unpackhi_ps(r2, r3), _mm_unpackhi_ps(r0, r1)) }
    }

    /// Four floats from `at` of triangles k (low half) and k + 4 (high
    /// half), for k = 0..4.
    #[inline(always)]
    unsafe fn rows8(t: &[*const f32; 8], at: usize) -> [__m256; 4] {
        unsafe {
            [
                _mm256_loadu2_m128(t[4].add(at), t[0].add(at)),
                _mm256_loadu2_m128(t[5].add(at), t[1].add(at)),
                _mm256_loadu2_m128(t[6].add(at), t[2].add(at)),
                _mm256_loadu2_m128(t[7].add(at), t[3].add(at)),
            ]
        }
    }

    /// [`transpose4`] in each 128-bit half.
    #[inline(always)]
    unsafe fn transpose8([r0, r1, r2, r3]: [__m256; 4]) -> [__m256; 4] {
        unsafe {
            let (t0, t1) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpacklo_ps(r2, r3));
            let (t2, t3) = (_mm256_unpackhi_ps(r0, r1), _mm256_unpackhi_ps(r2, r3));
            [
                _mm256_shuffle_ps::<0b01_00_01_00>(t0, t1),
                _mm256_shuffle_ps::<0b11_10_11_10>(t0, t1),
                _mm256_shuffle_ps::<0b01_00_01_00>(t2, t3),
                _mm256_shuffle_ps::<0b11_10_11_10>(t2, t3),
            ]
        }
    }

    /// [`fourth4`] in each 128-bit half.
    #[inline(always)]
    unsafe fn fourth8([r0, r1, r2, r3]: [__m256; 4]) -> __m256 {
        unsafe { _mm256_shuffle_ps::<0b11_10_11_10>(_mm256_unpackhi_ps(r0, r1), _mm256_unpackhi_ps(r2, r3)) }
    }

    /// Four lanes in an SSE register.
    #[derive(Clone, Copy, Debug)]
    pub struct Sse4(__m128);

    // SAFETY (every function below): SSE and SSE2 are part of the x86-64
    // baseline; `load` reads four f32s from a slice of at least four (the
    // indexing checks it) with an unaligned load.
    impl Lanes for Sse4 {
        const WIDTH: usize = 4;
        type Four = Sse4;
        type Array = [f32; 4];
        #[inline(always)]
        fn triangles(group: &[[glam::Vec3; 3]]) -> [[Self; 3]; 3] {
            let t = [
                triangle_floats(group, 0),
                triangle_floats(group, 1),
                triangle_floats(group, 2),
                triangle_floats(group, 3),
            ];
            // SAFETY: SSE is part of the x86-64 baseline; each load reads
            // four of a triangle's nine floats (`triangle_floats`).
            unsafe {
                let [v0x, v0y, v0z, e1x] = transpose4(rows4(&t, 0));
                let [e1y, e1z, e2x, e2y] = transpose4(rows4(&t, 4));
                let e2z = fourth4(rows4(&t, 5));
                [
                    [Sse4(v0x), Sse4(v0y), Sse4(v0z)],
                    [Sse4(e1x), Sse4(e1y), Sse4(e1z)],
                    [Sse4(e2x), Sse4(e2y), Sse4(e2z)],
                ]
            }
        }
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { Sse4(_mm_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(s: &[f32]) -> Self {
            let s = &s[..4];
            unsafe { Sse4(_mm_loadu_ps(s.as_ptr())) }
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 4] {
            let mut out = [0.0; 4];
            unsafe { _mm_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { Sse4(_mm_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { Sse4(_mm_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { Sse4(_mm_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            unsafe { Sse4(_mm_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            unsafe { Sse4(_mm_min_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { Sse4(_mm_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { Sse4(_mm_and_ps(self.0, _mm_castsi128_ps(_mm_set1_epi32(i32::MAX)))) }
        }
        #[inline(always)]
        fn flip_sign(self, sign_of: Self) -> Self {
            unsafe { Sse4(_mm_xor_ps(self.0, _mm_and_ps(sign_of.0, _mm_set1_ps(-0.0)))) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> u32 {
            unsafe { _mm_movemask_ps(_mm_cmplt_ps(self.0, o.0)) as u32 }
        }
        #[inline(always)]
        fn le(self, o: Self) -> u32 {
            unsafe { _mm_movemask_ps(_mm_cmple_ps(self.0, o.0)) as u32 }
        }
        #[inline(always)]
        fn eq(self, o: Self) -> u32 {
            unsafe { _mm_movemask_ps(_mm_cmpeq_ps(self.0, o.0)) as u32 }
        }
    }

    /// Whether this processor has AVX (checked once, then cached by std).
    #[inline]
    pub fn has_avx() -> bool {
        std::arch::is_x86_feature_detected!("avx")
    }

    /// Eight lanes in an AVX register. Only code compiled with AVX enabled
    /// (`#[target_feature(enable = "avx")]`, entered after [`has_avx`]) may
    /// use it: its operations are inlined there; elsewhere they would be
    /// calls to instructions the processor may lack.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx8(__m256);

    // SAFETY (every function below): an `Avx8` is only made and used in
    // functions that run after `has_avx()` said yes (the type's contract);
    // `load` reads eight f32s from a slice of at least eight (the indexing
    // checks it) with an unaligned load. The comparisons are the ordered,
    // quiet predicates: false with a NaN, as SSE's `cmplt`/`cmple`/`cmpeq`.
    impl Lanes for Avx8 {
        const WIDTH: usize = 8;
        type Four = Sse4;
        type Array = [f32; 8];
        #[inline(always)]
        fn triangles(group: &[[glam::Vec3; 3]]) -> [[Self; 3]; 3] {
            // No closures here: a closure is compiled without the AVX of the
            // function it is inlined into.
            let t = [
                triangle_floats(group, 0),
                triangle_floats(group, 1),
                triangle_floats(group, 2),
                triangle_floats(group, 3),
                triangle_floats(group, 4),
                triangle_floats(group, 5),
                triangle_floats(group, 6),
                triangle_floats(group, 7),
            ];
            // SAFETY: as for every `Avx8` function; each load reads four of a
            // triangle's nine floats (`triangle_floats`).
            unsafe {
                let [v0x, v0y, v0z, e1x] = transpose8(rows8(&t, 0));
                let [e1y, e1z, e2x, e2y] = transpose8(rows8(&t, 4));
                let e2z = fourth8(rows8(&t, 5));
                [
                    [Avx8(v0x), Avx8(v0y), Avx8(v0z)],
                    [Avx8(e1x), Avx8(e1y), Avx8(e1z)],
                    [Avx8(e2x), Avx8(e2y), Avx8(e2z)],
                ]
            }
        }
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { Avx8(_mm256_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(s: &[f32]) -> Self {
            let s = &s[..8];
            unsafe { Avx8(_mm256_loadu_ps(s.as_ptr())) }
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 8] {
            let mut out = [0.0; 8];
            unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { Avx8(_mm256_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { Avx8(_mm256_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { Avx8(_mm256_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            unsafe { Avx8(_mm256_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            unsafe { Avx8(_mm256_min_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { Avx8(_mm256_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { Avx8(_mm256_and_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX)))) }
        }
        #[inline(always)]
        fn flip_sign(self, sign_of: Self) -> Self {
            unsafe { Avx8(_mm256_xor_ps(self.0, _mm256_and_ps(sign_of.0, _mm256_set1_ps(-0.0)))) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0)) as u32 }
        }
        #[inline(always)]
        fn le(self, o: Self) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)) as u32 }
        }
        #[inline(always)]
        fn eq(self, o: Self) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0)) as u32 }
        }
    }

    /// Whether this processor has AVX-512's foundation (checked once, then
    /// cached by std).
    #[inline]
    pub fn has_avx512() -> bool {
        std::arch::is_x86_feature_detected!("avx512f")
    }

    /// Sixteen lanes in an AVX-512 register. As with [`Avx8`], only code
    /// compiled with the feature enabled (`#[target_feature(enable =
    /// "avx512f")]`, entered after [`has_avx512`]) may use it.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx16(__m512);

    // SAFETY (every function below): an `Avx16` is only made and used in
    // functions that run after `has_avx512()` said yes (the type's
    // contract); `load` reads sixteen f32s from a slice of at least sixteen
    // (the indexing checks it) with an unaligned load. The comparisons are
    // the ordered, quiet predicates, as [`Avx8`]'s, and give their mask
    // register's bits directly.
    impl Lanes for Avx16 {
        const WIDTH: usize = 16;
        type Four = Sse4;
        type Array = [f32; 16];
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { Avx16(_mm512_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(s: &[f32]) -> Self {
            let s = &s[..16];
            unsafe { Avx16(_mm512_loadu_ps(s.as_ptr())) }
        }
        #[inline(always)]
        fn to_array(self) -> [f32; 16] {
            let mut out = [0.0; 16];
            unsafe { _mm512_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            unsafe { Avx16(_mm512_add_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            unsafe { Avx16(_mm512_sub_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            unsafe { Avx16(_mm512_mul_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            unsafe { Avx16(_mm512_div_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            unsafe { Avx16(_mm512_min_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            unsafe { Avx16(_mm512_max_ps(self.0, o.0)) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { Avx16(_mm512_abs_ps(self.0)) }
        }
        #[inline(always)]
        fn flip_sign(self, sign_of: Self) -> Self {
            // Bitwise operations on floats need AVX-512DQ; on integers, only F.
            unsafe {
                let sign = _mm512_and_epi32(_mm512_castps_si512(sign_of.0), _mm512_set1_epi32(i32::MIN));
                Avx16(_mm512_castsi512_ps(_mm512_xor_epi32(_mm512_castps_si512(self.0), sign)))
            }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> u32 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, o.0) as u32 }
        }
        #[inline(always)]
        fn le(self, o: Self) -> u32 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, o.0) as u32 }
        }
        #[inline(always)]
        fn eq(self, o: Self) -> u32 {
            unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(self.0, o.0) as u32 }
        }
        // Masked stores: one instruction, where the default spills the lanes
        // and writes them back one by one. The slices are checked to hold
        // sixteen; masked-off lanes are neither read nor written.
        #[inline(always)]
        fn store_where(self, mask: u32, out: &mut [f32]) {
            let out = &mut out[..16];
            unsafe { _mm512_mask_storeu_ps(out.as_mut_ptr(), mask as u16, self.0) }
        }
        #[inline(always)]
        fn fill_where(mask: u32, value: u32, out: &mut [u32]) {
            let out = &mut out[..16];
            unsafe { _mm512_mask_storeu_epi32(out.as_mut_ptr().cast(), mask as u16, _mm512_set1_epi32(value as i32)) }
        }
    }
}

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
        // Triangles into lanes: every float moved bit for bit, lanes past a
        // group's end repeating its last triangle, for every group size.
        let float = |k: usize, v: usize, a: usize| match (k + v + a) % 5 {
            0 => VALUES[(k + 3 * v + a) % 8],
            _ => (100 * k + 10 * v + a) as f32 + 0.25,
        };
        let all: Vec<[glam::Vec3; 3]> = (0..L::WIDTH)
            .map(|k| std::array::from_fn(|v| glam::Vec3::new(float(k, v, 0), float(k, v, 1), float(k, v, 2))))
            .collect();
        for len in 1..=L::WIDTH {
            let lanes = L::triangles(&all[..len]);
            for (v, vector) in lanes.iter().enumerate() {
                for (a, axis) in vector.iter().enumerate() {
                    for k in 0..L::WIDTH {
                        let want = float(k.min(len - 1), v, a);
                        assert_eq!(
                            axis.to_array()[k].to_bits(),
                            want.to_bits(),
                            "{len} triangles: lane {k}, vector {v}, axis {a}"
                        );
                    }
                }
            }
        }
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
