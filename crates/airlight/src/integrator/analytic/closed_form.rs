//! The single-scatter airlight of a point light along a ray, in closed form.
//!
//! A ray o + t·d (d unit) passes a point light at P. Let h = d·(P − o) be the
//! parameter of the foot of the perpendicular from P to the ray's line and
//! p = |P − o − h·d| the light's distance from that line (Packard 2004,
//! "Efficient Rendering of Glowing Lights", Packard
//! 2004). With y = t − h, the distance to the
//! light is r(t) = √(p² + y²). For an isotropic light of intensity I in a
//! homogeneous medium the single-scattered radiance over t in [t₀, t₁] is
//!
//!   L = σs · phase · I · ∫_{t₀}^{t₁} e^{−σt (t + r(t))} / r(t)² dt.
//!
//! Without extinction (σt = 0 along the way, Packard's assumption) the
//! integral is Packard's atan form, [`glow_vacuum`]. With extinction it is
//! Sun, Ramamoorthi, Narasimhan and Nayar's (SIGGRAPH 2005) special function
//! F(u, v) = ∫₀^v e^{−u tan ξ} dξ, here evaluated exactly through the
//! complex exponential integral ([`Glow`], [`sun_f`]).

use super::expint::{Complex, scaled_e1};
use super::quadrature::gl8;
use super::table::im_s;
use glam::{DVec3, Vec3};

/// The relative floor on p: a light on or near the ray's line is treated as
/// lying at distance p_min = `P_FLOOR` · (|a| + |b|) from it (|a|, |b| the
/// ends' distances from the foot), so that [`glow_vacuum`] is at most
/// π / p_min, finite. It is far below f32's resolution of p for a scene in
/// f32 coordinates (about 6e-8 of the distances involved), so it changes no
/// value that f32 input can distinguish from a light exactly on the line.
pub const P_FLOOR: f64 = 1e-9;

/// Packard's a, b, p for a light at `light`, a ray from `origin` along the
/// unit vector `dir`, and the segment [0, t_end]: with the foot
/// Z = O + D (D·(P − O)), p = |P − Z|, and a, b the signed positions of the
/// segment's ends measured along the ray from Z: a = −D·(P − O) and
/// b = t_end − D·(P − O). Packard writes a = −|O − Z| and b = |O + T·D − Z|,
/// which are these values when the foot lies within the segment (a ≤ 0 ≤ b);
/// the signed form covers a foot before the origin or past the end as well.
pub fn seed_coordinates(light: DVec3, origin: DVec3, dir: DVec3, t_end: f64) -> (f64, f64, f64) {
    let to_light = light - origin;
    let h = dir.dot(to_light);
    let p = (to_light - dir * h).length();
    (-h, t_end - h, p)
}

/// ∫_a^b dy / (p² + y²) = (atan(b/p) − atan(a/p)) / p, Packard's closed
/// form (its sign convention reversed so that a < b gives a positive value),
/// evaluated as atan2(p (b − a), p² + a b) / p, which has no cancellation
/// when a and b are large and of one sign. For p → 0 with the foot outside
/// [a, b] this tends to the exact limit 1/a − 1/b; p is clamped below at
/// [`P_FLOOR`]·(|a| + |b|), so the value is at most π / (`P_FLOOR`·(|a| + |b|)).
/// Zero when b ≤ a.
pub fn glow_vacuum(p: f64, a: f64, b: f64) -> f64 {
    if b.partial_cmp(&a) != Some(std::cmp::Ordering::Greater) {
        return 0.0;
    }
    let p = p.max(P_FLOOR * (a.abs() + b.abs())).max(f64::MIN_POSITIVE.sqrt());
    (p * (b - a)).atan2(p * p + a * b) / p
}

/// [`glow_vacuum`] computed entirely in f32 from f32 inputs (light, origin,
/// unit direction, t_end), as a renderer working in f32 would: the tests
/// state its error against the f64 form.
pub fn glow_vacuum_f32(light: Vec3, origin: Vec3, dir: Vec3, t_end: f32) -> f32 {
    let to_light = light - origin;
    let h = dir.dot(to_light);
    let p = (to_light - dir * h).length();
    let (a, b) = (-h, t_end - h);
    if b <= a {
        return 0.0;
    }
    let p = p.max(1e-6 * (a.abs() + b.abs())).max(1e-18);
    (p * (b - a)).atan2(p * p + a * b) / p
}

/// y + √(p² + y²) without cancellation for y ≪ −p.
#[inline]
fn y_plus_r(p: f64, y: f64) -> f64 {
    let r = (p * p + y * y).sqrt();
    if y >= 0.0 { y + r } else { p * p / (r - y) }
}

/// The airlight integral with extinction, G(t₀, t₁) = ∫_{t₀}^{t₁} e^{−σt (t + r)} / r² dt,
/// r² = p² + (t − h)², for one extinction coefficient σt ≥ 0.
///
/// Derivation (after Sun et al. 2005, §3): substitute y = t − h = p tan θ, so
/// dt / r² = dθ / p, and then ξ = π/4 + θ/2, with which p tan ξ = y + r. So
///
///   G = (2/p) e^{−σt h} ∫_{ξ₀}^{ξ₁} e^{−u tan ξ} dξ = (2/p) e^{−σt h} [F(u, ξ₁) − F(u, ξ₀)],
///
/// u = σt p, Sun et al.'s F. With s = tan ξ and 1/(1 + s²) = Im 1/(s − i),
///
///   ∫ e^{−u s} / (1 + s²) ds = −Im[e^{−iu} E₁(u (s − i))] = −e^{−u s} Im S(u (s − i)),
///
/// S(z) = e^z E₁(z) ([`scaled_e1`]). Hence G = K(t₀) − K(t₁) with the
/// antiderivative
///
///   K(t) = (2/p) e^{−σt (t + r)} Im S(σt (y + r) − i σt p),
///
/// whose exponential never overflows (t + r ≥ 0 for t ≥ 0). For σt → 0,
/// Im S → −arg z = π/2 − ξ and K tends to Packard's atan form. When the
/// two values of K agree to 1e-3 (a short interval: the E₁ evaluation,
/// good to about 1e-13 of K, would lose digits to cancellation) the difference is
/// taken instead by 8-point Gauss–Legendre in θ over the piece, where the
/// integrand is nearly constant.
#[derive(Clone, Copy, Debug)]
pub struct Glow {
    pub sigma_t: f64,
    pub p: f64,
    pub h: f64,
}

impl Glow {
    /// The glow of a light at `light` along the ray `origin + t·dir` (dir
    /// unit); p is floored as in [`glow_vacuum`], with |a| + |b| replaced by
    /// the light's distance from the origin plus `length` (the longest span
    /// the caller will integrate).
    pub fn new(sigma_t: f64, light: DVec3, origin: DVec3, dir: DVec3, length: f64) -> Glow {
        let to_light = light - origin;
        let h = dir.dot(to_light);
        let p = (to_light - dir * h).length();
        let floor = P_FLOOR * (to_light.length() + length.abs());
        Glow { sigma_t, p: p.max(floor).max(f64::MIN_POSITIVE.sqrt()), h }
    }

    /// K(t), the antiderivative above (only for σt > 0).
    #[inline]
    pub fn antiderivative(&self, t: f64) -> f64 {
        let y = t - self.h;
        let w = y_plus_r(self.p, y);
        let z = Complex::new(self.sigma_t * w, -self.sigma_t * self.p);
        let s = scaled_e1(z);
        2.0 / self.p * (-self.sigma_t * (self.h + w)).exp() * s.im
    }

    /// K(t) with Im S read from the table ([`super::table::im_s`], relative
    /// error at most [`super::TABLE_ERROR`]): what the renderer uses.
    #[inline]
    pub fn antiderivative_tabulated(&self, t: f64) -> f64 {
        let y = t - self.h;
        let w = y_plus_r(self.p, y);
        let s = im_s(self.sigma_t * w, self.sigma_t * self.p);
        2.0 / self.p * (-self.sigma_t * (self.h + w)).exp() * s
    }

    /// G(t₀, t₁) given K(t₀) and K(t₁) (any values when σt = 0).
    #[inline]
    pub fn between_with(&self, t0: f64, t1: f64, k0: f64, k1: f64) -> f64 {
        if t1 <= t0 {
            return 0.0;
        }
        if self.sigma_t == 0.0 {
            return glow_vacuum(self.p, t0 - self.h, t1 - self.h);
        }
        let g = k0 - k1;
        if g > 1e-3 * k0.abs().max(k1.abs()) { g } else { self.quadrature(t0, t1) }
    }

    /// G(t₀, t₁).
    pub fn between(&self, t0: f64, t1: f64) -> f64 {
        if t1 <= t0 {
            return 0.0;
        }
        if self.sigma_t == 0.0 {
            return glow_vacuum(self.p, t0 - self.h, t1 - self.h);
        }
        self.between_with(t0, t1, self.antiderivative(t0), self.antiderivative(t1))
    }

    /// The transmittance factor e^{−σt (t + r)} at the point of angle θ.
    #[inline]
    pub fn attenuation_at_angle(&self, theta: f64) -> f64 {
        let y = self.p * theta.tan();
        (-self.sigma_t * (self.h + y_plus_r(self.p, y))).exp()
    }

    /// The angle θ = atan((t − h)/p) of the point at t, seen from the light
    /// relative to the perpendicular.
    #[inline]
    pub fn angle(&self, t: f64) -> f64 {
        (t - self.h).atan2(self.p)
    }

    /// The ray parameter of angle θ.
    #[inline]
    pub fn t_at_angle(&self, theta: f64) -> f64 {
        self.h + self.p * theta.tan()
    }

    /// G by 8-point Gauss–Legendre in θ for short pieces (see above):
    /// G = (1/p) ∫ e^{−σt (t + r)} dθ, with the width of the piece in θ
    /// taken as atan2(p (t₁ − t₀), p² + a b) (a, b = t − h at its ends), which
    /// keeps its digits however short the piece.
    fn quadrature(&self, t0: f64, t1: f64) -> f64 {
        let (a, b) = (t0 - self.h, t1 - self.h);
        let width = (self.p * (t1 - t0)).atan2(self.p * self.p + a * b);
        let start = self.angle(t0);
        let rule = gl8();
        let mut sum = 0.0;
        for (x, w) in rule.nodes.iter().zip(&rule.weights) {
            sum += w * self.attenuation_at_angle(start + width * x);
        }
        sum * width / self.p
    }
}

/// ∫_a^b e^{−σt (y + √(p² + y²))} / (p² + y²) dy: the airlight integral with
/// extinction in Packard's coordinates (the foot at y = 0; multiply by
/// e^{−σt h} for a foot at ray parameter h). See [`Glow`].
pub fn glow_extinction(sigma_t: f64, p: f64, a: f64, b: f64) -> f64 {
    let p = p.max(P_FLOOR * (a.abs() + b.abs())).max(f64::MIN_POSITIVE.sqrt());
    Glow { sigma_t, p, h: 0.0 }.between(a, b)
}

/// Sun et al.'s special function F(u, v) = ∫₀^v e^{−u tan ξ} dξ for u ≥ 0
/// and v in [0, π/2], exactly: F(u, v) = Im S(−iu) − e^{−u tan v} Im S(u (tan v − i))
/// (see [`Glow`]); F(0, v) = v.
pub fn sun_f(u: f64, v: f64) -> f64 {
    let v = v.clamp(0.0, std::f64::consts::FRAC_PI_2);
    if u == 0.0 || v == 0.0 {
        return v;
    }
    let at = |s: f64| {
        if s.is_infinite() { 0.0 } else { (-u * s).exp() * scaled_e1(Complex::new(u * s, -u)).im }
    };
    let s1 = if v >= std::f64::consts::FRAC_PI_2 { f64::INFINITY } else { v.tan() };
    at(0.0) - at(s1)
}
