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
//! direction to one of the (up to four) lights brightest at the vertex,
//! chosen with a chance ∝ intensity / distance² there
//! ([`crate::sampling::angle_uniform`], density ∝ 1/α ∝ 1/h near it), and
//! else as before; the path is weighted by the mixture's density (Veach's
//! one-sample model, "Robust Monte Carlo Methods for Light Transport
//! Simulation", 1997, §9.2.4), and so is next-event estimation's power
//! heuristic against area lights, which must know the density with which
//! the direction could have been drawn. Russian roulette then waits until
//! the new segment has gathered its light (mod.rs): the small weight of a
//! direction drawn close to the axis offsets that segment's large
//! estimate, and roulette on it would undo the offset.

use crate::sampling::{angle_uniform, angle_uniform_pdf};
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// The chance of drawing a new direction toward a light; the phase
/// function or BRDF draws the rest. Where the lights do not matter, the
/// path's weight (phase or BRDF × cosine over the mixture's density) is
/// then at most 1/(1 − this) times what their sampling alone gives.
pub(super) const GUIDE_PROBABILITY: f32 = 0.5;

/// How many lights a vertex may draw its new direction toward.
const GUIDED_LIGHTS: usize = 4;

/// The lights a vertex's new direction may be drawn toward: the point or
/// spot lights of largest intensity / distance² there (up to
/// [`GUIDED_LIGHTS`]), each with a chance ∝ that. Both are fixed by the
/// vertex, so that the density is a function of the direction alone.
#[derive(Clone, Copy, Debug)]
pub(super) struct Guide {
    /// Unit directions from the vertex to the lights, brightest first.
    axes: [Vec3; GUIDED_LIGHTS],
    /// The chance of each; they sum to 1 over the first `count`.
    chances: [f32; GUIDED_LIGHTS],
    count: usize,
}

impl Guide {
    /// The guide at `p`; None without a point or spot light.
    pub(super) fn at(scene: &Scene, p: Vec3) -> Option<Guide> {
        let mut guide = Guide { axes: [Vec3::ZERO; GUIDED_LIGHTS], chances: [0.0; GUIDED_LIGHTS], count: 0 };
        for &index in scene.placed_delta_lights() {
            let light = &scene.lights()[index as usize];
            // Point and spot lights: a line light's light is not ∝ 1/h.
            let Some((position, 0.0)) = light.anchor() else { continue };
            let to = position - p;
            let distance_squared = to.length_squared();
            let score = light.intensity().max_element() / distance_squared;
            if !(score > 0.0 && score.is_finite()) {
                continue;
            }
            // Insert by score, the brightest first, keeping the first few.
            let mut k = guide.count.min(GUIDED_LIGHTS - 1);
            if guide.count == GUIDED_LIGHTS && score <= guide.chances[k] {
                continue;
            }
            while k > 0 && guide.chances[k - 1] < score {
                guide.chances[k] = guide.chances[k - 1];
                guide.axes[k] = guide.axes[k - 1];
                k -= 1;
            }
            guide.chances[k] = score;
            guide.axes[k] = to / distance_squared.sqrt();
            guide.count = (guide.count + 1).min(GUIDED_LIGHTS);
        }
        if guide.count == 0 {
            return None;
        }
        let total: f32 = guide.chances[..guide.count].iter().sum();
        for chance in &mut guide.chances[..guide.count] {
            *chance /= total;
        }
        Some(guide)
    }

    /// A direction toward one of the lights, chosen by `choice` in [0, 1),
    /// drawn from `u` ([`angle_uniform`]).
    pub(super) fn sample(&self, choice: f32, u: Vec2) -> Vec3 {
        let mut k = 0;
        let mut below = self.chances[0];
        while k + 1 < self.count && choice >= below {
            k += 1;
            below += self.chances[k];
        }
        angle_uniform(u, self.axes[k])
    }

    /// The density of [`Guide::sample`]'s directions at `wi`.
    pub(super) fn pdf(&self, wi: Vec3) -> f32 {
        (0..self.count).map(|k| self.chances[k] * angle_uniform_pdf(self.axes[k], wi)).sum()
    }
}

/// The density of the mixture at `wi`: `base`, the phase function's or
/// BRDF's own, alone without a guide.
#[inline]
pub(super) fn mixed_pdf(base: f32, guide: Option<&Guide>, wi: Vec3) -> f32 {
    match guide {
        Some(guide) => (1.0 - GUIDE_PROBABILITY) * base + GUIDE_PROBABILITY * guide.pdf(wi),
        None => base,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Light;
    use crate::sampling::Sampler;
    use crate::{Rgb, SceneBuilder};
    use glam::vec3;

    #[test]
    fn a_guide_keeps_the_brightest_lights_and_its_samples_match_its_density() {
        // Six point lights seen from the origin, I/d² = 8, 1, 6, 0.5, 4, 2
        // (a sphere light and a sun, not delta points, are left out).
        let mut builder = SceneBuilder::new()
            .light(Light::sphere(vec3(0.0, 0.0, 3.0), 0.5, Rgb::ONE))
            .light(Light::distant(vec3(0.0, -1.0, 0.0), Rgb::ONE));
        for (at, score) in [
            (vec3(1.0, 0.0, 0.0), 8.0),
            (vec3(0.0, 2.0, 0.0), 1.0),
            (vec3(0.0, 0.0, -1.0), 6.0),
            (vec3(-2.0, 0.0, 0.0), 0.5),
            (vec3(0.0, -1.0, 1.0), 4.0),
            (vec3(1.0, 1.0, 1.0), 2.0),
        ] {
            let intensity = score * at.length_squared();
            builder = builder.light(Light::point(at, Rgb::splat(intensity)));
        }
        let scene = builder.build().unwrap();
        let guide = Guide::at(&scene, Vec3::ZERO).unwrap();
        assert_eq!(guide.count, 4);
        let expected = [
            (vec3(1.0, 0.0, 0.0), 8.0),
            (vec3(0.0, 0.0, -1.0), 6.0),
            (vec3(0.0, -1.0, 1.0), 4.0),
            (vec3(1.0, 1.0, 1.0), 2.0),
        ];
        for (k, (at, score)) in expected.iter().enumerate() {
            assert!((guide.axes[k] - at.normalize()).length() < 1e-6, "axis {k}: {}", guide.axes[k]);
            assert!((guide.chances[k] - score / 20.0).abs() < 1e-6, "chance {k}: {}", guide.chances[k]);
        }
        // E[g/pdf] over the guide's samples = ∫ g dω for g = max(0, cos)²
        // about the first axis (2π/3), where every direction with g > 0
        // has a positive density: the chances, the choice of light and the
        // summed density agree.
        let mut s = Sampler::for_pixel(11, 0, 0);
        let n = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let wi = guide.sample(s.next(), s.next2());
            let pdf = guide.pdf(wi);
            if pdf > 0.0 && pdf.is_finite() {
                sum += (wi.dot(guide.axes[0]).max(0.0) as f64).powi(2) / pdf as f64;
            }
        }
        let estimate = sum / n as f64;
        let expected = 2.0 * std::f64::consts::PI / 3.0;
        assert!((estimate - expected).abs() < 0.02 * expected, "{estimate} against {expected}");
    }
}
