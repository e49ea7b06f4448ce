//! Surface materials. All reflect on both sides (docs/scene-format.md: two-sided).

pub mod cutout;
pub mod metallic_roughness;
pub mod microfacet;
pub mod shading;

pub use cutout::{AlphaMode, Cutout};
pub use metallic_roughness::{MetallicRoughness, SurfaceMaps, TextureMap, UvTransform};

use crate::Rgb;
use crate::texture::Texture;
use glam::Vec3;
use std::f32::consts::PI;
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Lambertian: BRDF = albedo/π.
    Diffuse { albedo: Rgb },
    /// A solid checkerboard of two Lambertian albedos, squares `scale` wide.
    Checker { albedo: Rgb, albedo2: Rgb, scale: f32 },
    /// Diffuse plus a normalised Phong lobe (Lafortune and Willems 1994):
    /// f = albedo/π + specular·(n+2)/(2π)·max(0, r·wi)^n, r the mirror of wo.
    /// The (n+2)/(2π) makes the lobe's directional albedo at normal
    /// incidence equal `specular`, as in the ray-marching post's setUpPhongIllumination.
    Phong { albedo: Rgb, specular: Rgb, exponent: f32 },
    /// Lambertian with an image texture: albedo = `factor` × the texture's
    /// bilinearly filtered linear colour at the hit's texture coordinates
    /// ([`crate::Scene::material_at`] resolves it per hit). A surface
    /// without texture coordinates (a sphere, a mesh without them) takes
    /// `factor` × the texture's mean colour.
    Textured { factor: Rgb, texture: Arc<Texture> },
    /// glTF 2.0's metallic-roughness material: GGX over Lambert
    /// ([`MetallicRoughness`]).
    MetallicRoughness(MetallicRoughness),
}

impl Material {
    pub fn diffuse(albedo: Rgb) -> Self {
        Material::Diffuse { albedo }
    }
    pub fn checker(albedo: Rgb, albedo2: Rgb, scale: f32) -> Self {
        Material::Checker { albedo, albedo2, scale }
    }
    pub fn phong(albedo: Rgb, specular: Rgb, exponent: f32) -> Self {
        Material::Phong { albedo, specular, exponent }
    }
    pub fn textured(factor: Rgb, texture: Arc<Texture>) -> Self {
        Material::Textured { factor, texture }
    }
    /// The black surface of an area light.
    pub const BLACK: Material = Material::Diffuse { albedo: Rgb::ZERO };

    /// This material at texture coordinates `uv` (if the surface has
    /// them): a textured material becomes the diffuse one it is there;
    /// others are themselves.
    pub fn at_uv(&self, uv: Option<glam::Vec2>) -> Material {
        match (self, uv) {
            (Material::Textured { factor, texture }, Some(uv)) => {
                Material::Diffuse { albedo: *factor * texture.sample(uv.x, uv.y) }
            }
            (Material::MetallicRoughness(m), _) => Material::MetallicRoughness(m.at_uv(uv)),
            _ => self.clone(),
        }
    }

    /// Whether [`Material::at_uv`] depends on the texture coordinates.
    pub fn has_maps(&self) -> bool {
        match self {
            Material::Textured { .. } => true,
            Material::MetallicRoughness(m) => m.maps.is_some(),
            _ => false,
        }
    }

    /// The diffuse albedo at point `p` with outward normal `n` (a textured
    /// material: its mean; see [`Material::at_uv`]; a metallic-roughness
    /// one: its diffuse stand-in, [`MetallicRoughness::albedo`]).
    pub fn albedo(&self, p: Vec3, n: Vec3) -> Rgb {
        match *self {
            Material::Textured { factor, ref texture } => factor * texture.mean(),
            Material::MetallicRoughness(ref m) => m.at_uv(None).albedo(),
            Material::Diffuse { albedo } | Material::Phong { albedo, .. } => albedo,
            Material::Checker { albedo, albedo2, scale } => {
                // Step half a square inward so that points on a face that lies
                // on a cell boundary (a floor at y = 0) all fall in one cell.
                let q = (p - n * (0.5 * scale)) / scale;
                // Wrapping: a tiny scale sends the cell numbers to ±2⁶³.
                let parity = (q.x.floor() as i64).wrapping_add(q.y.floor() as i64).wrapping_add(q.z.floor() as i64);
                if parity.rem_euclid(2) == 0 { albedo } else { albedo2 }
            }
        }
    }

    /// The BRDF where it does not depend on the directions (every material
    /// but Phong): what [`Material::brdf`] gives at `p` for any `wo` and
    /// `wi` on one side of the surface, to the bit. None for Phong.
    #[inline]
    pub fn lambertian_brdf(&self, p: Vec3, n: Vec3) -> Option<Rgb> {
        match self {
            Material::Phong { .. } | Material::MetallicRoughness(_) => None,
            _ => Some(self.diffuse_brdf(p, n)),
        }
    }

    /// The diffuse part of the BRDF at `p`: albedo/π.
    #[inline]
    fn diffuse_brdf(&self, p: Vec3, n: Vec3) -> Rgb {
        self.albedo(p, n) / PI
    }

    /// The BRDF for outgoing `wo` and incident `wi` (both pointing away from
    /// the surface) at `p`, with geometric normal `n` facing either way. Zero
    /// when they lie on opposite sides: surfaces reflect on both sides but
    /// let no light through (a wall lit from behind is dark in front).
    pub fn brdf(&self, p: Vec3, n: Vec3, wo: Vec3, wi: Vec3) -> Rgb {
        if n.dot(wo) * n.dot(wi) <= 0.0 {
            return Rgb::ZERO;
        }
        if let Material::MetallicRoughness(m) = self {
            return m.eval(n, wo, wi).0;
        }
        let diffuse = self.diffuse_brdf(p, n);
        match *self {
            Material::Phong { specular, exponent, .. } => {
                // Both directions on one side of the surface, for the lobe.
                let n = if n.dot(wo) < 0.0 { -n } else { n };
                if n.dot(wi) <= 0.0 {
                    return diffuse;
                }
                let mirror = 2.0 * n.dot(wo) * n - wo;
                let cos = mirror.dot(wi).max(0.0);
                diffuse + specular * ((exponent + 2.0) / (2.0 * PI) * cos.powf(exponent))
            }
            _ => diffuse,
        }
    }
}

/// A direction drawn from a material's BRDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    /// The BRDF value f(wo, wi).
    pub f: Rgb,
    /// Solid-angle pdf of wi.
    pub pdf: f32,
}

impl Material {
    /// Chance of sampling the Phong lobe rather than the diffuse part: the
    /// lobe's share of the two weights (largest channels).
    fn lobe_probability(&self, p: Vec3, n: Vec3) -> f32 {
        match *self {
            Material::Phong { specular, .. } => {
                let (d, s) = (self.albedo(p, n).max_element(), specular.max_element());
                if d + s > 0.0 { s / (d + s) } else { 0.0 }
            }
            _ => 0.0,
        }
    }

    /// The BRDF and [`Material::pdf`] together, for light samples, which
    /// need both. Inlined, as [`Material::sample`]: the diffuse case is a
    /// few operations, and a call into another of the crate's codegen
    /// units cost the Cornell box 6% of its time (0.942×, 6 side-by-side
    /// pairs, with both marked).
    #[inline]
    pub fn eval(&self, p: Vec3, n: Vec3, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if let Material::Diffuse { albedo } = *self {
            let (cos_o, cos_i) = (n.dot(wo), n.dot(wi));
            let f = if cos_o * cos_i > 0.0 { albedo / PI } else { Rgb::ZERO };
            // As `pdf`: cosine about the normal turned toward wo.
            let cos = if cos_o < 0.0 { -cos_i } else { cos_i };
            return (f, if cos > 0.0 { cos / PI } else { 0.0 });
        }
        if let Material::MetallicRoughness(m) = self {
            return m.eval(n, wo, wi);
        }
        (self.brdf(p, n, wo, wi), self.pdf(p, n, wo, wi))
    }

    /// Solid-angle pdf with which [`Material::sample`] draws `wi`.
    pub fn pdf(&self, p: Vec3, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        if let Material::MetallicRoughness(m) = self {
            return m.eval(n, wo, wi).1;
        }
        // Directions are drawn on wo's side; `n` itself still picks the
        // checker's square.
        let facing = if n.dot(wo) < 0.0 { -n } else { n };
        let cos = facing.dot(wi);
        if cos <= 0.0 {
            return 0.0;
        }
        let diffuse = cos / PI;
        match *self {
            Material::Phong { exponent, .. } => {
                let ps = self.lobe_probability(p, n);
                let mirror = 2.0 * facing.dot(wo) * facing - wo;
                let c = mirror.dot(wi).max(0.0);
                (1.0 - ps) * diffuse + ps * (exponent + 1.0) / (2.0 * PI) * c.powf(exponent)
            }
            _ => diffuse,
        }
    }

    /// Draws an incident direction for outgoing `wo`: cosine-weighted for
    /// the diffuse part, cos^n around the mirror direction for the Phong
    /// lobe (Lafortune and Willems 1994), chosen by `u_lobe`. None if the
    /// draw falls below the surface.
    #[inline]
    pub fn sample(&self, p: Vec3, n: Vec3, wo: Vec3, u: glam::Vec2, u_lobe: f32) -> Option<BsdfSample> {
        let facing = if n.dot(wo) < 0.0 { -n } else { n };
        if let Material::Diffuse { albedo } = *self {
            // The common case in one step: the general path below computes
            // the same pdf and BRDF through `pdf` and `brdf`.
            let wi = crate::sampling::to_world(crate::sampling::cosine_hemisphere(u), facing);
            let cos = facing.dot(wi);
            if cos <= 0.0 {
                return None;
            }
            let f = if n.dot(wo) * n.dot(wi) > 0.0 { albedo / PI } else { Rgb::ZERO };
            return Some(BsdfSample { wi, f, pdf: cos / PI });
        }
        if let Material::MetallicRoughness(m) = self {
            return m.sample(n, wo, u, u_lobe).map(|(wi, f, pdf)| BsdfSample { wi, f, pdf });
        }
        let wi = if u_lobe < self.lobe_probability(p, n) {
            let Material::Phong { exponent, .. } = *self else { unreachable!() };
            let mirror = 2.0 * facing.dot(wo) * facing - wo;
            let cos_a = u.x.powf(1.0 / (exponent + 1.0));
            let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
            let phi = 2.0 * PI * u.y;
            crate::sampling::to_world(Vec3::new(sin_a * phi.cos(), sin_a * phi.sin(), cos_a), mirror)
        } else {
            crate::sampling::to_world(crate::sampling::cosine_hemisphere(u), facing)
        };
        let pdf = self.pdf(p, n, wo, wi);
        (pdf > 0.0).then(|| BsdfSample { wi, f: self.brdf(p, n, wo, wi), pdf })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Sampler, to_world, uniform_sphere};

    /// Directional albedo ∫ f·cos dω by Monte Carlo over the hemisphere.
    fn directional_albedo(m: &Material, wo: Vec3, n: usize) -> Rgb {
        let mut s = Sampler::for_pixel(3, 1, 4);
        let mut sum = Rgb::ZERO;
        for _ in 0..n {
            let mut wi = uniform_sphere(s.next2());
            wi.z = wi.z.abs();
            sum += m.brdf(Vec3::ZERO, Vec3::Z, wo, wi) * wi.z * (2.0 * PI);
        }
        sum / n as f32
    }

    #[test]
    fn lambertian_reflects_its_albedo() {
        let a = directional_albedo(&Material::diffuse(Rgb::splat(0.6)), Vec3::Z, 200_000);
        assert!((a.x - 0.6).abs() < 0.005, "{a}");
    }

    #[test]
    fn phong_lobe_at_normal_incidence_reflects_its_specular_weight() {
        // With the (n+2)/2π normalisation, ∫ cos^n(α) cos θ dω = 2π/(n+2) at
        // normal incidence, where α = θ; so the lobe's albedo is `specular`.
        let m = Material::phong(Rgb::ZERO, Rgb::splat(0.5), 20.0);
        let a = directional_albedo(&m, Vec3::Z, 400_000);
        assert!((a.x - 0.5).abs() < 0.01, "{a}");
        // And it is symmetric in wo and wi (reciprocity).
        let wo = to_world(Vec3::new(0.3, 0.1, 0.9).normalize(), Vec3::Z);
        let wi = Vec3::new(-0.2, 0.25, 0.8).normalize();
        let f1 = m.brdf(Vec3::ZERO, Vec3::Z, wo, wi);
        let f2 = m.brdf(Vec3::ZERO, Vec3::Z, wi, wo);
        assert!((f1 - f2).length() < 1e-5);
    }

    #[test]
    fn sampled_directions_estimate_the_directional_albedo() {
        // E[f cos / pdf] over the material's own samples equals the albedo
        // computed by uniform sampling: checks pdf and sample agree.
        for m in [Material::diffuse(Rgb::splat(0.7)), Material::phong(Rgb::splat(0.3), Rgb::splat(0.5), 15.0)] {
            let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
            let reference = directional_albedo(&m, wo, 400_000);
            let mut s = Sampler::for_pixel(8, 8, 8);
            let n = 400_000;
            let mut sum = Rgb::ZERO;
            for _ in 0..n {
                if let Some(b) = m.sample(Vec3::ZERO, Vec3::Z, wo, s.next2(), s.next()) {
                    sum += b.f * b.wi.z.abs() / b.pdf;
                    assert!((m.pdf(Vec3::ZERO, Vec3::Z, wo, b.wi) - b.pdf).abs() < 1e-4 * b.pdf.max(1.0));
                }
            }
            let est = sum / n as f32;
            assert!((est.x - reference.x).abs() < 0.01, "{m:?}: {est} vs {reference}");
        }
    }

    #[test]
    fn eval_is_brdf_and_pdf_and_diffuse_samples_match_them() {
        let mut s = Sampler::for_pixel(4, 4, 4);
        let materials = [
            Material::diffuse(Rgb::new(0.7, 0.5, 0.2)),
            Material::phong(Rgb::splat(0.3), Rgb::splat(0.5), 15.0),
            Material::checker(Rgb::ONE, Rgb::splat(0.2), 0.5),
        ];
        for m in &materials {
            for _ in 0..2000 {
                let (p, n) = (uniform_sphere(s.next2()) * 3.0, uniform_sphere(s.next2()));
                let (wo, wi) = (uniform_sphere(s.next2()), uniform_sphere(s.next2()));
                assert_eq!(m.eval(p, n, wo, wi), (m.brdf(p, n, wo, wi), m.pdf(p, n, wo, wi)), "{m:?}");
                if let Some(b) = m.sample(p, n, wo, s.next2(), s.next()) {
                    let (f, pdf) = (m.brdf(p, n, wo, b.wi), m.pdf(p, n, wo, b.wi));
                    assert!((b.f - f).abs().max_element() < 1e-6 && (b.pdf - pdf).abs() < 1e-5 * pdf.max(1.0), "{m:?}");
                }
            }
        }
    }

    #[test]
    fn no_light_passes_through_a_surface() {
        // Directional albedo from the whole sphere of directions: what a
        // two-sided surface reflects toward wo, from wo's side only (light
        // arriving from behind would be transmission, which diffuse walls
        // do not do).
        let mut s = Sampler::for_pixel(5, 2, 1);
        for m in [Material::diffuse(Rgb::splat(0.6)), Material::phong(Rgb::splat(0.3), Rgb::splat(0.2), 20.0)] {
            for wo in [Vec3::Z, -Vec3::Z, Vec3::new(0.3, 0.2, -0.9).normalize()] {
                let n = 100_000;
                let mut total = Rgb::ZERO;
                for _ in 0..n {
                    let wi = uniform_sphere(s.next2());
                    total += m.brdf(Vec3::ZERO, Vec3::Z, wo, wi) * wi.z.abs() * (4.0 * PI);
                }
                let behind = (0..1000)
                    .map(|_| uniform_sphere(s.next2()))
                    .filter(|wi| wi.z * wo.z < 0.0)
                    .all(|wi| m.brdf(Vec3::ZERO, Vec3::Z, wo, wi) == Rgb::ZERO);
                assert!(behind, "{m:?}: light from behind reflected toward {wo}");
                let albedo = total / n as f32;
                assert!(albedo.x <= 0.62, "{m:?} toward {wo}: directional albedo {albedo} over the sphere");
            }
        }
    }

    #[test]
    fn checker_alternates_and_is_stable_on_cell_boundaries() {
        let m = Material::checker(Rgb::ONE, Rgb::ZERO, 1.0);
        let up = Vec3::Y;
        let a = m.albedo(Vec3::new(0.5, 0.0, 0.5), up);
        let b = m.albedo(Vec3::new(0.5, 1e-7, 0.5), up);
        let c = m.albedo(Vec3::new(0.5, -1e-7, 0.5), up);
        assert_eq!(a, b);
        assert_eq!(a, c);
        assert_ne!(a, m.albedo(Vec3::new(1.5, 0.0, 0.5), up));
        assert_eq!(a, m.albedo(Vec3::new(1.5, 0.0, 1.5), up));
    }
}
