//! A tabulated Im S(z), S(z) = e^z E₁(z), for the renderer's hot path.
//!
//! Sun, Ramamoorthi, Narasimhan and Nayar (SIGGRAPH 2005, §4) tabulate their
//! special function F(u, v) = ∫₀^v e^{−u tan ξ} dξ once in a 2D table and
//! interpolate it per pixel. The same idea is used here, on a better-behaved
//! function of two variables. With s = tan ξ, F's integrand is the Laplace
//! transform
//!
//!   H(u, s) = ∫₀^∞ e^{−u τ} / (1 + (s + τ)²) dτ = Im S(u s − i u),
//!
//! (so that F(u, v) = H(u, 0) − e^{−u tan v} H(u, tan v), see [`super::sun_f`])
//! and the airlight antiderivative is K(t) = (2/p) e^{−σt (t + r)} H(σt p, (y + r)/p)
//! ([`super::Glow`]). Tabulating F itself, as the paper does, loses the
//! relative accuracy of its differences where F is flat (ξ → π/2, which is
//! where most of a ray lies when the light is behind the camera); H keeps it,
//! because the exponential is factored out exactly.
//!
//! In polar form z = ρ e^{−iφ}, φ ∈ [0, π/2], Im S behaves as φ + O(ρ ln ρ)
//! for small ρ and as sin φ / ρ for large ρ (A&S 5.1.11 and 5.1.51), so the
//! table holds the smooth, O(1) quantity
//!
//!   N(τ, q) = Im S(z) · (1 + ρ) / τ,   τ = tan(φ/2) = u / (x + ρ),   q = ρ^{1/4},
//!
//! on a uniform grid in τ ∈ [0, 1] and q ∈ [0, 64^{1/4}], read by
//! tensor-product 4-point (cubic) Lagrange interpolation. Both coordinates
//! are algebraic in (x, u), so a look-up costs three square roots, two
//! divisions and 16 reads. q = ρ^{1/4} spreads the nodes toward small ρ, as
//! a logarithm would, while keeping ρ ln ρ = 4 q⁴ ln q smooth enough for
//! cubics (its fourth derivative grows only as ln q). At τ = 0 (real z) N is
//! the limit 2 (1 + ρ)(1 − ρ S(ρ)) (from S′(z) = S(z) − 1/z); at ρ = 0 it is
//! 2 atan(τ)/τ (Im S = φ). For ρ > 64, the asymptotic series
//! S(z) ~ Σ_k (−1)^k k! / z^{k+1} (A&S 5.1.51), truncated after 9 terms
//! (relative error below 9!/ρ⁹ ≈ 1e-11 at ρ = 64).
//!
//! Accuracy against the exact [`scaled_e1`] is tested below (and F against
//! [`super::sun_f`]): see `TABLE_ERROR`.

use super::expint::{Complex, scaled_e1};
use std::sync::OnceLock;

/// Grid nodes in τ = tan(φ/2) over [0, 1].
const NT: usize = 49;
/// Grid nodes in q = ρ^{1/4} over [0, Q_MAX].
const NQ: usize = 193;
/// ρ_max = Q_MAX⁴ = 64.
const Q_MAX: f64 = 2.828_427_124_746_190_3;
const RHO_MAX: f64 = 64.0;

/// The worst relative error of [`im_s`] against the exact Im S found by the
/// tests (random points over the quadrant, ρ from 1e-6 to 1e4): a bound the
/// tests enforce.
pub const TABLE_ERROR: f64 = 2e-7;

struct Table {
    values: Vec<f64>,
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut values = vec![0.0; NT * NQ];
        for j in 0..NQ {
            let rho = (Q_MAX * j as f64 / (NQ - 1) as f64).powi(4);
            for i in 0..NT {
                let tau = i as f64 / (NT - 1) as f64;
                values[j * NT + i] = if j == 0 {
                    // ρ = 0: Im S = φ = 2 atan τ.
                    if i == 0 { 2.0 } else { 2.0 * tau.atan() / tau }
                } else if i == 0 {
                    let s = scaled_e1(Complex::new(rho, 0.0)).re;
                    2.0 * (1.0 + rho) * (1.0 - rho * s)
                } else {
                    // z = ρ e^{−iφ}, with cos φ and sin φ from τ = tan(φ/2).
                    let d = 1.0 + tau * tau;
                    let (c, s) = ((1.0 - tau * tau) / d, 2.0 * tau / d);
                    scaled_e1(Complex::new(rho * c, -rho * s)).im * (1.0 + rho) / tau
                };
            }
        }
        Table { values }
    })
}

/// 4-point Lagrange weights for nodes −1, 0, 1, 2 at position f.
#[inline]
fn lagrange4(f: f64) -> [f64; 4] {
    let (fm1, fm2, fp1) = (f - 1.0, f - 2.0, f + 1.0);
    [-f * fm1 * fm2 / 6.0, fp1 * fm1 * fm2 / 2.0, -fp1 * f * fm2 / 2.0, fp1 * f * fm1 / 6.0]
}

/// The first node of the 4-point stencil around position `x` (in grid
/// units) on a grid of `n` nodes, and the position relative to the stencil's
/// second node.
#[inline]
fn stencil(x: f64, n: usize) -> (usize, f64) {
    // x ≥ 0, so truncation is the floor.
    let i = (x as usize).clamp(1, n - 3);
    (i - 1, x - i as f64)
}

/// Im S(x − i u) for x ≥ 0, u ≥ 0, not both 0: H(u, x/u) above, the
/// integrand factor of Sun et al.'s F. Tabulated (see the module
/// documentation); relative error at most [`TABLE_ERROR`].
#[inline]
pub fn im_s(x: f64, u: f64) -> f64 {
    let rho = (x * x + u * u).sqrt();
    if rho > RHO_MAX {
        return asymptotic_im_s(x, u, rho);
    }
    let q = rho.sqrt().sqrt();
    let tau = u / (x + rho);
    let t = table();
    let (i0, fi) = stencil(tau * (NT - 1) as f64, NT);
    let (j0, fj) = stencil(q * ((NQ - 1) as f64 / Q_MAX), NQ);
    let (wi, wj) = (lagrange4(fi), lagrange4(fj));
    let mut n = 0.0;
    for (b, wb) in wj.iter().enumerate() {
        let row = &t.values[(j0 + b) * NT + i0..(j0 + b) * NT + i0 + 4];
        n += wb * (wi[0] * row[0] + wi[1] * row[1] + wi[2] * row[2] + wi[3] * row[3]);
    }
    n * tau / (1.0 + rho)
}

/// Im S(z) for large |z| by S(z) ~ (1/z) Σ_{k=0}^{8} (−1)^k k! / z^k.
#[inline]
fn asymptotic_im_s(x: f64, u: f64, rho: f64) -> f64 {
    // w = 1/z = (x + i u) / ρ².
    let inv2 = 1.0 / (rho * rho);
    let (wr, wi) = (x * inv2, u * inv2);
    // Horner: s = 1 − 1·w(1 − 2w(1 − 3w(… (1 − 8w)))).
    let (mut sr, mut si) = (1.0, 0.0);
    for k in (1..=8).rev() {
        let (mr, mi) = (sr * wr - si * wi, sr * wi + si * wr);
        sr = 1.0 - k as f64 * mr;
        si = -(k as f64) * mi;
    }
    // Im(w · s).
    wr * si + wi * sr
}

/// F(u, v) = ∫₀^v e^{−u tan ξ} dξ (Sun et al. 2005) from the table:
/// F = H(u, 0) − e^{−u tan v} H(u, tan v). For the tests' statement of the
/// table's accuracy; the renderer uses [`im_s`] directly.
pub fn sun_f_tabulated(u: f64, v: f64) -> f64 {
    let v = v.clamp(0.0, std::f64::consts::FRAC_PI_2);
    if u == 0.0 || v == 0.0 {
        return v;
    }
    let top = if v >= std::f64::consts::FRAC_PI_2 {
        0.0
    } else {
        let s = v.tan();
        (-u * s).exp() * im_s(u * s, u)
    };
    im_s(0.0, u) - top
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::analytic::sun_f;

    /// SplitMix64 in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn tabulated_im_s_matches_the_exact_exponential_integral() {
        let mut state = 7;
        let mut worst = (0.0f64, 0.0, 0.0);
        for k in 0..200_000 {
            // ρ log-uniform over 1e-6 .. 1e4, φ uniform, and the two edges.
            let rho = 10f64.powf(-6.0 + 10.0 * uniform(&mut state));
            let phi = match k % 10 {
                0 => 0.0,
                1 => std::f64::consts::FRAC_PI_2,
                _ => std::f64::consts::FRAC_PI_2 * uniform(&mut state),
            };
            let (x, u) = (rho * phi.cos(), rho * phi.sin());
            let exact = scaled_e1(Complex::new(x, -u)).im;
            let got = im_s(x, u);
            let err = if exact == 0.0 { got.abs() } else { (got / exact - 1.0).abs() };
            if err > worst.0 {
                worst = (err, rho, phi);
            }
        }
        println!("tabulated Im S: worst relative error {:.2e} at ρ = {:.3e}, φ = {:.4}", worst.0, worst.1, worst.2);
        assert!(worst.0 <= TABLE_ERROR, "{worst:?}");
    }

    #[test]
    fn tabulated_sun_f_matches_the_exact_f() {
        // F on a grid of u and v, against the exact F through E₁ (itself
        // checked against numeric integration in tests/analytic_closed_form.rs).
        let mut worst = 0.0f64;
        for i in 0..=60 {
            let u = if i == 0 { 1e-7 } else { 10f64.powf(-5.0 + 7.0 * i as f64 / 60.0) };
            for j in 1..=64 {
                let v = std::f64::consts::FRAC_PI_2 * j as f64 / 64.0;
                let (exact, got) = (sun_f(u, v), sun_f_tabulated(u, v));
                worst = worst.max((got / exact - 1.0).abs());
            }
        }
        println!("tabulated F(u, v): worst relative error {worst:.2e}");
        assert!(worst <= 2.0 * TABLE_ERROR, "{worst}");
    }
}
