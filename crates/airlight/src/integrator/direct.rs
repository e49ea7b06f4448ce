use super::{Integrator, first_surface, first_surface_batch, no_extra};
use crate::Rgb;
use crate::geometry::Ray;
use crate::sampling::Sampler;
use crate::scene::Scene;

/// Direct illumination of surfaces with shadows; any medium is ignored.
pub struct Direct;

impl Integrator for Direct {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        first_surface(scene, ray, sampler, None, no_extra).0
    }

    fn radiance_batch(&self, scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb]) {
        first_surface_batch(scene, rays, samplers, out)
    }

    /// Four blocks: only the lit hits trace a shadow ray (about 42 of a
    /// block's 64 camera rays on the 1.1 M-triangle mesh), so a batch of
    /// one block filled two thirds of a packet, and four fill most. The
    /// batch's work took 4.2% fewer instructions so (callgrind, the mesh
    /// at 1 spp, part of it the packets' stack zeroing since removed); in
    /// time the gain was within the machine's noise.
    fn batch_blocks(&self) -> usize {
        4
    }
}
