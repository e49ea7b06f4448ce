//! The x86-64 lanes: four in an SSE register (the x86-64 baseline),
//! eight with AVX and sixteen with AVX-512 (each used only after the
//! processor is found to have it), and triangles loaded into them from
//! blocks of four.

use super::Lanes;
use crate::geometry::blocks::TriangleBlock;
use std::arch::x86_64::*;

/// Row `r` of a block in four lanes.
#[inline(always)]
fn row4(rows: &[[f32; 4]; 9], r: usize) -> Sse4 {
    // SAFETY: a row is four f32s, 16-byte aligned (a block is 32-byte
    // aligned and a row 16 bytes); SSE is part of the x86-64 baseline.
    unsafe { Sse4(_mm_load_ps(rows[r].as_ptr())) }
}

/// Row `r` of two blocks in eight lanes, the first block's in the low
/// half.
///
/// # Safety
/// The processor must have AVX (the contract of every [`Avx8`]).
#[inline(always)]
unsafe fn row8(low: &[[f32; 4]; 9], high: &[[f32; 4]; 9], r: usize) -> Avx8 {
    unsafe { Avx8(_mm256_loadu2_m128(high[r].as_ptr(), low[r].as_ptr())) }
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
    fn triangle_lanes(blocks: &[TriangleBlock]) -> [[Self; 3]; 3] {
        let r = &blocks[0].rows;
        [
            [row4(r, 0), row4(r, 1), row4(r, 2)],
            [row4(r, 3), row4(r, 4), row4(r, 5)],
            [row4(r, 6), row4(r, 7), row4(r, 8)],
        ]
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
    fn triangle_lanes(blocks: &[TriangleBlock]) -> [[Self; 3]; 3] {
        let low = &blocks[0].rows;
        let high = &blocks[blocks.len().min(2) - 1].rows;
        // SAFETY: as for every `Avx8` function; each row is four f32s.
        // No closure here: a closure is compiled without the AVX of the
        // function it is inlined into.
        unsafe {
            [
                [row8(low, high, 0), row8(low, high, 1), row8(low, high, 2)],
                [row8(low, high, 3), row8(low, high, 4), row8(low, high, 5)],
                [row8(low, high, 6), row8(low, high, 7), row8(low, high, 8)],
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
