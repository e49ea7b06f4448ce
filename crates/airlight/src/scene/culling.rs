//! Which lights reach a point: lights with a finite range sit in a BVH of
//! their spheres of influence, so a point pays only for those near it.

use crate::light::Light;
use glam::{Vec3, Vec3A};
use obvhs::{Boundable, BvhBuildParams, aabb::Aabb, bvh2::Bvh2};
use std::time::Duration;

/// The lights of a scene split into those that reach everywhere and those
/// with a range, the latter under a BVH.
#[derive(Default)]
pub struct LightCulling {
    /// Indices of lights that reach everywhere.
    unbounded: Vec<u32>,
    /// (light index, centre, reach from centre) of lights with a range, in
    /// the BVH's primitive order.
    bounded: Vec<(u32, Vec3, f32)>,
    bvh: Option<Bvh2>,
}

impl std::fmt::Debug for LightCulling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LightCulling")
            .field("unbounded", &self.unbounded.len())
            .field("bounded", &self.bounded.len())
            .finish()
    }
}

struct Reach(Vec3, f32);

impl Boundable for Reach {
    fn aabb(&self) -> Aabb {
        Aabb::new(Vec3A::from(self.0 - self.1), Vec3A::from(self.0 + self.1))
    }
}

impl LightCulling {
    /// The culling of lights `candidates` (indices into `lights`, in
    /// increasing order): the scene passes its emitters' first lights, so
    /// that an emitting mesh's triangles are not each walked per point.
    pub fn new(lights: &[Light], candidates: &[u32]) -> Self {
        let mut unbounded = Vec::new();
        let mut bounded = Vec::new();
        for &i in candidates {
            match lights[i as usize].reach() {
                Some((center, reach)) => bounded.push((i, center, reach)),
                None => unbounded.push(i),
            }
        }
        if bounded.is_empty() {
            return LightCulling { unbounded, bounded, bvh: None };
        }
        let reaches: Vec<Reach> = bounded.iter().map(|&(_, c, r)| Reach(c, r)).collect();
        let bvh = obvhs::bvh2::builder::build_bvh2(&reaches, BvhBuildParams::fast_build(), &mut Duration::default());
        let bounded = bvh.primitive_indices.iter().map(|&i| bounded[i as usize]).collect();
        LightCulling { unbounded, bounded, bvh: Some(bvh) }
    }

    /// Whether any light has a finite range.
    pub fn has_ranges(&self) -> bool {
        self.bvh.is_some()
    }

    /// Indices of the lights that may reach `p`, in increasing order (so sums
    /// over them add in the same order as over all lights).
    pub fn lights_at(&self, p: Vec3, out: &mut Vec<u32>) {
        out.clear();
        out.extend_from_slice(&self.unbounded);
        if let Some(bvh) = &self.bvh {
            bvh.point_traverse(Vec3A::from(p), |bvh, node| {
                let node = &bvh.nodes[node as usize];
                for i in node.first_index..node.first_index + node.prim_count {
                    let (light, center, reach) = self.bounded[i as usize];
                    if (p - center).length_squared() < reach * reach {
                        out.push(light);
                    }
                }
                true
            });
            out.sort_unstable();
        }
    }
}
