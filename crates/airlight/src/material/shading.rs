//! Shading normals: a surface shaded by a normal other than its triangle's
//! (interpolated vertex normals, normal maps), as Phong shading does.
//!
//! The material's lobes are evaluated about the shading normal n_s, and
//! the cosine the rendering equation weighs by is n_s·ωi; the integrators
//! multiply by the geometric cosine |n·ωi|, so the value given them is
//! f·|n_s·ωi|/|n·ωi|. Light still never passes through: ωo and ωi must lie
//! on one side of the geometric surface (the leak of a shading normal that
//! leans past a direction, Veach 1996, "Non-symmetric scattering in light
//! transport algorithms"). Where a shading normal leans so far from the
//! view that the view's mirror about it falls below the geometric surface,
//! the normal is bent back until that mirror lies just above it (Keller et
//! al. 2017, "The Iray light transport simulation and rendering system",
//! section 4.2): the view then always sees the shading normal's front, so
//! no black facets appear at grazing views, and light arriving below the
//! shading hemisphere fades with n_s·ωi to zero at the terminator instead
//! of stopping at the triangle's edge.

use super::{BsdfSample, Material};
use crate::Rgb;
use glam::{Vec2, Vec3};

/// How far above the geometric surface (as a cosine) a bent shading
/// normal keeps the view's mirror.
const LIFT: f32 = 0.01;

/// The shading normal `shading` turned to the side of the geometric
/// normal `n` that `wo` is on, and bent (see the module notes) so that the
/// mirror of `wo` about it lies at least [`LIFT`] above the surface.
pub fn bent_normal(n: Vec3, shading: Vec3, wo: Vec3) -> Vec3 {
    let n = if n.dot(wo) < 0.0 { -n } else { n };
    let ns = if shading.dot(n) < 0.0 { -shading } else { shading };
    let mirror = 2.0 * wo.dot(ns) * ns - wo;
    let height = n.dot(mirror);
    if height >= LIFT {
        return ns;
    }
    let lifted = (mirror + (LIFT - height) * n).normalize();
    (wo + lifted).try_normalize().unwrap_or(n)
}

impl Material {
    /// [`Material::eval`] at a point shaded by the normal `shading` (None:
    /// the geometric normal `n` itself, the same value to the bit): the
    /// BRDF times |n_s·ωi|/|n·ωi| (see the module notes), and the pdf of
    /// [`Material::sample_at`].
    #[inline]
    pub fn eval_at(&self, p: Vec3, n: Vec3, shading: Option<Vec3>, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let Some(shading) = shading else { return self.eval(p, n, wo, wi) };
        let ns = bent_normal(n, shading, wo);
        let (f, pdf) = self.eval(p, ns, wo, wi);
        let (co, ci) = (n.dot(wo), n.dot(wi));
        if co * ci <= 0.0 {
            return (Rgb::ZERO, pdf);
        }
        (f * (ns.dot(wi).abs() / ci.abs()), pdf)
    }

    /// [`Material::brdf`] at a point shaded by `shading` (see [`Material::eval_at`]).
    #[inline]
    pub fn brdf_at(&self, p: Vec3, n: Vec3, shading: Option<Vec3>, wo: Vec3, wi: Vec3) -> Rgb {
        match shading {
            None => self.brdf(p, n, wo, wi),
            Some(_) => self.eval_at(p, n, shading, wo, wi).0,
        }
    }

    /// [`Material::sample`] about the shading normal: a direction drawn
    /// about it that falls below the geometric surface is no direction.
    #[inline]
    pub fn sample_at(
        &self,
        p: Vec3,
        n: Vec3,
        shading: Option<Vec3>,
        wo: Vec3,
        u: Vec2,
        u_lobe: f32,
    ) -> Option<BsdfSample> {
        let Some(shading) = shading else { return self.sample(p, n, wo, u, u_lobe) };
        let ns = bent_normal(n, shading, wo);
        let s = self.sample(p, ns, wo, u, u_lobe)?;
        let (co, ci) = (n.dot(wo), n.dot(s.wi));
        if co * ci <= 0.0 {
            return None;
        }
        Some(BsdfSample { f: s.f * (ns.dot(s.wi).abs() / ci.abs()), ..s })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Sampler, uniform_sphere};

    #[test]
    fn a_bent_normal_faces_the_view_and_keeps_its_mirror_above_the_surface() {
        let mut s = Sampler::for_pixel(1, 1, 1);
        for _ in 0..10_000 {
            let (n, shading, wo) = (uniform_sphere(s.next2()), uniform_sphere(s.next2()), uniform_sphere(s.next2()));
            if n.dot(wo).abs() < 1e-3 {
                continue;
            }
            let ns = bent_normal(n, shading, wo);
            let facing = if n.dot(wo) < 0.0 { -n } else { n };
            assert!(ns.dot(wo) > 0.0 && (ns.length() - 1.0).abs() < 1e-4, "{n} {shading} {wo}: {ns}");
            let mirror = 2.0 * wo.dot(ns) * ns - wo;
            assert!(facing.dot(mirror) > 0.5 * LIFT, "{n} {shading} {wo}: mirror {mirror}");
            // A normal that needs no bending is kept as it is.
            let up = if shading.dot(facing) < 0.0 { -shading } else { shading };
            if facing.dot(2.0 * wo.dot(up) * up - wo) >= LIFT {
                assert_eq!(ns, up);
            }
        }
    }

    #[test]
    fn a_constant_shading_normal_shades_as_the_surface_tilted_to_it() {
        // A Lambertian surface shaded by a normal tilted 30° gives, times
        // the geometric cosine, albedo/π · n_s·ωi: what the geometrically
        // tilted surface gives, for every light direction above both.
        let (n, tilt) = (Vec3::Z, 30f32.to_radians());
        let ns = Vec3::new(tilt.sin(), 0.0, tilt.cos());
        let m = Material::diffuse(Rgb::splat(0.7));
        let wo = Vec3::new(0.2, 0.1, 0.97).normalize();
        let mut s = Sampler::for_pixel(2, 2, 2);
        for _ in 0..2000 {
            let wi = uniform_sphere(s.next2());
            if wi.dot(n) <= 0.0 || wi.dot(ns) <= 0.0 {
                continue;
            }
            let shaded = m.eval_at(Vec3::ZERO, n, Some(ns), wo, wi).0 * wi.dot(n);
            let tilted = m.eval(Vec3::ZERO, ns, wo, wi).0 * wi.dot(ns);
            assert!((shaded - tilted).abs().max_element() < 1e-6, "{wi}: {shaded} vs {tilted}");
        }
        // No shading normal: the material's own value, to the bit.
        let wi = Vec3::new(-0.3, 0.2, 0.9).normalize();
        assert_eq!(m.eval_at(Vec3::ZERO, n, None, wo, wi), m.eval(Vec3::ZERO, n, wo, wi));
    }

    #[test]
    fn no_light_passes_through_a_smooth_shaded_surface() {
        let mut s = Sampler::for_pixel(3, 3, 3);
        let m = Material::diffuse(Rgb::splat(0.7));
        for _ in 0..5000 {
            let (shading, wo, wi) = (uniform_sphere(s.next2()), uniform_sphere(s.next2()), uniform_sphere(s.next2()));
            if wo.z * wi.z < 0.0 {
                assert_eq!(m.eval_at(Vec3::ZERO, Vec3::Z, Some(shading), wo, wi).0, Rgb::ZERO);
            }
            if let Some(b) = m.sample_at(Vec3::ZERO, Vec3::Z, Some(shading), wo, s.next2(), s.next()) {
                assert!(b.wi.z * wo.z > 0.0);
            }
        }
    }
}
