//! glTF 2.0's metallic-roughness material: a Lambertian base under a
//! GGX specular layer whose reflectance at normal incidence is 0.04 for a
//! dielectric and the base colour for a metal, blended by `metallic`
//! (glTF 2.0 specification, appendix B).

use super::microfacet::{self, Fresnel, MIN_ALPHA, SpecularAlbedo};
use crate::Rgb;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

/// The reflectance at normal incidence of glTF's dielectrics (index of
/// refraction 1.5).
const DIELECTRIC_F0: f32 = 0.04;

/// A metallic-roughness surface at one point, or with the maps that give
/// its values per point.
///
/// The specular lobe is glTF's: f_s = F·D·V with F = mix(s·F_d, F_m,
/// metallic), F_d Schlick's for F0 = 0.04 and F_m for F0 = base, s the
/// dielectric's specular weight (`KHR_materials_specular`'s
/// `specularFactor`, 1 without it), GGX's D and the height-correlated Smith V,
/// α = roughness² (held at least [`MIN_ALPHA`]). The diffuse lobe is the
/// base colour of the dielectric part, c = base·(1 − metallic), scaled by
/// what the specular layer leaves in both directions:
///
/// f_d = c/π · (1 − E(μo))(1 − E(μi)) / (1 − Ē),
///
/// with E the specular lobe's directional albedo and Ē its cosine-weighted
/// mean (Kelemen and Szirmay-Kalos 2001, "A microfacet based coupled
/// specular-matte BRDF model with importance sampling"). The specification's
/// own sketch weights the diffuse lobe by 1 − F(v·h) instead; at grazing
/// views that reflects nearly twice what arrives (the specular lobe takes
/// F ≈ 1 at the mirror direction while the diffuse lobe keeps almost all
/// of its light), so the coupled form is used: reciprocal, and its albedo
/// E(μo) + c·(1 − E(μo)) never exceeds one.
#[derive(Clone, Debug, PartialEq)]
pub struct MetallicRoughness {
    pub base: Rgb,
    pub metallic: f32,
    pub roughness: f32,
    /// The weight of the dielectric's specular reflection, in [0, 1].
    pub specular: f32,
    /// Texture maps that scale the factors above, per point.
    pub maps: Option<Arc<SurfaceMaps>>,
}

/// The texture maps of a metallic-roughness material.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SurfaceMaps {
    /// Linear RGB that multiplies the base colour.
    pub base_colour: Option<TextureMap>,
    /// Data: green multiplies the roughness, blue the metalness (glTF's layout).
    pub metallic_roughness: Option<TextureMap>,
    /// A tangent-space normal map (data) and its scale (glTF's
    /// `normalTexture`): see [`SurfaceMaps::mapped_normal`].
    pub normal: Option<(TextureMap, f32)>,
}

impl SurfaceMaps {
    /// The shading normal the normal map gives at `uv`, about the normal
    /// `n` (the vertex normals' or the triangle's) with the surface's
    /// texture derivatives `dpdu`, `dpdv`: the texel (r, g, b) read as the
    /// tangent-space vector (2r − 1, 2g − 1, 2b − 1), its x and y times
    /// the scale, in the frame of the tangent t (∂p/∂u made perpendicular
    /// to n), the bitangent ±n × t on the side of −∂p/∂v, and n. glTF's
    /// normal maps have +x along u and +y up the image, and its v runs down
    /// the image. The frame is the triangle's (tangents per triangle from
    /// its texture coordinates, not MikkTSpace's per vertex: seams between
    /// triangles of different mappings can show). None without a normal
    /// map or where the frame degenerates.
    pub fn mapped_normal(&self, uv: Vec2, n: Vec3, dpdu: Vec3, dpdv: Vec3) -> Option<Vec3> {
        let (map, scale) = self.normal.as_ref()?;
        let t = (dpdu - n * n.dot(dpdu)).try_normalize()?;
        // glTF's tangent space: +x along u, +y along v pointing up the
        // image, which is −∂p/∂v (v runs down the image), made right-handed
        // or left-handed as the texture's mapping is.
        let b = n.cross(t) * if n.cross(t).dot(-dpdv) < 0.0 { -1.0 } else { 1.0 };
        let c = map.sample(uv) * 2.0 - Vec3::ONE;
        (t * (c.x * scale) + b * (c.y * scale) + n * c.z).try_normalize()
    }
}

/// A texture as a material reads it: through a transform of the surface's
/// texture coordinates (glTF's `KHR_texture_transform`).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureMap {
    pub texture: Arc<Texture>,
    pub transform: UvTransform,
}

impl TextureMap {
    pub fn new(texture: Arc<Texture>) -> Self {
        TextureMap { texture, transform: UvTransform::IDENTITY }
    }

    /// The texture's value at the surface's coordinates `uv`.
    pub fn sample(&self, uv: Vec2) -> Rgb {
        let uv = self.transform.apply(uv);
        self.texture.sample(uv.x, uv.y)
    }

    /// The texture's mean over the triangle with corners at coordinates
    /// `uv`: the triangle cut into m² triangles of equal area (m from the
    /// texels it covers, at most [`MAX_TRIANGLE_SPLIT`]), the texture
    /// taken at each one's centroid.
    pub fn mean_over_triangle(&self, uv: [Vec2; 3]) -> Rgb {
        let (w, h) = self.texture.size();
        let [a, b, c] = uv.map(|t| self.transform.apply(t) * Vec2::new(w as f32, h as f32));
        let texels = 0.5 * (b - a).perp_dot(c - a).abs();
        let m = if texels.is_finite() {
            (2.0 * texels).sqrt().ceil().clamp(1.0, MAX_TRIANGLE_SPLIT as f32) as u32
        } else {
            1
        };
        let at = |s: f32, t: f32| self.sample(uv[0] + (uv[1] - uv[0]) * s + (uv[2] - uv[0]) * t);
        let mut sum = glam::DVec3::ZERO;
        let step = 1.0 / m as f32;
        for i in 0..m {
            for j in 0..m - i {
                // The upright piece with corner (i, j), and the inverted one
                // beside it where there is room.
                sum += at((i as f32 + 1.0 / 3.0) * step, (j as f32 + 1.0 / 3.0) * step).as_dvec3();
                if i + j + 1 < m {
                    sum += at((i as f32 + 2.0 / 3.0) * step, (j as f32 + 2.0 / 3.0) * step).as_dvec3();
                }
            }
        }
        (sum / (m * m) as f64).as_vec3()
    }
}

/// The finest cut of a triangle for [`TextureMap::mean_over_triangle`]:
/// 64² pieces, enough for a triangle of two thousand texels a side.
pub const MAX_TRIANGLE_SPLIT: u32 = 64;

/// An affine map of texture coordinates: scale, then rotate, then offset,
/// as `KHR_texture_transform` composes them. A rotation by r turns (u, v)
/// into (u·cos r + v·sin r, −u·sin r + v·cos r): counter-clockwise in the
/// texture's image, whose v axis points down (the extension's example, the
/// lower left quadrant turned a quarter, comes out so).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub offset: Vec2,
    pub rotation: f32,
    pub scale: Vec2,
}

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform { offset: Vec2::ZERO, rotation: 0.0, scale: Vec2::ONE };

    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let s = uv * self.scale;
        let (sin, cos) = self.rotation.sin_cos();
        Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y) + self.offset
    }
}

impl MetallicRoughness {
    /// The material at texture coordinates `uv` (the maps' means without
    /// them), with no maps left.
    pub fn at_uv(&self, uv: Option<Vec2>) -> MetallicRoughness {
        let Some(maps) = &self.maps else { return self.clone() };
        let value = |m: &TextureMap| uv.map_or(m.texture.mean(), |uv| m.sample(uv));
        let base = maps.base_colour.as_ref().map_or(self.base, |m| self.base * value(m));
        let (roughness, metallic) = maps.metallic_roughness.as_ref().map_or((self.roughness, self.metallic), |m| {
            let v = value(m);
            (self.roughness * v.y, self.metallic * v.z)
        });
        MetallicRoughness { base, metallic, roughness, specular: self.specular, maps: None }
    }

    /// A diffuse surface of `albedo` (no specular reflection at all).
    pub fn lambertian(albedo: Rgb) -> MetallicRoughness {
        MetallicRoughness { base: albedo, metallic: 0.0, roughness: 1.0, specular: 0.0, maps: None }
    }

    fn alpha(&self) -> f32 {
        (self.roughness * self.roughness).max(MIN_ALPHA)
    }

    fn fresnel(&self) -> Fresnel {
        let (d, m) = (Fresnel::schlick(Rgb::splat(DIELECTRIC_F0)), Fresnel::schlick(self.base));
        let (ws, wm) = (self.specular * (1.0 - self.metallic), self.metallic);
        Fresnel { normal: d.normal * ws + m.normal * wm, grazing: d.grazing * ws + m.grazing * wm }
    }

    fn diffuse_colour(&self) -> Rgb {
        self.base * (1.0 - self.metallic)
    }

    /// A diffuse stand-in for integrators that only know Lambertian
    /// surfaces (radiosity, the preview's irradiance cache): the
    /// material's albedo at normal incidence, E(1) + c·(1 − E(1)).
    pub fn albedo(&self) -> Rgb {
        let e = SpecularAlbedo::get().albedo(self.fresnel(), 1.0, self.alpha());
        e + self.diffuse_colour() * (Rgb::ONE - e)
    }

    /// The BRDF for `wo` and `wi` in the frame of `n` turned toward `wo`
    /// (cosines `co`, `ci` both positive).
    fn brdf_local(&self, n: Vec3, wo: Vec3, wi: Vec3, co: f32, ci: f32) -> Rgb {
        let alpha = self.alpha();
        let fresnel = self.fresnel();
        let h = (wo + wi).normalize_or_zero();
        let table = SpecularAlbedo::get();
        let specular = if h == Vec3::ZERO || fresnel.is_zero() {
            Rgb::ZERO
        } else {
            let (t, b) = crate::sampling::basis(n);
            let h_local = Vec3::new(h.dot(t), h.dot(b), h.dot(n));
            fresnel.at(wo.dot(h)) * microfacet::distribution(h_local, alpha) * microfacet::visibility(co, ci, alpha)
        };
        let c = self.diffuse_colour();
        if c == Rgb::ZERO {
            return specular;
        }
        if fresnel.is_zero() {
            return c / PI;
        }
        let (eo, ei) = (table.albedo(fresnel, co, alpha), table.albedo(fresnel, ci, alpha));
        // Held away from zero: the numerator vanishes with it, and a
        // larger denominator only lowers the albedo.
        let rest = (Rgb::ONE - table.average(fresnel, alpha)).max(Rgb::splat(1e-4));
        specular + c / PI * (Rgb::ONE - eo) * (Rgb::ONE - ei) / rest
    }

    /// The chance of drawing the specular lobe for a view at cosine `co`:
    /// its share of the albedo.
    fn specular_probability(&self, co: f32) -> f32 {
        let e = SpecularAlbedo::get().albedo(self.fresnel(), co, self.alpha());
        let (s, d) = (e.max_element(), (self.diffuse_colour() * (Rgb::ONE - e)).max_element());
        if s + d > 0.0 { s / (s + d) } else { 1.0 }
    }

    /// The BRDF (zero unless both directions lie on one side of `n`) and
    /// the solid-angle pdf of [`MetallicRoughness::sample`] for `wi`.
    pub fn eval(&self, n: Vec3, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let n = if n.dot(wo) < 0.0 { -n } else { n };
        let (co, ci) = (n.dot(wo), n.dot(wi));
        if co <= 0.0 || ci <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        (self.brdf_local(n, wo, wi, co, ci), self.pdf_local(n, wo, wi, co, ci))
    }

    fn pdf_local(&self, n: Vec3, wo: Vec3, wi: Vec3, co: f32, ci: f32) -> f32 {
        let ps = self.specular_probability(co);
        let h = (wo + wi).normalize_or_zero();
        let specular = if h == Vec3::ZERO {
            0.0
        } else {
            let (t, b) = crate::sampling::basis(n);
            let local = |w: Vec3| Vec3::new(w.dot(t), w.dot(b), w.dot(n));
            // The visible normal's density over 4 (o·h): the Jacobian of
            // reflection (Walter et al. 2007, eq. 14).
            microfacet::visible_normal_pdf(local(wo), local(h), self.alpha()) / (4.0 * wo.dot(h))
        };
        ps * specular.max(0.0) + (1.0 - ps) * ci / PI
    }

    /// Draws `wi` for `wo`: the specular lobe's visible normals reflected
    /// (with chance its share of the albedo), or a cosine-weighted
    /// direction for the diffuse lobe; returns it with the BRDF and the
    /// pdf of both strategies together. None below the surface.
    pub fn sample(&self, n: Vec3, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<(Vec3, Rgb, f32)> {
        let n = if n.dot(wo) < 0.0 { -n } else { n };
        let co = n.dot(wo);
        if co <= 0.0 {
            return None;
        }
        let wi = if u_lobe < self.specular_probability(co) {
            let (t, b) = crate::sampling::basis(n);
            let v = Vec3::new(wo.dot(t), wo.dot(b), co);
            let h = microfacet::sample_visible_normal(v, self.alpha(), u);
            let h = t * h.x + b * h.y + n * h.z;
            microfacet::reflect(wo, h)
        } else {
            crate::sampling::to_world(crate::sampling::cosine_hemisphere(u), n)
        };
        let ci = n.dot(wi);
        if ci <= 0.0 {
            return None;
        }
        let pdf = self.pdf_local(n, wo, wi, co, ci);
        (pdf > 0.0).then(|| (wi, self.brdf_local(n, wo, wi, co, ci), pdf))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Sampler, uniform_sphere};

    fn material(base: f32, metallic: f32, roughness: f32) -> MetallicRoughness {
        MetallicRoughness { base: Rgb::splat(base), metallic, roughness, specular: 1.0, maps: None }
    }

    fn view(mu: f32) -> Vec3 {
        Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu)
    }

    /// ∫ f·cos dωi by uniform sampling of the upper hemisphere: an answer
    /// that uses neither the material's sampling nor its pdf.
    fn uniform_albedo(m: &MetallicRoughness, wo: Vec3, n: usize, seed: u64) -> Rgb {
        let mut s = Sampler::for_pixel(seed, 1, 2);
        let mut sum = glam::DVec3::ZERO;
        for _ in 0..n {
            let mut wi = uniform_sphere(s.next2());
            wi.z = wi.z.abs();
            sum += (m.eval(Vec3::Z, wo, wi).0 * wi.z).as_dvec3();
        }
        (sum / n as f64 * 2.0 * std::f64::consts::PI).as_vec3()
    }

    /// The same integral by the material's own samples.
    fn sampled_albedo(m: &MetallicRoughness, wo: Vec3, n: usize, seed: u64) -> Rgb {
        let mut s = Sampler::for_pixel(seed, 3, 4);
        let mut sum = glam::DVec3::ZERO;
        for _ in 0..n {
            if let Some((wi, f, pdf)) = m.sample(Vec3::Z, wo, s.next2(), s.next()) {
                sum += (f * wi.z / pdf).as_dvec3();
            }
        }
        (sum / n as f64).as_vec3()
    }

    #[test]
    fn a_white_furnace_never_reflects_more_than_arrives() {
        // A white base (by the material's own samples, which the test below
        // holds to uniform sampling): the albedo is at most one at every angle, and for a
        // dielectric close to it (the coupled diffuse lobe takes what the
        // specular lobe leaves); a white metal loses only the single-
        // scattering microfacet model's energy (most at high roughness).
        for roughness in [0.05, 0.3, 0.6, 1.0] {
            for metallic in [0.0, 0.5, 1.0] {
                let m = material(1.0, metallic, roughness);
                for mu in [0.05, 0.3, 0.7, 1.0] {
                    let a = sampled_albedo(&m, view(mu), 100_000, 1).x;
                    let smooth_enough = roughness >= 0.3 || mu >= 0.3;
                    assert!(a <= 1.0 + if smooth_enough { 0.01 } else { 0.05 }, "{m:?} at μ {mu}: {a}");
                    if metallic == 0.0 && smooth_enough {
                        assert!(a > 0.9, "{m:?} at μ {mu}: {a}");
                    }
                }
            }
        }
    }

    #[test]
    fn samples_and_their_pdf_integrate_as_the_brdf() {
        // E[f cos / pdf] over the material's samples equals the albedo by
        // uniform sampling, and the pdf each sample carries is the one
        // `eval` gives for its direction.
        let mut s = Sampler::for_pixel(5, 5, 5);
        for (base, metallic, roughness) in [(0.8, 0.0, 0.5), (0.9, 1.0, 0.35), (0.5, 0.5, 0.8), (0.7, 0.0, 0.25)] {
            let m = material(base, metallic, roughness);
            for mu in [0.2, 0.6, 0.95] {
                let wo = view(mu);
                let reference = uniform_albedo(&m, wo, 400_000, 2).x;
                let estimate = sampled_albedo(&m, wo, 200_000, 3).x;
                let tolerance = 0.01 + 0.02 * reference;
                assert!((estimate - reference).abs() < tolerance, "{m:?} at μ {mu}: {estimate} vs {reference}");
                for _ in 0..200 {
                    if let Some((wi, f, pdf)) = m.sample(Vec3::Z, wo, s.next2(), s.next()) {
                        let (f2, pdf2) = m.eval(Vec3::Z, wo, wi);
                        assert!((pdf - pdf2).abs() <= 1e-4 * pdf.max(1.0) && (f - f2).abs().max_element() < 1e-4);
                    }
                }
            }
        }
    }

    #[test]
    fn sampled_directions_follow_the_pdf_by_a_chi_square_test() {
        // As Mitsuba 3 tests its BSDFs: a histogram of drawn directions
        // against the pdf integrated over each cell.
        let mut s = Sampler::for_pixel(8, 8, 8);
        for (metallic, roughness, mu) in [(0.0, 0.5, 0.7), (1.0, 0.3, 0.5), (0.5, 0.8, 0.3), (1.0, 0.6, 0.95)] {
            let m = material(0.8, metallic, roughness);
            let wo = view(mu);
            let (chi2, cells) = super::super::microfacet::chi_square_hemisphere(
                || m.sample(Vec3::Z, wo, s.next2(), s.next()).map(|(wi, _, _)| wi),
                |wi| m.eval(Vec3::Z, wo, wi).1,
                200_000,
            );
            assert!(cells > 100 && chi2 < 2.0 * cells as f64, "{m:?} at μ {mu}: χ² {chi2} over {cells} cells");
        }
    }

    #[test]
    fn the_pdf_integrates_to_one() {
        // ∫ pdf dω over the hemisphere: the density of a strategy that
        // always draws a direction above the surface, bar the visible
        // normals whose mirror falls below it.
        let mut s = Sampler::for_pixel(6, 6, 6);
        for (metallic, roughness, mu) in [(0.0, 0.5, 0.7), (1.0, 0.3, 0.5), (1.0, 0.9, 0.2)] {
            let m = material(0.8, metallic, roughness);
            let wo = view(mu);
            let n = 400_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let mut wi = uniform_sphere(s.next2());
                wi.z = wi.z.abs();
                sum += m.eval(Vec3::Z, wo, wi).1 as f64;
            }
            let integral = sum / n as f64 * 2.0 * std::f64::consts::PI;
            assert!(integral <= 1.02 && integral > 0.85, "{m:?} at μ {mu}: {integral}");
        }
    }

    #[test]
    fn the_brdf_is_reciprocal_and_two_sided_without_transmission() {
        let mut s = Sampler::for_pixel(7, 7, 7);
        let m = MetallicRoughness {
            base: Rgb::new(0.9, 0.5, 0.2),
            metallic: 0.4,
            roughness: 0.35,
            specular: 1.0,
            maps: None,
        };
        for _ in 0..2000 {
            let (n, wo, wi) = (uniform_sphere(s.next2()), uniform_sphere(s.next2()), uniform_sphere(s.next2()));
            let (a, b) = (m.eval(n, wo, wi).0, m.eval(n, wi, wo).0);
            assert!((a - b).abs().max_element() <= 1e-4 * a.max_element().max(1.0), "{a} vs {b}");
            if n.dot(wo) * n.dot(wi) <= 0.0 {
                assert_eq!(a, Rgb::ZERO);
            }
            assert_eq!(m.eval(-n, wo, wi).0, a);
        }
    }

    #[test]
    fn a_smooth_metal_reflects_its_base_colour_at_normal_incidence() {
        // Schlick's F at normal incidence is F0 = the base colour, and a
        // narrow lobe loses nothing to masking there.
        let m = MetallicRoughness {
            base: Rgb::new(0.9, 0.6, 0.3),
            metallic: 1.0,
            roughness: 0.1,
            specular: 1.0,
            maps: None,
        };
        let a = sampled_albedo(&m, Vec3::Z, 100_000, 9);
        assert!((a - m.base).abs().max_element() < 0.01, "{a}");
    }

    #[test]
    fn without_specular_weight_a_dielectric_is_lambertian() {
        // KHR_materials_specular's specularFactor 0 (Blender's exports of
        // diffuse surfaces): the BRDF is base/π, sampled by the cosine.
        let base = Rgb::new(0.6, 0.3, 0.1);
        let m = MetallicRoughness::lambertian(base);
        let mut s = Sampler::for_pixel(9, 9, 9);
        for _ in 0..1000 {
            let (wo, wi) = (uniform_sphere(s.next2()), uniform_sphere(s.next2()));
            let (f, pdf) = m.eval(Vec3::Z, wo, wi);
            if wo.z * wi.z > 0.0 {
                assert!((f - base / PI).abs().max_element() < 1e-7 && (pdf - wi.z.abs() / PI).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn a_triangles_mean_weighs_the_texels_it_covers() {
        // A 256×1 texture, its left half white and its right half black:
        // a triangle within the left half is white; the image's lower left
        // half (corners (0, 0), (0, 1), (1, 1)), {0 ≤ u ≤ v ≤ 1}, has the
        // mean 2∫₀^½ (1 − u) du = 3/4 (the bilinear ramp at the seam is
        // symmetric about u = ½, so it weighs as the step).
        let texels = (0..256).map(|i| if i < 128 { [255; 3] } else { [0; 3] }).collect();
        let clamp = crate::texture::Wrap::ClampToEdge;
        let map = TextureMap::new(Arc::new(Texture::from_srgb8(256, 1, texels).unwrap().with_wrap(clamp, clamp)));
        let left = map.mean_over_triangle([Vec2::new(0.0, 0.0), Vec2::new(0.25, 0.0), Vec2::new(0.0, 1.0)]);
        assert!((left.x - 1.0).abs() < 1e-6, "{left}");
        let lower = map.mean_over_triangle([Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0)]);
        assert!((lower.x - 0.75).abs() < 0.01, "{lower}");
        // Moved by a transform: the same triangle read mirrored along u
        // sees the black half where the white was.
        let mirrored = TextureMap {
            transform: UvTransform { offset: Vec2::X, rotation: 0.0, scale: Vec2::new(-1.0, 1.0) },
            ..map.clone()
        };
        let lower = mirrored.mean_over_triangle([Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0)]);
        assert!((lower.x - 0.25).abs() < 0.01, "{lower}");
    }

    #[test]
    fn the_texture_transform_follows_the_extensions_example() {
        // KHR_texture_transform's example: offset (0, 1), a quarter turn,
        // half scale shows the lower left quadrant of the image.
        let t =
            UvTransform { offset: Vec2::new(0.0, 1.0), rotation: std::f32::consts::FRAC_PI_2, scale: Vec2::splat(0.5) };
        for (uv, expected) in
            [((0.0, 0.0), (0.0, 1.0)), ((1.0, 0.0), (0.0, 0.5)), ((1.0, 1.0), (0.5, 0.5)), ((0.0, 1.0), (0.5, 1.0))]
        {
            let got = t.apply(Vec2::new(uv.0, uv.1));
            assert!((got - Vec2::new(expected.0, expected.1)).length() < 1e-6, "{uv:?} → {got}");
        }
    }
}
