//! Owen-scrambled, shuffled Sobol' points in four dimensions, after Burley,
//! "Practical Hash-based Owen Scrambling" (JCGT 9(4), 2020).
//!
//! The Sobol' sequence (Sobol' 1967) in base 2: point n's coordinate in a
//! dimension is the XOR of the direction numbers vₖ for the set bits k of n.
//! Dimension 0 has vₖ = 2^(31−k) (the van der Corput sequence); the others
//! come from the primitive polynomials and initial numbers of Joe and Kuo,
//! "Constructing Sobol sequences with better two-dimensional projections"
//! (SIAM J. Sci. Comput. 30, 2008): x + 1 (m = 1); x² + x + 1 (m = 1, 3);
//! x³ + x + 1 (m = 1, 3, 1), by the recurrence
//! vₖ = vₖ₋ₛ ⊕ (vₖ₋ₛ ≫ s) ⊕ ⨁ⱼ aⱼ·vₖ₋ⱼ (Bratley and Fox, Algorithm 659).
//!
//! Each coordinate is then Owen scrambled (a random nested uniform
//! permutation of the binary digits, which keeps the points stratified and
//! makes each one uniformly distributed), and the index is scrambled the same
//! way first, which shuffles the order of the points so that independent
//! groups of four dimensions, each with its own seed, do not correlate
//! (Burley's "padding"). The nested scramble uses Laine and Karras's
//! hash, x += seed; x ^= x·c for four even constants c (each step changes a bit
//! only from the bits below it), applied to the bit-reversed value.

/// Direction numbers of the four dimensions.
const DIRECTIONS: [[u32; 32]; 4] =
    [directions(0, 0, &[]), directions(1, 0, &[1]), directions(2, 1, &[1, 3]), directions(3, 1, &[1, 3, 1])];

/// vₖ for k = 1..32 (stored from index 0) of the polynomial of degree s
/// with inner coefficients `a` (bit j − 1 from the top is aⱼ) and initial
/// odd numbers mₖ < 2ᵏ; s = 0 gives the van der Corput dimension.
const fn directions(s: usize, a: u32, m: &[u32]) -> [u32; 32] {
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        v[k] = if s == 0 {
            1 << (31 - k)
        } else if k < s {
            m[k] << (31 - k)
        } else {
            let mut x = v[k - s] ^ (v[k - s] >> s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    x ^= v[k - j];
                }
                j += 1;
            }
            x
        };
        k += 1;
    }
    v
}

/// Coordinate `dim` (0..4) of Sobol' point `index`, as 32 fixed-point bits.
#[inline]
pub fn sobol(index: u32, dim: usize) -> u32 {
    sobol4(index)[dim]
}

/// All four coordinates of Sobol' point `index`. Branch-free (a mask per
/// bit), since shuffled indices have random bits that defeat prediction;
/// dimension 0 is the bit reversal of the index.
#[inline]
fn sobol4(index: u32) -> [u32; 4] {
    let mut x = [index.reverse_bits(), 0, 0, 0];
    let bits = 32 - index.leading_zeros() as usize;
    let columns = DIRECTIONS[1].iter().zip(&DIRECTIONS[2]).zip(&DIRECTIONS[3]).take(bits);
    for (k, ((v1, v2), v3)) in columns.enumerate() {
        let mask = 0u32.wrapping_sub((index >> k) & 1);
        x[1] ^= v1 & mask;
        x[2] ^= v2 & mask;
        x[3] ^= v3 & mask;
    }
    x
}

/// Laine and Karras's permutation: each output bit depends only on the
/// input bits below it (and the seed).
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// A nested uniform (Owen) scramble of the binary fraction x: each bit is
/// flipped or not depending only on the bits above it.
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// A seed for dimension `i` of a group with seed `seed` (a 32-bit mix).
#[inline]
fn dimension_seed(seed: u32, i: u32) -> u32 {
    let mut h = seed ^ i.wrapping_mul(0x9e37_79b9).wrapping_add(0x7f4a_7c15);
    h = (h ^ (h >> 16)).wrapping_mul(0x7feb_352d);
    h = (h ^ (h >> 15)).wrapping_mul(0x846c_a68b);
    h ^ (h >> 16)
}

/// The bit-reversed direction numbers of the four dimensions as nibble
/// tables, the four dimensions side by side: entry [j][v][d] is the XOR of
/// dimension d's reversed vₖ over the set bits b of v, k = 4j + b. A
/// point's four coordinates are then eight reads of four lanes instead of
/// a step per index bit; bit-reversed, because the Owen scramble works on
/// the reversed value (dimension 0's reversed vₖ is 2ᵏ, so its lane gives
/// the index back).
const NIBBLES: [[[u32; 4]; 16]; 8] = nibble_tables();

const fn nibble_tables() -> [[[u32; 4]; 16]; 8] {
    let mut t = [[[0u32; 4]; 16]; 8];
    let mut j = 0;
    while j < 8 {
        let mut v = 0;
        while v < 16 {
            let mut d = 0;
            while d < 4 {
                let mut x = 0u32;
                let mut b = 0;
                while b < 4 {
                    if (v >> b) & 1 == 1 {
                        x ^= DIRECTIONS[d][4 * j + b].reverse_bits();
                    }
                    b += 1;
                }
                t[j][v][d] = x;
                d += 1;
            }
            v += 1;
        }
        j += 1;
    }
    t
}

/// Point `index` of the shuffled, Owen-scrambled 4D Sobol' sequence with
/// this seed, each coordinate in [0, 1): the same numbers as scrambling
/// [`sobol`]'s coordinates of the scrambled index with [`owen_scramble`],
/// computed with the coordinates kept bit-reversed until the end (the
/// reversed Sobol' point of a scrambled index is its dimension-0 value
/// itself), which halves the bit reversals. Written lane by lane over the
/// four dimensions, so that the compiler does them in one vector.
pub fn scrambled_sobol4(index: u32, seed: u32) -> [f32; 4] {
    let shuffled = owen_scramble(index, seed);
    let mut reversed = [0u32; 4];
    for (j, table) in NIBBLES.iter().enumerate() {
        let row = &table[((shuffled >> (4 * j)) & 15) as usize];
        for d in 0..4 {
            reversed[d] ^= row[d];
        }
    }
    let mut out = [0.0; 4];
    for d in 0..4 {
        let x = laine_karras(reversed[d], dimension_seed(seed, d as u32)).reverse_bits();
        // The top 24 bits: exact in an f32, strictly below 1.
        out[d] = (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_dimension_has_the_known_direction_numbers() {
        // x + 1 with m₁ = 1: vₖ = vₖ₋₁ ⊕ (vₖ₋₁ ≫ 1), the Pascal triangle mod 2.
        assert_eq!(&DIRECTIONS[1][..5], &[0x8000_0000, 0xc000_0000, 0xa000_0000, 0xf000_0000, 0x8800_0000]);
        // Dimension 2 (x² + x + 1, m = 1, 3), by hand: v₁ = 0.1₂, v₂ = 0.11₂,
        // v₃ = v₁ ⊕ v₁/4 ⊕ v₂ = 0.011₂; points n = 0..5 in index order.
        let first: Vec<f64> = (0..6).map(|i| sobol(i, 2) as f64 / 2f64.powi(32)).collect();
        assert_eq!(first, [0.0, 0.5, 0.75, 0.25, 0.375, 0.875]);
    }

    /// Whether the first 2^m values fall one in each interval [k/2^m, (k+1)/2^m).
    fn stratified_1d(values: &[u32], m: u32) -> bool {
        let mut seen = vec![false; 1 << m];
        values.iter().all(|&v| !std::mem::replace(&mut seen[(v >> (32 - m)) as usize], true))
    }

    #[test]
    fn every_dimension_stays_stratified_after_scrambling() {
        for seed in [0u32, 1, 0xdead_beef] {
            for m in 1..=10 {
                for d in 0..4 {
                    let raw: Vec<u32> = (0..1u32 << m).map(|i| sobol(i, d)).collect();
                    assert!(stratified_1d(&raw, m), "raw dim {d} m {m}");
                    let shuffled: Vec<u32> = (0..1u32 << m)
                        .map(|i| owen_scramble(sobol(owen_scramble(i, seed), d), dimension_seed(seed, d as u32)))
                        .collect();
                    assert!(stratified_1d(&shuffled, m), "scrambled dim {d} m {m} seed {seed}");
                }
            }
        }
    }

    #[test]
    fn first_two_dimensions_form_a_0_m_2_net() {
        // Every elementary interval of area 2^−m, [a/2^i, (a+1)/2^i) ×
        // [b/2^j, (b+1)/2^j) with i + j = m, holds exactly one of the first 2^m points.
        let seed = 12345;
        for m in 2..=8u32 {
            let pts: Vec<(u32, u32)> = (0..1u32 << m)
                .map(|i| {
                    let s = owen_scramble(i, seed);
                    let x = owen_scramble(sobol(s, 0), dimension_seed(seed, 0));
                    let y = owen_scramble(sobol(s, 1), dimension_seed(seed, 1));
                    (x, y)
                })
                .collect();
            for i in 0..=m {
                let j = m - i;
                let mut count = vec![0u32; 1 << m];
                for &(x, y) in &pts {
                    let a = if i == 0 { 0 } else { x >> (32 - i) };
                    let b = if j == 0 { 0 } else { y >> (32 - j) };
                    count[((a << j) | b) as usize] += 1;
                }
                assert!(count.iter().all(|&c| c == 1), "m {m} split {i}+{j}");
            }
        }
    }

    #[test]
    fn table_form_gives_the_scrambled_points_bit_for_bit() {
        // The direct form: scramble the index, take its Sobol' point,
        // scramble each coordinate.
        for seed in [0u32, 7, 0xdead_beef] {
            for index in (0..4096u32).chain([u32::MAX, 0x8000_0000, 0x1234_5678]) {
                let s = owen_scramble(index, seed);
                let direct: Vec<f32> = (0..4)
                    .map(|d| {
                        let x = owen_scramble(sobol(s, d), dimension_seed(seed, d as u32));
                        (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
                    })
                    .collect();
                assert_eq!(scrambled_sobol4(index, seed).to_vec(), direct, "index {index} seed {seed}");
            }
        }
    }

    #[test]
    fn scrambled_points_are_uniform_on_average() {
        // Owen scrambling makes each point uniform: over many seeds, point 5's
        // coordinates have mean 1/2 and variance 1/12.
        let n = 20_000;
        for d in 0..4 {
            let xs: Vec<f64> = (0..n).map(|s| scrambled_sobol4(5, dimension_seed(s, 99))[d] as f64).collect();
            let mean = xs.iter().sum::<f64>() / n as f64;
            let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
            assert!((mean - 0.5).abs() < 0.01 && (var - 1.0 / 12.0).abs() < 0.005, "dim {d}: {mean} {var}");
        }
    }
}
