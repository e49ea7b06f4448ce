//! Phase functions, normalised over the sphere.

use std::f32::consts::PI;

/// The isotropic phase function, 1/4π.
pub const fn isotropic() -> f32 {
    1.0 / (4.0 * PI)
}

/// Henyey–Greenstein as pbrt-v4 writes it (DESIGN.md):
/// p = (1 − g²) / (4π (1 + g² + 2g cos θ)^1.5), with cos θ between the two
/// directions both pointing away from the scattering point, so g > 0 favours
/// light continuing forward (cos θ = −1).
#[inline]
pub fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    if g == 0.0 {
        return isotropic();
    }
    let denom = 1.0 + g * g + 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denom * denom.max(1e-12).sqrt())
}
