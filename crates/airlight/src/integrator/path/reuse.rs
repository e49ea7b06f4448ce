//! Path reuse: the paths of a batch's neighbouring pixels share what they
//! gathered beyond their second vertex (Bekaert, Sbert and Halton,
//! "Accelerating Path Tracing by Re-Using Paths", EGWR 2002).
//!
//! Each path of a group of [`GROUP`] from one batch (neighbouring pixels,
//! the same sample number) draws a direction at its first surface vertex
//! x₁ and meets a second vertex x₂. Where x₂ is Lambertian, the light the
//! rest of the path gathers there, R (next-event estimation at x₂ and all
//! that follows, without x₂'s own emission), is the same toward any point
//! on the same side of x₂'s surface. So every pixel i of the group can
//! use every such x₂,k: it adds
//!
//!   f_i(x₁,i → x₂,k)·G(x₁,i, x₂,k)·V·R_k / Σ_j p_j(x₂,k)
//!
//! with G = |cos θ₁|·|cos θ₂|/d², and p_j(x₂,k) the density (per unit area)
//! with which path j's direction sampling would have met x₂,k: its BRDF
//! sampling pdf toward x₂,k times |cos θ₂|/d², where x₁,j sees x₂,k from
//! the side x₁,k saw it from, else 0. That is the balance heuristic over
//! the group's directions as techniques (Veach 1997), so every pixel's
//! estimate stays unbiased, and a path alone (a group of one) gets back its
//! own f·cos/pdf·R. The price is a shadow ray for each pair of a first
//! vertex and another path's second one. Light gathered at x₁ and x₂'s
//! emission (weighted against next-event estimation at x₁) stay the path's
//! own, as does all of a path whose second vertex is not Lambertian.
//!
//! Only in vacuum: in a medium the segment x₁x₂ scatters and attenuates,
//! and its hero-channel weights differ from path to path.

use crate::Rgb;
use crate::geometry::offset_origin;
use crate::material::Material;
use crate::scene::Scene;
use glam::Vec3;

/// How many consecutive paths of a batch share their second vertices: a
/// 4×2 rectangle of pixels where the batch is a block in Morton order.
/// Each path costs GROUP − 1 shadow rays more. On the Cornell box with
/// adaptive sampling (128 spp, 8 seeds, relative variance × time), groups
/// of 4, 8 and 16 gave 0.00042 × 2.13 s, 0.00029 × 2.46 s and 0.00023 ×
/// 2.93 s, against 0.00099 × 1.83 s without sharing.
pub(super) const GROUP: usize = 8;

/// What a path tells its group (filled in by `PathTracer::trace`).
#[derive(Clone, Default)]
pub(crate) struct Split {
    /// The first surface vertex, where the path drew a new direction and
    /// went on with a nonzero weight: a technique of the group.
    pub first: Option<FirstVertex>,
    /// The second vertex, if Lambertian, and the light the path gathered
    /// up to and including that vertex's emission; the trace then returns
    /// R, what it gathered after (as if its weight there were 1).
    pub second: Option<SecondVertex>,
}

#[derive(Clone)]
pub(crate) struct FirstVertex {
    pub p: Vec3,
    pub n: Vec3,
    /// The normal it is shaded with, when not `n`.
    pub shading: Option<Vec3>,
    pub wo: Vec3,
    pub material: Material,
}

#[derive(Clone, Copy)]
pub(crate) struct SecondVertex {
    pub p: Vec3,
    pub n: Vec3,
    pub own: Rgb,
}

/// Whether the light leaving a surface of this material is the same toward
/// every point on one side of it (so that a second vertex can be shared).
pub(super) fn lambertian(material: &Material) -> bool {
    matches!(material, Material::Diffuse { .. } | Material::Checker { .. })
}

/// The group's pixel values: `traced[i]` is what path i's trace returned
/// (R where its second vertex is shared, else its whole estimate).
pub(super) fn share(scene: &Scene, splits: &[Split], traced: &[Rgb], out: &mut [Rgb]) {
    debug_assert!(splits.len() <= GROUP && splits.len() == traced.len() && splits.len() == out.len());
    for ((out, split), traced) in out.iter_mut().zip(splits).zip(traced) {
        *out = split.second.map_or(*traced, |second| second.own);
    }
    for (k, split) in splits.iter().enumerate() {
        let Some(second) = split.second else { continue };
        let reflected = traced[k];
        if reflected == Rgb::ZERO {
            continue;
        }
        let Some(own_first) = &split.first else { continue };
        let side = (own_first.p - second.p).dot(second.n);
        // Per technique j: the BRDF value toward x₂,k times |cos θ₁|·G's
        // other factors, and the density; zero where j cannot meet x₂,k.
        let mut reached = [(Rgb::ZERO, 0.0f32); GROUP];
        let mut total_density = 0.0;
        for (j, other) in splits.iter().enumerate() {
            let Some(first) = &other.first else { continue };
            let to = second.p - first.p;
            let distance2 = to.length_squared();
            if (first.p - second.p).dot(second.n) * side <= 0.0 || distance2 <= 0.0 {
                continue;
            }
            let distance = distance2.sqrt();
            let dir = to / distance;
            let (f, pdf) = first.material.eval_at(first.p, first.n, first.shading, first.wo, dir);
            if pdf <= 0.0 {
                continue;
            }
            let visible = j == k || scene.light_visible(first.p, offset_origin(first.p, first.n, dir), dir, distance);
            if !visible {
                continue;
            }
            let cos_second = second.n.dot(dir).abs() / distance2;
            reached[j] = (f * (first.n.dot(dir).abs() * cos_second), pdf * cos_second);
            total_density += pdf * cos_second;
        }
        if total_density <= 0.0 {
            continue;
        }
        for (out, (f_g, density)) in out.iter_mut().zip(reached) {
            if density > 0.0 {
                *out += f_g * reflected / total_density;
            }
        }
    }
}
