//! Direct light for many camera rays at once: the camera rays traced as
//! packets, then every shadow ray of every sample traced as packets too
//! (grouped by light, so that a packet's rays run toward one light), then
//! each sample's light summed in the order [`super::surface_radiance`] sums it, so
//! that each sample's radiance is the one-ray answer, bit for bit.

use crate::Rgb;
use crate::geometry::{Hit, Ray, Segment, offset_origin};
use crate::sampling::Sampler;
use crate::scene::Scene;
use crate::scratch::with_scratch;
use std::cell::RefCell;

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
    thread_local! {
        static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
    }
    with_scratch(&SCRATCH, |scratch| trace_batch(scene, rays, samplers, out, scratch))
}

/// What [`first_surface_batch`] works in.
#[derive(Default)]
struct Scratch {
    hits: Vec<Option<Hit>>,
    candidates: Vec<Candidate>,
    order: Vec<usize>,
    segments: Vec<Segment>,
    blocked_sorted: Vec<bool>,
    blocked: Vec<bool>,
}

/// [`first_surface_batch`] in `scratch`'s buffers.
fn trace_batch(scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb], scratch: &mut Scratch) {
    let Scratch { hits, candidates, order, segments, blocked_sorted, blocked } = scratch;
    let geometry = scene.geometry();
    hits.clear();
    hits.resize(rays.len(), None);
    geometry.intersect_packet(rays, f32::INFINITY, hits);
    candidates.clear();
    for (k, ((ray, hit), sampler)) in rays.iter().zip(hits.iter()).zip(samplers.iter_mut()).enumerate() {
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
    order.clear();
    order.extend((0..candidates.len()).filter(|&c| candidates[c].segment.is_some()));
    order.sort_by_key(|&c| candidates[c].light);
    segments.clear();
    segments.extend(order.iter().filter_map(|&c| candidates[c].segment));
    blocked_sorted.clear();
    blocked_sorted.resize(segments.len(), false);
    geometry.occluded_packet(segments, blocked_sorted);
    blocked.clear();
    blocked.extend(candidates.iter().map(|c| c.segment.is_none()));
    for (&c, &b) in order.iter().zip(blocked_sorted.iter()) {
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
