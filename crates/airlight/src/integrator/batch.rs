//! Direct light for many camera rays at once: the camera rays traced as
//! packets, then every shadow ray of every sample traced as packets too
//! (grouped by light, so that a packet's rays run toward one light), then
//! each sample's light summed in the order [`super::surface_radiance`] sums it, so
//! that each sample's radiance is the one-ray answer, bit for bit.

use crate::Rgb;
use crate::geometry::{Hit, Ray, Segment, offset_origin};
use crate::sampling::Sampler;
use crate::scene::Scene;

/// A light's contribution to one sample, counted if its shadow ray is clear.
struct Candidate {
    sample: usize,
    light: usize,
    contribution: Rgb,
    /// None: no shadow ray is traced and the light counts as hidden.
    segment: Option<Segment>,
}

/// `out[i]` = what [`super::first_surface`] gives for `rays[i]` without a
/// medium and with no extra term: the first surface's emission and direct
/// light, or the background.
pub fn first_surface_batch(scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb]) {
    assert!(rays.len() == samplers.len() && rays.len() == out.len(), "one sampler and one answer per ray");
    let geometry = scene.geometry();
    let mut hits: Vec<Option<Hit>> = vec![None; rays.len()];
    geometry.intersect_packet(rays, f32::INFINITY, &mut hits);
    let mut candidates = Vec::with_capacity(rays.len());
    for (k, ((ray, hit), sampler)) in rays.iter().zip(&hits).zip(samplers.iter_mut()).enumerate() {
        let Some(hit) = *hit else {
            out[k] = scene.settings().background;
            continue;
        };
        let surface = geometry.surface(ray, hit);
        // What `surface_radiance` computes, with its shadow rays put off.
        out[k] = super::emitted(scene, ray, &surface);
        super::for_each_light_term(scene, ray, &surface, sampler, |index, sample, contribution| {
            let origin = offset_origin(surface.p, surface.n, sample.wi);
            candidates.push(Candidate {
                sample: k,
                light: index,
                contribution,
                segment: scene.light_segment(surface.p, origin, sample.wi, sample.distance),
            });
        });
    }
    // Shadow rays toward one light after another, each light's in the
    // samples' order (neighbouring pixels).
    let mut order: Vec<usize> = (0..candidates.len()).filter(|&c| candidates[c].segment.is_some()).collect();
    order.sort_by_key(|&c| candidates[c].light);
    let segments: Vec<Segment> = order.iter().filter_map(|&c| candidates[c].segment).collect();
    let mut blocked_sorted = vec![false; segments.len()];
    geometry.occluded_packet(&segments, &mut blocked_sorted);
    let mut blocked: Vec<bool> = candidates.iter().map(|c| c.segment.is_none()).collect();
    for (&c, &b) in order.iter().zip(&blocked_sorted) {
        blocked[c] = b;
    }
    // Each sample's lights in index order, as `surface_radiance` adds them.
    for (c, candidate) in candidates.iter().enumerate() {
        if !blocked[c] {
            out[candidate.sample] += candidate.contribution;
        }
    }
    for (k, hit) in hits.iter().enumerate() {
        if hit.is_some() {
            // `first_surface` adds its extra term, zero here; adding it
            // keeps the bits (−0 + 0 is +0).
            out[k] += Rgb::ZERO;
        }
    }
}
