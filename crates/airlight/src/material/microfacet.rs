//! The microfacet functions of glTF 2.0's metallic-roughness material, as
//! the specification's appendix B gives them: the Trowbridge–Reitz (GGX)
//! distribution of normals (Walter et al. 2007, "Microfacet models for
//! refraction through rough surfaces"), Smith's height-correlated masking
//! and shadowing (Heitz 2014, "Understanding the masking-shadowing function
//! in microfacet-based BRDFs"), Schlick's Fresnel (1994), and sampling of
//! the distribution of visible normals (Heitz 2018, "Sampling the GGX
//! distribution of visible normals").
//!
//! Directions are in a frame whose z axis is the surface normal; `alpha`
//! is the distribution's width, roughness² in glTF.

use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The narrowest distribution used: glTF's roughness 0 is a mirror, which
/// a renderer without delta lobes draws as a very narrow one (a peak of
/// 1/(π·alpha²) ≈ 3·10⁵, still finite in f32).
pub const MIN_ALPHA: f32 = 1e-3;

/// D(h): the density of microfacet normals `h` (unit, local), per unit
/// solid angle of projected area, normalised so that ∫ D(h)·h.z dω = 1.
/// Written as α² / (π (α²·cos² + sin²)²), with sin² from x and y, so
/// that normals within 10⁻³ of the macro normal keep their precision.
#[inline]
pub fn distribution(h: Vec3, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let d = a2 * h.z * h.z + h.x * h.x + h.y * h.y;
    a2 / (PI * d * d)
}

/// Smith's Λ for a direction at cosine `cos` to the normal:
/// (√(1 + α² tan²θ) − 1)/2.
#[inline]
fn lambda(cos: f32, alpha: f32) -> f32 {
    let c2 = cos * cos;
    let a2 = alpha * alpha;
    ((a2 + (1.0 - a2) * c2).max(0.0).sqrt() / cos.abs() - 1.0) * 0.5
}

/// G1(v): the fraction of microfacets facing `v` that `v` sees.
#[inline]
pub fn masking(cos: f32, alpha: f32) -> f32 {
    if cos <= 0.0 { 0.0 } else { 1.0 / (1.0 + lambda(cos, alpha)) }
}

/// The height-correlated G2(o, i) / (4 cos_o cos_i) of glTF's reference
/// BRDF, "V" in the specification: ½ / (cos_i √(α² + (1−α²)cos_o²) +
/// cos_o √(α² + (1−α²)cos_i²)).
#[inline]
pub fn visibility(cos_o: f32, cos_i: f32, alpha: f32) -> f32 {
    if cos_o <= 0.0 || cos_i <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let o = (a2 + (1.0 - a2) * cos_o * cos_o).sqrt();
    let i = (a2 + (1.0 - a2) * cos_i * cos_i).sqrt();
    0.5 / (cos_i * o + cos_o * i)
}

/// Schlick's approximation of the Fresnel reflectance at the cosine
/// `cos` between a direction and the microfacet normal: F0 + (1 − F0)(1 − cos)⁵.
#[inline]
pub fn schlick(f0: Rgb, cos: f32) -> Rgb {
    Fresnel::schlick(f0).at(cos)
}

/// A reflectance of Schlick's form, F(c) = `normal` + `grazing`·(1 − c)⁵:
/// Schlick's own (`grazing` = 1 − F0), and any blend or scaling of such
/// terms, which keeps the form (glTF's mix of a dielectric and a metal,
/// `KHR_materials_specular`'s weight).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fresnel {
    pub normal: Rgb,
    pub grazing: Rgb,
}

impl Fresnel {
    pub fn schlick(f0: Rgb) -> Fresnel {
        Fresnel { normal: f0, grazing: Rgb::ONE - f0 }
    }

    #[inline]
    pub fn at(&self, cos: f32) -> Rgb {
        let m = (1.0 - cos.abs()).clamp(0.0, 1.0);
        let m5 = (m * m) * (m * m) * m;
        self.normal + self.grazing * m5
    }

    pub fn is_zero(&self) -> bool {
        self.normal == Rgb::ZERO && self.grazing == Rgb::ZERO
    }
}

/// A microfacet normal drawn from the normals that `v` (local, v.z > 0)
/// sees, by Heitz's 2018 method: stretch the view to the hemisphere
/// configuration, draw a point on the projected disk of that hemisphere,
/// lift it onto it, and unstretch. Its density is [`visible_normal_pdf`].
pub fn sample_visible_normal(v: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(alpha * v.x, alpha * v.y, v.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    // The half of the disk hidden behind the hemisphere's rim is squeezed
    // into the visible part.
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// The solid-angle density of [`sample_visible_normal`]'s normal `h`:
/// G1(v)·max(0, v·h)·D(h) / v.z.
#[inline]
pub fn visible_normal_pdf(v: Vec3, h: Vec3, alpha: f32) -> f32 {
    if v.z <= 0.0 {
        return 0.0;
    }
    masking(v.z, alpha) * v.dot(h).max(0.0) * distribution(h, alpha) / v.z
}

/// The mirror of `v` about the unit normal `h`.
#[inline]
pub fn reflect(v: Vec3, h: Vec3) -> Vec3 {
    2.0 * v.dot(h) * h - v
}

/// Points in the tables of [`SpecularAlbedo`], along each axis.
const TABLE_SIZE: usize = 32;

/// The directional albedo of the specular lobe alone, E(μ) = ∫ F·D·V·μᵢ dωᵢ,
/// for every [`Fresnel`] at once: F is linear in its two terms, so with
/// W(μ, α) = ∫ D·V·μᵢ dωᵢ and B(μ, α) = ∫ (1 − c)⁵·D·V·μᵢ dωᵢ, E is
/// normal·W plus grazing·B (the "split sum" of real-time rendering, Karis
/// 2013). Tabulated once over μ and √α, each entry from the visible normals
/// (G2/G1 per sample), with the averages W̄(α) = 2∫W μ dμ and B̄ likewise. The
/// metallic-roughness material scales its diffuse part by what the
/// specular lobe leaves (see [`super::MetallicRoughness`]).
pub struct SpecularAlbedo {
    /// (W, B) at μ = i/(N−1), √α = j/(N−1), row by row in α.
    at: Vec<Vec2>,
    /// (W̄, B̄) at √α = j/(N−1).
    average: Vec<Vec2>,
}

impl SpecularAlbedo {
    /// The table, computed on first use (about a million samples).
    pub fn get() -> &'static SpecularAlbedo {
        static TABLE: std::sync::OnceLock<SpecularAlbedo> = std::sync::OnceLock::new();
        TABLE.get_or_init(SpecularAlbedo::compute)
    }

    fn compute() -> SpecularAlbedo {
        const SIDE: usize = 32;
        let n = TABLE_SIZE;
        let mut at = Vec::with_capacity(n * n);
        for j in 0..n {
            let alpha = table_alpha(j);
            for i in 0..n {
                // μ = 0 sees nothing: its value is the limit, taken close by.
                let mu = (i as f32 / (n - 1) as f32).max(1e-3);
                let v = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let mut sum = glam::DVec2::ZERO;
                for s in 0..SIDE * SIDE {
                    let u = Vec2::new(((s % SIDE) as f32 + 0.5) / SIDE as f32, ((s / SIDE) as f32 + 0.5) / SIDE as f32);
                    let h = sample_visible_normal(v, alpha, u);
                    let l = reflect(v, h);
                    if l.z <= 0.0 {
                        continue;
                    }
                    // G2/G1 for the height-correlated G2.
                    let g = (1.0 + lambda(v.z, alpha)) / (1.0 + lambda(v.z, alpha) + lambda(l.z, alpha));
                    let m = (1.0 - v.dot(h)).clamp(0.0, 1.0);
                    let s5 = (m * m) * (m * m) * m;
                    sum += glam::DVec2::new(g as f64, (s5 * g) as f64);
                }
                at.push((sum / (SIDE * SIDE) as f64).as_vec2());
            }
        }
        // 2∫E μ dμ by the trapezoid rule over the table's own points.
        let average = (0..n)
            .map(|j| {
                let row = &at[j * n..(j + 1) * n];
                let h = 1.0 / (n - 1) as f32;
                let sum: Vec2 = (0..n)
                    .map(|i| {
                        let w = if i == 0 || i == n - 1 { 0.5 } else { 1.0 };
                        row[i] * (i as f32 * h) * w
                    })
                    .sum();
                2.0 * sum * h
            })
            .collect();
        SpecularAlbedo { at, average }
    }

    /// E(μ) for the reflectance `fresnel`, interpolated.
    pub fn albedo(&self, fresnel: Fresnel, mu: f32, alpha: f32) -> Rgb {
        let (j, fj) = alpha_coordinate(alpha);
        let x = mu.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
        let i = (x as usize).min(TABLE_SIZE - 2);
        let fi = x - i as f32;
        let row = |j: usize| {
            let r = &self.at[j * TABLE_SIZE..];
            r[i] * (1.0 - fi) + r[i + 1] * fi
        };
        let wb = row(j) * (1.0 - fj) + row(j + 1) * fj;
        fresnel.normal * wb.x + fresnel.grazing * wb.y
    }

    /// The cosine-weighted average 2∫E(μ) μ dμ for `fresnel`, interpolated.
    pub fn average(&self, fresnel: Fresnel, alpha: f32) -> Rgb {
        let (j, fj) = alpha_coordinate(alpha);
        let wb = self.average[j] * (1.0 - fj) + self.average[j + 1] * fj;
        fresnel.normal * wb.x + fresnel.grazing * wb.y
    }
}

/// The α of the table's row `j`: √α evenly spaced, the first at [`MIN_ALPHA`].
fn table_alpha(j: usize) -> f32 {
    let r = j as f32 / (TABLE_SIZE - 1) as f32;
    (r * r).max(MIN_ALPHA)
}

/// The row below `alpha` and the fraction of the way to the next.
fn alpha_coordinate(alpha: f32) -> (usize, f32) {
    let y = alpha.clamp(0.0, 1.0).sqrt() * (TABLE_SIZE - 1) as f32;
    let j = (y as usize).min(TABLE_SIZE - 2);
    (j, y - j as f32)
}

/// Pearson's χ² of `n` draws of `sample` (None: no direction) against
/// the solid-angle density `pdf` over the upper hemisphere, in cells of
/// (cos θ, φ) whose expected counts come from a 16×16 midpoint rule of
/// the density (dω = d cos θ dφ); cells expecting fewer than five draws
/// are left out. Returns the statistic and the cells counted.
#[cfg(test)]
pub(crate) fn chi_square_hemisphere(
    mut sample: impl FnMut() -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
    n: usize,
) -> (f64, usize) {
    let (rows, cols) = (10, 20);
    let mut counts = vec![0f64; rows * cols];
    for _ in 0..n {
        let Some(w) = sample() else { continue };
        let row = ((w.z.clamp(0.0, 1.0) * rows as f32) as usize).min(rows - 1);
        let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
        let col = ((phi / (2.0 * PI) * cols as f32) as usize).min(cols - 1);
        counts[row * cols + col] += 1.0;
    }
    let (mut chi2, mut cells) = (0.0, 0);
    let k = 16;
    let cell = (1.0 / rows as f64) * (2.0 * std::f64::consts::PI / cols as f64);
    for r in 0..rows {
        for c in 0..cols {
            let mut p = 0.0f64;
            for a in 0..k {
                for b in 0..k {
                    let z = (r as f32 + (a as f32 + 0.5) / k as f32) / rows as f32;
                    let phi = (c as f32 + (b as f32 + 0.5) / k as f32) / cols as f32 * 2.0 * PI;
                    let sin = (1.0 - z * z).sqrt();
                    p += pdf(Vec3::new(sin * phi.cos(), sin * phi.sin(), z)) as f64;
                }
            }
            let expected = p / (k * k) as f64 * cell * n as f64;
            if expected > 5.0 {
                chi2 += (counts[r * cols + c] - expected).powi(2) / expected;
                cells += 1;
            }
        }
    }
    (chi2, cells)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Sampler, uniform_sphere};

    fn upper(s: &mut Sampler) -> Vec3 {
        let mut w = uniform_sphere(s.next2());
        w.z = w.z.abs();
        w
    }

    #[test]
    fn the_distribution_projects_to_unit_area() {
        // ∫ D(h) h.z dω = 1, by uniform sampling of the hemisphere.
        let mut s = Sampler::for_pixel(1, 2, 3);
        for alpha in [0.1, 0.3, 0.7, 1.0] {
            let n = 400_000;
            let sum: f64 = (0..n).map(|_| upper(&mut s)).map(|h| (distribution(h, alpha) * h.z) as f64).sum();
            let integral = sum / n as f64 * 2.0 * std::f64::consts::PI;
            assert!((integral - 1.0).abs() < 0.03, "alpha {alpha}: {integral}");
        }
    }

    #[test]
    fn visible_normals_project_to_the_view() {
        // ∫ G1(v) max(0, v·h) D(h) dω = v.z (Heitz 2014, eq. 16): the
        // visible normals' density integrates to one.
        let mut s = Sampler::for_pixel(4, 5, 6);
        for (alpha, mu) in [(0.2f32, 0.9f32), (0.5, 0.4), (0.9, 0.15)] {
            let v = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let n = 400_000;
            let sum: f64 = (0..n).map(|_| upper(&mut s)).map(|h| visible_normal_pdf(v, h, alpha) as f64).sum();
            let integral = sum / n as f64 * 2.0 * std::f64::consts::PI;
            assert!((integral - 1.0).abs() < 0.03, "alpha {alpha}, mu {mu}: {integral}");
        }
    }

    #[test]
    fn sampled_visible_normals_follow_their_density() {
        let (alpha, v) = (0.4, Vec3::new(0.6, 0.0, 0.8));
        let mut s = Sampler::for_pixel(7, 8, 9);
        let (chi2, cells) = chi_square_hemisphere(
            || Some(sample_visible_normal(v, alpha, s.next2())),
            |h| visible_normal_pdf(v, h, alpha),
            200_000,
        );
        // The statistic's mean is about the number of cells; a sampler
        // off by a few per cent in one region lands in the thousands.
        assert!(cells > 100 && chi2 < 2.0 * cells as f64, "χ² {chi2} over {cells} cells");
    }

    #[test]
    fn the_specular_albedo_table_matches_direct_integration() {
        // E(μ) integrated over the hemisphere of light directions with the
        // BRDF written out (uniform sampling, no visible normals), against
        // the table, for a metal's F0 and a dielectric's.
        let table = SpecularAlbedo::get();
        let mut s = Sampler::for_pixel(11, 12, 13);
        for (alpha, mu) in [(0.3f32, 0.8f32), (0.6, 0.3), (1.0, 0.95)] {
            let v = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            for f0 in [Rgb::splat(0.04), Rgb::new(0.95, 0.64, 0.54)] {
                let n = 400_000;
                let mut sum = glam::DVec3::ZERO;
                for _ in 0..n {
                    let l = upper(&mut s);
                    let h = (v + l).normalize();
                    let f = schlick(f0, v.dot(h)) * distribution(h, alpha) * visibility(v.z, l.z, alpha) * l.z;
                    sum += f.as_dvec3();
                }
                let direct = (sum / n as f64 * 2.0 * std::f64::consts::PI).as_vec3();
                let tabled = table.albedo(Fresnel::schlick(f0), mu, alpha);
                assert!((direct - tabled).abs().max_element() < 0.015, "alpha {alpha} mu {mu}: {direct} vs {tabled}");
            }
        }
    }

    #[test]
    fn schlick_meets_f0_at_normal_incidence_and_one_at_grazing() {
        let f0 = Rgb::new(0.04, 0.5, 0.9);
        assert!((schlick(f0, 1.0) - f0).abs().max_element() < 1e-7);
        assert!((schlick(f0, 0.0) - Rgb::ONE).abs().max_element() < 1e-7);
    }
}
