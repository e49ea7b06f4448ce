//! Direct light for many camera rays at once: the camera rays traced as
//! packets, then every shadow ray of every sample traced as packets too
//! (grouped by light, so that a packet's rays run toward one light), then
//! each sample's light summed in the order [`super::surface_radiance`] sums it, so
//! that each sample's radiance is the one-ray answer, bit for bit.

use super::light_lanes::{Candidate, LaneScratch, LitPoint, light_terms};
use crate::Rgb;
use crate::geometry::{Hit, Ray, Segment, SurfaceHit};
use crate::medium::Medium;
use crate::sampling::Sampler;
use crate::scene::Scene;
use crate::scratch::with_scratch;
use glam::Vec3;
use std::cell::RefCell;

/// Direct light whose shadow rays are put off: the light terms of many
/// shading points are kept, then their shadow rays traced as packets
/// (grouped by light, so that a packet's rays run toward one light), then
/// each visible term added to its point's sum in the order
/// [`super::surface_radiance`] adds it: each point's light is the one-ray
/// answer, bit for bit.
#[derive(Default)]
pub(crate) struct DeferredShadows {
    points: Vec<LitPoint>,
    lanes: LaneScratch,
    candidates: Vec<Candidate>,
    order: Vec<usize>,
    segments: Vec<Segment>,
    blocked_sorted: Vec<bool>,
    blocked: Vec<bool>,
}

impl DeferredShadows {
    /// Forgets the kept points.
    pub fn clear(&mut self) {
        self.points.clear();
    }

    /// What [`super::surface_radiance`] gives at `surface` before its light
    /// terms (the surface's emission); the point is kept as sample
    /// `sample`'s, for [`DeferredShadows::resolve`] to add its terms. Draws
    /// from `sampler` as `surface_radiance` does.
    pub fn surface(
        &mut self,
        scene: &Scene,
        ray: &Ray,
        surface: &SurfaceHit,
        sampler: &mut Sampler,
        sample: usize,
    ) -> Rgb {
        // `for_each_light_term`'s one draw.
        let key = sampler.next_key();
        self.points.push(LitPoint { sample, surface: *surface, wo: -ray.dir, key });
        super::emitted(scene, ray, surface)
    }

    /// Finds the kept points' light terms (many at once: `light_lanes.rs`),
    /// traces their shadow rays through the scene's geometry and adds each
    /// visible term (through `medium`, if any, as `surface_radiance` does)
    /// to its sample's `out[sample]`.
    pub fn resolve(&mut self, scene: &Scene, medium: Option<&Medium>, out: &mut [Rgb]) {
        let DeferredShadows { points, lanes, candidates, order, segments, blocked_sorted, blocked } = self;
        candidates.clear();
        light_terms(scene, points, lanes, candidates);
        // Shadow rays toward one light after another, each light's in the
        // samples' order (neighbouring pixels).
        order.clear();
        order.extend((0..candidates.len()).filter(|&c| candidates[c].segment.is_some()));
        order.sort_by_key(|&c| candidates[c].light);
        // Field by field into place: a push of each whole segment went
        // through the stack, its load waiting on the stores before it.
        let none = Segment { origin: Vec3::ZERO, dir: Vec3::Z, tmax: 0.0 };
        segments.clear();
        segments.resize(order.len(), none);
        for (segment, &c) in segments.iter_mut().zip(order.iter()) {
            if let Some(s) = &candidates[c].segment {
                (segment.origin, segment.dir, segment.tmax) = (s.origin, s.dir, s.tmax);
            }
        }
        blocked_sorted.clear();
        blocked_sorted.resize(segments.len(), false);
        scene.geometry().occluded_packet(segments, blocked_sorted);
        blocked.clear();
        blocked.extend(candidates.iter().map(|c| c.segment.is_none()));
        for (&c, &b) in order.iter().zip(blocked_sorted.iter()) {
            blocked[c] = b;
        }
        // Each sample's lights in index order, as `surface_radiance` adds
        // them (the candidates hold them so, lights of other samples between).
        for (c, candidate) in candidates.iter().enumerate() {
            if blocked[c] {
                continue;
            }
            let mut contribution = candidate.contribution;
            if let Some(m) = medium {
                let (origin, wi) = (candidate.origin, candidate.wi);
                contribution *= m.transmittance(origin, wi, 0.0, scene.light_distance(candidate.distance));
            }
            out[candidate.sample] += contribution;
        }
    }
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
    shadows: DeferredShadows,
}

/// [`first_surface_batch`] in `scratch`'s buffers.
fn trace_batch(scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb], scratch: &mut Scratch) {
    let Scratch { hits, shadows } = scratch;
    let geometry = scene.geometry();
    hits.clear();
    hits.resize(rays.len(), None);
    geometry.intersect_packet(rays, f32::INFINITY, hits);
    shadows.clear();
    for (k, ((ray, hit), sampler)) in rays.iter().zip(hits.iter()).zip(samplers.iter_mut()).enumerate() {
        out[k] = match *hit {
            // What `surface_radiance` computes, with its shadow rays put off.
            Some(hit) => shadows.surface(scene, ray, &geometry.surface(ray, hit), sampler, k),
            None => scene.escaped_radiance(ray.dir),
        };
    }
    shadows.resolve(scene, None, out);
    for (k, hit) in hits.iter().enumerate() {
        if hit.is_some() {
            // `first_surface` adds its extra term, zero here; adding it
            // keeps the bits (−0 + 0 is +0).
            out[k] += Rgb::ZERO;
        }
    }
}
