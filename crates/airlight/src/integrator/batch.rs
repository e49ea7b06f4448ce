//! Direct light for many rays at once: the camera rays traced as
//! packets, then every shadow ray of every sample traced as packets too
//! (grouped by light, so that a packet's rays run toward one light), then
//! each sample's light summed in the order [`super::surface_radiance`] sums it, so
//! that each sample's radiance is the one-ray answer, bit for bit.

use crate::Rgb;
use crate::geometry::{Hit, Ray, Segment, SurfaceHit, offset_origin};
use crate::medium::Medium;
use crate::sampling::{Sampler, keyed2};
use crate::scene::{Scene, light_numbers};
use glam::Vec3;

/// A light's contribution to one sample, counted if its shadow ray is clear.
struct Candidate {
    sample: usize,
    light: usize,
    contribution: Rgb,
    /// None: no shadow ray is traced and the light counts as hidden.
    segment: Option<Segment>,
    /// The shadow ray's lifted origin and direction and the light's
    /// distance, for the medium's transmittance.
    origin: Vec3,
    wi: Vec3,
    distance: f32,
}

/// Buffers that [`surface_radiance_batch`] reuses from call to call.
#[derive(Default)]
pub struct ShadowScratch {
    candidates: Vec<Candidate>,
    order: Vec<usize>,
    segments: Vec<Segment>,
    blocked_sorted: Vec<bool>,
    blocked: Vec<bool>,
}

/// `out[i]` = what [`super::first_surface`] gives for `rays[i]` without a
/// medium and with no extra term: the first surface's emission and direct
/// light, or the background.
pub fn first_surface_batch(scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb]) {
    assert!(rays.len() == samplers.len() && rays.len() == out.len(), "one sampler and one answer per ray");
    let geometry = scene.geometry();
    let mut hits: Vec<Option<Hit>> = vec![None; rays.len()];
    geometry.intersect_packet(rays, f32::INFINITY, &mut hits);
    let surfaces: Vec<Option<SurfaceHit>> =
        rays.iter().zip(&hits).map(|(ray, hit)| hit.map(|hit| geometry.surface(ray, hit))).collect();
    surface_radiance_batch(scene, rays, &surfaces, samplers, None, &mut ShadowScratch::default(), out);
    for (k, s) in surfaces.iter().enumerate() {
        match s {
            // `first_surface` adds its extra term, zero here; adding it
            // keeps the bits (−0 + 0 is +0).
            Some(_) => out[k] += Rgb::ZERO,
            None => out[k] = scene.settings().background,
        }
    }
}

/// `out[i]` = [`super::surface_radiance`] of `rays[i]` at `surfaces[i]`
/// with `samplers[i]` and `medium`, bit for bit, for every i with a
/// surface (the others are left as they are): each surface's light sampled
/// as there, then every shadow ray traced in packets (grouped by light, so
/// that a packet's rays run toward one light), then each sample's light
/// summed in the one-ray order.
pub fn surface_radiance_batch(
    scene: &Scene,
    rays: &[Ray],
    surfaces: &[Option<SurfaceHit>],
    samplers: &mut [Sampler],
    medium: Option<&Medium>,
    scratch: &mut ShadowScratch,
    out: &mut [Rgb],
) {
    assert!(
        rays.len() == surfaces.len() && rays.len() == samplers.len() && rays.len() == out.len(),
        "one surface, sampler and answer per ray"
    );
    let ShadowScratch { candidates, order, segments, blocked_sorted, blocked } = scratch;
    candidates.clear();
    for (k, ((ray, surface), sampler)) in rays.iter().zip(surfaces).zip(samplers.iter_mut()).enumerate() {
        let Some(surface) = surface else { continue };
        // What `surface_radiance` computes, with its shadow rays put off.
        let wo = -ray.dir;
        out[k] = match surface.emitter {
            Some(light) => scene.lights()[light as usize].emitted(surface.n, ray.dir),
            None => Rgb::ZERO,
        };
        let material = scene.material_at(surface);
        let key = sampler.next_key();
        scene.for_each_light_at(surface.p, |index, _| {
            let u = light_numbers(keyed2(key, index as u64));
            let Some(sample) = scene.sample_light(index, surface.p, u) else { return };
            let cos = sample.wi.dot(surface.n).abs();
            if cos == 0.0 {
                return;
            }
            let f = material.brdf(surface.p, surface.n, wo, sample.wi);
            if f == Rgb::ZERO {
                return;
            }
            let origin = offset_origin(surface.p, surface.n, sample.wi);
            candidates.push(Candidate {
                sample: k,
                light: index,
                contribution: f * sample.weight * cos,
                segment: scene.light_segment(surface.p, origin, sample.wi, sample.distance),
                origin,
                wi: sample.wi,
                distance: sample.distance,
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
    scene.geometry().occluded_packet(segments, blocked_sorted);
    blocked.clear();
    blocked.extend(candidates.iter().map(|c| c.segment.is_none()));
    for (&c, &b) in order.iter().zip(blocked_sorted.iter()) {
        blocked[c] = b;
    }
    // Each sample's lights in index order, as `surface_radiance` adds them.
    for (c, candidate) in candidates.iter().enumerate() {
        if !blocked[c] {
            let mut contribution = candidate.contribution;
            if let Some(m) = medium {
                let length = scene.light_distance(candidate.distance);
                contribution *= m.transmittance(candidate.origin, candidate.wi, 0.0, length);
            }
            out[candidate.sample] += contribution;
        }
    }
}
