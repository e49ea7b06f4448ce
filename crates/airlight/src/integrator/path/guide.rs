//! New directions drawn toward a point light as well as by the phase
//! function or BRDF.
//!
//! After a scattering event in fog, the next segment gathers the light of
//! each point light by equiangular sampling (nee.rs), whose estimate along
//! a line that passes the light at distance h grows as 1/h. Drawn by the
//! phase function or BRDF, such lines come within h of the light with a
//! chance ∝ h², so the estimate's second moment, ∫ h⁻² d(h²), diverges:
//! rare, bright pixels (fireflies) that never average out. So where that
//! can happen, the new direction is drawn, with chance
//! [`GUIDE_PROBABILITY`], at an angle uniform in [0, π/2] from the
//! direction to the light brightest at the vertex
//! ([`crate::sampling::angle_uniform`], density ∝ 1/α ∝ 1/h near it), and
//! else as before; the path is weighted by the mixture's density (Veach's
//! one-sample model, "Robust Monte Carlo Methods for Light Transport
//! Simulation", 1997, §9.2.4), and so is next-event estimation's balance
//! heuristic against area lights, which must know the density with which
//! the direction could have been drawn. Russian roulette then waits until
//! the new segment has gathered its light (mod.rs): the small weight of a
//! direction drawn close to the axis offsets that segment's large
//! estimate, and roulette on it would undo the offset.

use crate::sampling::angle_uniform_pdf;
use crate::scene::Scene;
use glam::Vec3;

/// The chance of drawing a new direction toward the light; the phase
/// function or BRDF draws the rest. Where the light does not matter, the
/// path's weight (phase or BRDF × cosine over the mixture's density) is
/// then at most 1/(1 − this) times what their sampling alone gives.
pub(super) const GUIDE_PROBABILITY: f32 = 0.5;

/// The unit direction from `p` to the point or spot light of the largest
/// intensity / distance² at `p` (a choice fixed by `p`, so that the
/// mixture's density is a function of the direction alone); None without
/// one.
pub(super) fn guide_axis(scene: &Scene, p: Vec3) -> Option<Vec3> {
    let mut best: Option<(f32, Vec3)> = None;
    for light in scene.lights() {
        let Some((position, 0.0)) = light.anchor().filter(|_| light.is_delta()) else { continue };
        let to = position - p;
        let distance_squared = to.length_squared();
        if distance_squared.is_nan() || distance_squared <= 0.0 {
            continue;
        }
        let score = light.intensity().max_element() / distance_squared;
        if best.is_none_or(|(s, _)| score > s) {
            best = Some((score, to / distance_squared.sqrt()));
        }
    }
    best.map(|(_, axis)| axis)
}

/// The density of the mixture at `wi`: `base`, the phase function's or
/// BRDF's own, alone without a guide.
#[inline]
pub(super) fn mixed_pdf(base: f32, guide: Option<Vec3>, wi: Vec3) -> f32 {
    match guide {
        Some(axis) => (1.0 - GUIDE_PROBABILITY) * base + GUIDE_PROBABILITY * angle_uniform_pdf(axis, wi),
        None => base,
    }
}
