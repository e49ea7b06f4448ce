//! The benchmark's converged reference, independent of the analytic
//! integrator's closed forms: the single-scatter integral along each camera
//! ray by adaptive Gauss–Kronrod quadrature (7/15 points), with the
//! integrand written out as the physics states it, in f64:
//!
//!   L_medium = ∫_0^{t_end} e^{−σt t} σs Σ_lights phase · I e^{−σt r} / r² · V dt,
//!
//! r the distance to the (point) light and V its visibility by a shadow ray
//! through the scene's BVH (as `raymarch` casts them). The surface term is
//! the one every integrator shares (`single_scattering, no_extra`, attenuated by
//! e^{−σt t_end}). No sampling: the same camera ray as the other
//! integrators (1 spp, same seed), integrated to a relative tolerance.
//!
//! The ray is first cut at the points closest to each light (where a glow
//! peaks) and into `START` equal pieces; a piece is accepted when the
//! Kronrod and Gauss estimates differ by at most tol · I · max(w / T, 1e-3)
//! (I the ray's first estimate, w the piece's length, T the ray's), else
//! halved, down to pieces of 1e-7 T (below f32's resolution of t). Shadow
//! boundaries are found by this halving, not by formula.

use airlight::Rgb;
use airlight::geometry::Ray;
use airlight::integrator::{Integrator, no_extra, single_scattering};
use airlight::light::Light;
use airlight::medium::henyey_greenstein;
use airlight::sampling::Sampler;
use airlight::scene::Scene;
use glam::DVec3;

/// Equal pieces the ray starts from.
const START: usize = 16;

/// Gauss–Kronrod 15-point nodes on [−1, 1] (non-negative half, decreasing;
/// the odd ones, 1, 3, 5, 7, are the 7-point Gauss nodes) and weights.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// 7-point Gauss weights at XGK[1], XGK[3], XGK[5], XGK[7].
const WG: [f64; 4] =
    [0.129_484_966_168_869_7, 0.279_705_391_489_276_7, 0.381_830_050_505_118_9, 0.417_959_183_673_469_4];

/// Checks the rule: Kronrod exact to degree 22, Gauss to degree 13.
pub fn check_rule() {
    for k in 0..=22 {
        let exact = if k % 2 == 1 { 0.0 } else { 2.0 / (k as f64 + 1.0) };
        let (kr, g) = gk(|x| DVec3::splat(x.powi(k)), -1.0, 1.0);
        assert!((kr.x - exact).abs() < 1e-14, "Kronrod, degree {k}: {} vs {exact}", kr.x);
        if k <= 13 {
            assert!((g.x - exact).abs() < 1e-14, "Gauss, degree {k}: {} vs {exact}", g.x);
        }
    }
}

/// (Kronrod, Gauss) estimates of ∫_a^b f.
fn gk(f: impl Fn(f64) -> DVec3, a: f64, b: f64) -> (DVec3, DVec3) {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mid = f(c);
    let (mut k, mut g) = (mid * WGK[7], mid * WG[3]);
    for i in 0..7 {
        let s = f(c - h * XGK[i]) + f(c + h * XGK[i]);
        k += s * WGK[i];
        if i % 2 == 1 {
            g += s * WG[i / 2];
        }
    }
    (k * h, g * h)
}

/// The reference integrator (see the module documentation).
pub struct Reference {
    /// Relative tolerance on the ray's in-scattered radiance.
    pub tol: f64,
}

struct PointSource {
    position: DVec3,
    intensity: DVec3,
}

impl Reference {
    fn in_scattered(&self, scene: &Scene, ray: &Ray, t_end: f64) -> DVec3 {
        let medium = scene.medium().unwrap();
        let sigma_t = medium.sigma_t().as_dvec3();
        let sigma_s = medium.sigma_s.as_dvec3();
        let lights: Vec<PointSource> = scene
            .lights()
            .iter()
            .map(|l| match *l {
                Light::Point { position, intensity, .. } => {
                    PointSource { position: position.as_dvec3(), intensity: intensity.as_dvec3() }
                }
                _ => panic!("the reference integrates point lights only"),
            })
            .collect();
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3().normalize());
        let f = |t: f64| {
            let x = o + d * t;
            let mut sum = DVec3::ZERO;
            for l in &lights {
                let to = l.position - x;
                let r2 = to.length_squared();
                let r = r2.sqrt();
                let wi = to / r;
                let (xf, wf) = (x.as_vec3(), wi.as_vec3());
                if scene.geometry().occluded(xf, wf, (r * (1.0 - 1e-4)) as f32) {
                    continue;
                }
                let phase = henyey_greenstein((-d).dot(wi) as f32, medium.g) as f64;
                let att = DVec3::new((-sigma_t.x * r).exp(), (-sigma_t.y * r).exp(), (-sigma_t.z * r).exp());
                sum += l.intensity * att * (phase / r2);
            }
            let eye = DVec3::new((-sigma_t.x * t).exp(), (-sigma_t.y * t).exp(), (-sigma_t.z * t).exp());
            sum * eye * sigma_s
        };
        // First pieces: the lights' closest points and START equal parts.
        let mut cuts: Vec<f64> = (0..=START).map(|i| t_end * i as f64 / START as f64).collect();
        for l in &lights {
            let h = d.dot(l.position - o);
            if h > 0.0 && h < t_end {
                cuts.push(h);
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let mut stack: Vec<(f64, f64, DVec3, DVec3)> = Vec::new();
        let mut first = DVec3::ZERO;
        for w in cuts.windows(2) {
            let (k, g) = gk(f, w[0], w[1]);
            first += k;
            stack.push((w[0], w[1], k, g));
        }
        let scale = first.element_sum().abs().max(1e-300);
        let mut total = DVec3::ZERO;
        while let Some((a, b, k, g)) = stack.pop() {
            let w = b - a;
            let allowed = self.tol * scale * (w / t_end).max(1e-3);
            if (k - g).abs().element_sum() <= allowed || w <= 1e-7 * t_end {
                total += k;
                continue;
            }
            let m = 0.5 * (a + b);
            let (k1, g1) = gk(f, a, m);
            let (k2, g2) = gk(f, m, b);
            stack.push((a, m, k1, g1));
            stack.push((m, b, k2, g2));
        }
        total
    }
}

impl Integrator for Reference {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        single_scattering(scene, ray, sampler, no_extra, |_, length, _| {
            if length <= 0.0 { Rgb::ZERO } else { self.in_scattered(scene, ray, length as f64).as_vec3() }
        })
    }
}
