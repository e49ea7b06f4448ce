//! The density along a line in closed form, and the inverse of its
//! integral: what exact free-flight sampling needs.
//!
//! Along o + t·d the height fog's density e^{−k (y − base)} is
//! ρ(t) = ρ0·e^{−a t} with ρ0 = ρ(0) and a = k·d.y; the homogeneous medium
//! is the case ρ0 = 1, a = 0. Its integral from 0 is
//!
//!   X(t) = ∫0^t ρ = ρ0 (1 − e^{−a t}) / a   (→ ρ0 t as a → 0),
//!
//! and the optical depth in a channel is τ(t) = σt·X(t). A free flight in a
//! medium whose collision rate is σt·ρ(t) ends where τ reaches an
//! exponential variate E, since P(no collision before t) = e^{−τ(t)}
//! ("closed-form tracking": Novák, Georgiev, Hanika and Jarosz, "Monte
//! Carlo Methods for Volumetric Light Transport Simulation", Computer
//! Graphics Forum 2018), so t = X⁻¹(E/σt), with
//!
//!   X⁻¹(x) = −ln(1 − a x/ρ0) / a,
//!
//! finite only if a x/ρ0 < 1: heading up (a > 0) the whole line holds the
//! finite depth X(∞) = ρ0/a, and a flight drawn beyond it never collides.
//!
//! Everything is in f64 and in logarithms of ρ where ρ may overflow: below
//! the base the density grows without bound (e^{0.8·900} overflows f64),
//! and far above it underflows to 0.

/// ρ(t) = e^{ln_rho0 − a·t} along a line (module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DensityProfile {
    /// ln ρ(0): finite even where ρ(0) itself would overflow.
    pub ln_rho0: f64,
    /// The density's logarithmic rate of decrease along the line, k·d.y.
    pub a: f64,
}

impl DensityProfile {
    /// ρ(t).
    #[inline]
    pub fn density(&self, t: f64) -> f64 {
        if self.is_unit() {
            return 1.0;
        }
        (self.ln_rho0 - self.a * t).exp()
    }

    /// Whether ρ = 1 all along (a homogeneous medium): the exp and ln
    /// below are then skipped, as the free flights of the path tracer ask
    /// for them at every collision.
    #[inline]
    fn is_unit(&self) -> bool {
        self.a == 0.0 && self.ln_rho0 == 0.0
    }

    /// ∫_{t0}^{t1} ρ dt (0 for an empty or reversed interval; t1 may be
    /// infinite). Evaluated from the denser end, ρ_max (1 − e^{−|a| L})/|a|
    /// with L = t1 − t0, so that the bracket (by expm1) stays in [0, L] and
    /// only a truly overflowing integral overflows; a·L → 0 gives ρ·L.
    pub fn integral(&self, t0: f64, t1: f64) -> f64 {
        let length = t1 - t0;
        if length.is_nan() || length <= 0.0 {
            return 0.0;
        }
        if self.is_unit() {
            return length;
        }
        let x = self.a.abs() * length;
        if length.is_infinite() {
            // Heading down (or level) the integral diverges; heading up it
            // is ρ(t0)/a.
            return if self.a > 0.0 { (self.ln_rho0 - self.a * t0 - self.a.ln()).exp() } else { f64::INFINITY };
        }
        let ln_rho_max = self.ln_rho0 - self.a * if self.a > 0.0 { t0 } else { t1 };
        if x == 0.0 {
            return ln_rho_max.exp() * length;
        }
        ln_rho_max.exp() * (-(-x).exp_m1() / self.a.abs())
    }

    /// X⁻¹(x): the t ≥ 0 with ∫0^t ρ = x, infinite if the whole line holds
    /// less than x (module notes). x ≤ 0 gives 0.
    pub fn distance_to(&self, x: f64) -> f64 {
        if x.is_nan() || x <= 0.0 {
            return 0.0;
        }
        if self.is_unit() {
            return x;
        }
        // ln q, q = x/ρ0: the distance at the starting density.
        let ln_q = x.ln() - self.ln_rho0;
        if self.a == 0.0 {
            return ln_q.exp();
        }
        let ln_z = self.a.abs().ln() + ln_q;
        if self.a > 0.0 {
            // t = −ln(1 − z)/a, z = a q: finite only for z < 1.
            if ln_z >= 0.0 {
                return f64::INFINITY;
            }
            -(-ln_z.exp()).ln_1p() / self.a
        } else {
            // t = ln(1 + z)/|a|; for large z, ln z + ln(1 + 1/z) with the
            // last term below 1e-16 relative.
            let log = if ln_z > 36.0 { ln_z } else { ln_z.exp().ln_1p() };
            log / -self.a
        }
    }
}
