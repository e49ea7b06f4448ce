//! Closed-form single-scatter airlight (issue 4), after Packard 2004 (the
//! seed `packard-2004-glowing-lights.txt`) and Sun, Ramamoorthi, Narasimhan
//! and Nayar 2005.
//!
//! Along a camera ray o + t·d the radiance is the surface term attenuated
//! by the transmittance, plus, for each point light of intensity I at P,
//!
//!   σs ∫_0^{t_end} e^{−σt t} · phase(t) · m(t) · I e^{−σt r(t)} / r(t)² dt,
//!
//! r(t) = |o + t d − P|. m(t) is 1 for a point light, the spot's falloff
//! for a spot light, the emission cosine for a point of a quad light, and 0
//! where the point is in shadow (with `shadows`). The ray is cut where m
//! jumps or its formula changes (spot cones, a quad light's plane, shadow
//! boundaries); on each piece:
//!
//! - when phase·m is constant (isotropic phase, inside a spot's inner cone,
//!   lit), the integral is exact: [`glow_vacuum`] (the seed's atan form) for
//!   σt = 0, [`Glow`] (Sun et al.'s F through the complex exponential
//!   integral) for σt > 0;
//! - otherwise (Henyey–Greenstein with g ≠ 0, a spot's soft edge, a quad
//!   light's cosine) the exact integral of the attenuation alone is
//!   multiplied by the mean of phase·m weighted by that attenuation, taken by
//!   16-point Gauss–Legendre in the angle θ = atan((t − h)/p), in panels of at
//!   most π/4 (the variable in which dt/r² = dθ/p is uniform). Measured
//!   against adaptive quadrature along 200 rays (σt = 0.13, tests/
//!   analytic_render.rs): worst relative error 1.2e-6 (g = 0.3), 1.7e-6
//!   (g = 0.6), 6.4e-6 (g = 0.9), 1.6e-5 (g = −0.7); isotropic pieces are
//!   exact. A soft spot edge, with 32768-step marching as reference, agrees
//!   to 1.4e-4 relative RMSE (the march's own error).
//!
//! Line and quad lights are sums of such point lights ([`LightQuadrature`],
//! `light_steps` points per dimension), as the seed superposes them. A fixed
//! set of points fails for rays that pass closer to the light than a few
//! point spacings (each point then shows its own glow), so per ray a piece
//! of the light that the ray passes close to is halved (line, up to 8
//! times) or quartered (quad, up to 3 times) and the rule applied on each
//! part: an adaptive composite rule, which leaves far rays with n points. A sphere light of radiance L and
//! radius R is, for points outside it, exactly a point light of intensity
//! πR²L at its centre (a Lambertian sphere's radiant intensity; exact for
//! isotropic scattering when the extinction along the different paths from
//! its surface is neglected, O(σt R)).

mod boundaries;
mod closed_form;
mod expint;
mod quadrature;

pub use boundaries::{
    box_boundaries, box_edges, cone_crossings, edge_boundaries, plane_boundaries,
    polygon_boundaries, quadratic_roots, sphere_boundaries,
};
pub use closed_form::{
    Glow, P_FLOOR, glow_extinction, glow_vacuum, glow_vacuum_f32, seed_coordinates, sun_f,
};
pub use expint::{Complex, scaled_e1};
pub use quadrature::Rule;

use super::{Integrator, surface_radiance};
use crate::Rgb;
use crate::geometry::{Occluder, Ray};
use crate::light::{Light, SpotProfile, spot_falloff};
use crate::medium::{Density, Medium, henyey_greenstein};
use crate::sampling::Sampler;
use crate::scene::{RenderSettings, Scene};
use glam::{DAffine3, DMat3, DVec3, Vec3};
use serde::Deserialize;
use std::f64::consts::FRAC_PI_4;

/// How the points of a line or quad light are placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightQuadrature {
    /// Gauss–Legendre nodes and weights along each edge.
    #[default]
    Gauss,
    /// The seed's uniform stepping: the middles of equal cells, equal weights.
    Uniform,
}

/// The analytic integrator's settings (`[render]` shadows, light_steps,
/// light_quadrature).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalyticOptions {
    pub shadows: bool,
    pub light_steps: u32,
    pub quadrature: LightQuadrature,
}

impl AnalyticOptions {
    pub fn from_settings(s: &RenderSettings) -> Self {
        AnalyticOptions {
            shadows: s.shadows,
            light_steps: s.light_steps,
            quadrature: s.light_quadrature,
        }
    }
}

/// How a point emitter's intensity varies with direction.
#[derive(Clone, Copy, Debug)]
enum Emission {
    Isotropic,
    Spot {
        axis: DVec3,
        cos_outer: f64,
        cos_inner: f64,
        cone: f32,
        start: f32,
        profile: SpotProfile,
    },
    /// A point of a one-sided Lambertian emitter: intensity × cos of the
    /// angle to `normal`, zero behind.
    Cosine {
        normal: DVec3,
    },
    /// The centre of a sphere light of this radius, with intensity πR²L: see
    /// [`sphere_factor`] for the near-field correction.
    Sphere {
        radius: f64,
    },
}

/// A point light, or one point of a line, quad or sphere light.
#[derive(Clone, Copy, Debug)]
struct PointEmitter {
    position: DVec3,
    /// W/sr (for `Cosine`, along the normal).
    intensity: DVec3,
    emission: Emission,
    /// Index of the scene light it belongs to (its own surface casts no shadow).
    light: u32,
    /// Shadow rays stop this far short of `position` (a sphere light's radius).
    gap: f64,
}

/// A line or quad light: its points are chosen per ray.
#[derive(Clone, Copy, Debug)]
enum Extended {
    Line {
        start: DVec3,
        end: DVec3,
        /// intensity per unit length × length, W/sr.
        intensity: DVec3,
        light: u32,
    },
    Quad {
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
        normal: DVec3,
        /// radiance × area: the intensity along the normal, W/sr.
        intensity: DVec3,
        light: u32,
    },
}

impl Extended {
    fn intensity(&self) -> DVec3 {
        match *self {
            Extended::Line { intensity, .. } | Extended::Quad { intensity, .. } => intensity,
        }
    }
}

/// How many times a line light's piece may be halved for one ray.
const MAX_LINE_SPLITS: u32 = 8;
/// How many times a quad light's piece may be quartered for one ray.
const MAX_QUAD_SPLITS: u32 = 5;

/// The closed-form airlight integrator (see the module documentation).
pub struct Analytic {
    pub options: AnalyticOptions,
    emitters: Vec<PointEmitter>,
    /// Line and quad lights, superposed per ray.
    extended: Vec<Extended>,
    /// The rule over each piece of a line or quad light, on [0, 1].
    rule: Rule,
    /// Whether some occluder is a triangle: shadow boundaries on meshes are
    /// bracketed by a coarse march and refined by bisection.
    meshes: bool,
}

/// Coarse march samples per ray for shadow boundaries on meshes.
pub const MESH_MARCH_STEPS: usize = 64;
/// Bisection steps refining each boundary found by the march.
const BISECTIONS: usize = 40;
/// Gauss–Legendre points per panel for a non-constant phase or emission.
const MODULATED_POINTS: usize = 16;

impl Analytic {
    /// The integrator for `scene`, or why it cannot render it: the medium
    /// must be homogeneous, and distant lights have no closed form here.
    pub fn new(scene: &Scene, options: AnalyticOptions) -> Result<Analytic, String> {
        let in_medium = scene
            .medium
            .as_ref()
            .is_some_and(|m| m.sigma_s != Rgb::ZERO);
        if let Some(m) = &scene.medium
            && let Density::Height { .. } = m.density
        {
            return Err("the analytic integrator needs a homogeneous medium; \
                        this scene's is height fog: use raymarch"
                .into());
        }
        if options.light_steps == 0 {
            return Err("light_steps must be at least 1".into());
        }
        let n = options.light_steps as usize;
        let rule = match options.quadrature {
            LightQuadrature::Gauss => Rule::gauss_legendre(n),
            LightQuadrature::Uniform => Rule::uniform(n),
        };
        let mut emitters = Vec::new();
        let mut extended = Vec::new();
        for (i, light) in scene.lights.iter().enumerate() {
            let index = i as u32;
            let point = |position: Vec3, intensity: Rgb, emission, gap| PointEmitter {
                position: position.as_dvec3(),
                intensity: intensity.as_dvec3(),
                emission,
                light: index,
                gap,
            };
            match *light {
                Light::Point {
                    position,
                    intensity,
                } => emitters.push(point(position, intensity, Emission::Isotropic, 0.0)),
                Light::Spot {
                    position,
                    direction,
                    intensity,
                    cone_angle,
                    falloff_start,
                    profile,
                } => emitters.push(point(
                    position,
                    intensity,
                    Emission::Spot {
                        axis: direction.as_dvec3().normalize(),
                        cos_outer: (cone_angle as f64).cos(),
                        cos_inner: (falloff_start as f64).cos(),
                        cone: cone_angle,
                        start: falloff_start,
                        profile,
                    },
                    0.0,
                )),
                Light::Sphere {
                    center,
                    radius,
                    radiance,
                } => emitters.push(point(
                    center,
                    radiance * (std::f32::consts::PI * radius * radius),
                    Emission::Sphere {
                        radius: radius as f64,
                    },
                    radius as f64,
                )),
                Light::Line {
                    start,
                    end,
                    intensity,
                } => {
                    let (a, b) = (start.as_dvec3(), end.as_dvec3());
                    extended.push(Extended::Line {
                        start: a,
                        end: b,
                        intensity: intensity.as_dvec3() * (b - a).length(),
                        light: index,
                    });
                }
                Light::Quad {
                    corner,
                    edge_u,
                    edge_v,
                    radiance,
                } => {
                    let (u, v) = (edge_u.as_dvec3(), edge_v.as_dvec3());
                    let n = u.cross(v);
                    // dI = L cos θ dA: the intensity along the normal is L·A.
                    extended.push(Extended::Quad {
                        corner: corner.as_dvec3(),
                        edge_u: u,
                        edge_v: v,
                        normal: n.normalize(),
                        intensity: radiance.as_dvec3() * n.length(),
                        light: index,
                    });
                }
                Light::Distant { .. } => {
                    if in_medium {
                        return Err(format!(
                            "the analytic integrator has no closed form for the light a distant \
                             light (lights[{i}]) scatters in a medium: use raymarch"
                        ));
                    }
                }
            }
        }
        emitters.retain(|e| e.intensity != DVec3::ZERO);
        extended.retain(|e| e.intensity() != DVec3::ZERO);
        let meshes = scene
            .geometry
            .occluders()
            .any(|(o, _)| matches!(o, Occluder::Triangle { .. }));
        Ok(Analytic {
            options,
            emitters,
            extended,
            rule,
            meshes,
        })
    }

    /// Single-scattered radiance along `ray` over [0, t_end] from all lights.
    pub fn in_scattered(&self, scene: &Scene, medium: &Medium, ray: &Ray, t_end: f32) -> Rgb {
        if medium.sigma_s == Rgb::ZERO || t_end.is_nan() || t_end <= 0.0 {
            return Rgb::ZERO;
        }
        let o = ray.origin.as_dvec3();
        let d = ray.dir.as_dvec3().normalize();
        let consts = MediumConsts::new(medium);
        let mut scratch = Scratch::default();
        let mut total = DVec3::ZERO;
        let t_end = t_end as f64;
        for e in &self.emitters {
            total += self.emitter_light(scene, &consts, o, d, t_end, e, &mut scratch);
        }
        for x in &self.extended {
            let mut each = |e: &PointEmitter| {
                total += self.emitter_light(scene, &consts, o, d, t_end, e, &mut scratch);
            };
            match *x {
                Extended::Line {
                    start,
                    end,
                    intensity,
                    light,
                } => self.line_pieces(o, d, t_end, (start, end), intensity, light, 0, &mut each),
                Extended::Quad {
                    corner,
                    edge_u,
                    edge_v,
                    normal,
                    intensity,
                    light,
                } => self.quad_pieces(
                    o,
                    d,
                    t_end,
                    (corner, edge_u, edge_v),
                    normal,
                    intensity,
                    light,
                    0,
                    &mut each,
                ),
            }
        }
        (total * medium.sigma_s.as_dvec3()).as_vec3()
    }

    /// Whether a piece of a light with centre `c` and half-size `half`
    /// must be split for the ray segment o + t d, t in [0, t_end]: when the
    /// segment passes closer to the piece than 8·half/n (n = light_steps).
    /// An n-point Gauss–Legendre rule on an interval of half-length L
    /// converges like ρ^(−2n) for a kernel whose singularity lies at
    /// distance δ from it, ρ = δ/L + √(1 + δ²/L²); δ ≥ 8L/n keeps ρ^(−2n)
    /// below about 1e-6 for every n, and for the uniform rule it keeps the
    /// ray several point spacings away. A rule of n > 16 points splits
    /// log2(n/16) times fewer.
    #[allow(clippy::too_many_arguments)]
    fn must_split(
        &self,
        o: DVec3,
        d: DVec3,
        t_end: f64,
        c: DVec3,
        half: f64,
        depth: u32,
        max: u32,
    ) -> bool {
        if depth >= max {
            return false;
        }
        let t = d.dot(c - o).clamp(0.0, t_end);
        let gap = (o + d * t - c).length() - half;
        gap < 8.0 * half / self.rule.nodes.len() as f64
    }

    /// The points of a piece [a, b] of a line light, split where the ray
    /// passes close (see must_split).
    #[allow(clippy::too_many_arguments)]
    fn line_pieces(
        &self,
        o: DVec3,
        d: DVec3,
        t_end: f64,
        (a, b): (DVec3, DVec3),
        intensity: DVec3,
        light: u32,
        depth: u32,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let half = 0.5 * (b - a).length();
        if self.must_split(o, d, t_end, 0.5 * (a + b), half, depth, MAX_LINE_SPLITS) {
            let m = 0.5 * (a + b);
            self.line_pieces(o, d, t_end, (a, m), intensity * 0.5, light, depth + 1, each);
            self.line_pieces(o, d, t_end, (m, b), intensity * 0.5, light, depth + 1, each);
            return;
        }
        for (x, w) in self.rule.nodes.iter().zip(&self.rule.weights) {
            each(&PointEmitter {
                position: a + (b - a) * *x,
                intensity: intensity * *w,
                emission: Emission::Isotropic,
                light,
                gap: 0.0,
            });
        }
    }

    /// The points of a piece of a quad light (corner, edges), split in four
    /// where the ray passes close.
    #[allow(clippy::too_many_arguments)]
    fn quad_pieces(
        &self,
        o: DVec3,
        d: DVec3,
        t_end: f64,
        (c, u, v): (DVec3, DVec3, DVec3),
        normal: DVec3,
        intensity: DVec3,
        light: u32,
        depth: u32,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let half = 0.5 * (u + v).length().max((u - v).length());
        if self.must_split(o, d, t_end, c + 0.5 * (u + v), half, depth, MAX_QUAD_SPLITS) {
            let (hu, hv) = (0.5 * u, 0.5 * v);
            for corner in [c, c + hu, c + hv, c + hu + hv] {
                self.quad_pieces(
                    o,
                    d,
                    t_end,
                    (corner, hu, hv),
                    normal,
                    intensity * 0.25,
                    light,
                    depth + 1,
                    each,
                );
            }
            return;
        }
        let rule = &self.rule;
        for (x, wx) in rule.nodes.iter().zip(&rule.weights) {
            for (y, wy) in rule.nodes.iter().zip(&rule.weights) {
                each(&PointEmitter {
                    position: c + u * *x + v * *y,
                    intensity: intensity * (wx * wy),
                    emission: Emission::Cosine { normal },
                    light,
                    gap: 0.0,
                });
            }
        }
    }

    /// ∫ e^{−σt (t + r)} · phase · m / r² dt · I over [0, t_end], per channel.
    #[allow(clippy::too_many_arguments)]
    fn emitter_light(
        &self,
        scene: &Scene,
        k: &MediumConsts,
        o: DVec3,
        d: DVec3,
        t_end: f64,
        e: &PointEmitter,
        s: &mut Scratch,
    ) -> DVec3 {
        let p = e.position;
        let glows: [Glow; 3] = std::array::from_fn(|c| Glow::new(k.sigma_t[c], p, o, d, t_end));
        let range = (0.0, t_end);
        s.cuts.clear();
        s.cuts.push(0.0);
        s.cuts.push(t_end);
        match e.emission {
            Emission::Isotropic | Emission::Sphere { .. } => {}
            Emission::Spot {
                axis,
                cos_outer,
                cos_inner,
                cone,
                start,
                ..
            } => {
                cone_crossings(p, axis, cos_outer, o, d, range, &mut s.cuts);
                if start > 0.0 && start < cone {
                    cone_crossings(p, axis, cos_inner, o, d, range, &mut s.cuts);
                }
            }
            Emission::Cosine { normal } => {
                plane_boundaries(p, normal, o, d, range, &mut s.cuts);
            }
        }
        if self.options.shadows {
            self.shadow_boundaries(scene, e, o, d, range, &mut s.cuts);
        }
        s.cuts.sort_unstable_by(f64::total_cmp);
        s.cuts.dedup_by(|a, b| *a - *b <= 1e-12 * t_end);
        s.k.clear();
        s.k.resize(s.cuts.len(), [f64::NAN; 3]);
        let mut sum = DVec3::ZERO;
        for i in 0..s.cuts.len() - 1 {
            let (ta, tb) = (s.cuts[i], s.cuts[i + 1]);
            if tb <= ta {
                continue;
            }
            let x = o + d * (0.5 * (ta + tb));
            let Some(constant) = self.modulation_class(scene, k, x, e) else {
                continue;
            };
            let mut piece = [0.0; 3];
            for c in 0..k.channels {
                let g = &glows[c];
                if g.sigma_t > 0.0 {
                    for j in [i, i + 1] {
                        if s.k[j][c].is_nan() {
                            s.k[j][c] = g.antiderivative(s.cuts[j]);
                        }
                    }
                }
                piece[c] = g.between_with(ta, tb, s.k[i][c], s.k[i + 1][c]);
            }
            let factor = match constant {
                Some(m) => [m; 3],
                None => self.weighted_mean(k, &glows, o, d, ta, tb, e),
            };
            for c in 0..3 {
                let from = c.min(k.channels - 1);
                sum[c] += piece[from] * factor[from];
            }
        }
        sum * e.intensity
    }

    /// What multiplies the attenuation on the piece around `x`: None if the
    /// piece is dark (outside a spot's cone, behind a quad light, in shadow),
    /// Some(Some(m)) if phase·m is the constant m there, Some(None) if it
    /// varies (weighted_mean takes it).
    fn modulation_class(
        &self,
        scene: &Scene,
        k: &MediumConsts,
        x: DVec3,
        e: &PointEmitter,
    ) -> Option<Option<f64>> {
        let to = e.position - x;
        let dist = to.length();
        if dist == 0.0 {
            return None;
        }
        let wi = to / dist;
        let mut varies = k.g != 0.0;
        match e.emission {
            Emission::Isotropic => {}
            Emission::Spot { .. } => {
                let f = emission_factor(&e.emission, wi);
                if f <= 0.0 {
                    return None;
                }
                varies |= f < 1.0;
            }
            Emission::Cosine { .. } => {
                if emission_factor(&e.emission, wi) <= 0.0 {
                    return None;
                }
                varies = true;
            }
            Emission::Sphere { .. } => varies = true,
        }
        if self.options.shadows && !visible(scene, x, e) {
            return None;
        }
        Some(if varies {
            None
        } else {
            Some(henyey_greenstein(0.0, 0.0) as f64)
        })
    }

    /// Σ w e(θ) m(θ) / Σ w e(θ) over [ta, tb] per channel, with e the
    /// attenuation e^{−σt (t + r)} and m = phase · emission factor, by
    /// Gauss–Legendre in θ in panels of at most π/4.
    #[allow(clippy::too_many_arguments)]
    fn weighted_mean(
        &self,
        k: &MediumConsts,
        glows: &[Glow; 3],
        o: DVec3,
        d: DVec3,
        ta: f64,
        tb: f64,
        e: &PointEmitter,
    ) -> [f64; 3] {
        let g0 = &glows[0];
        let (a, b) = (g0.angle(ta), g0.angle(tb));
        let panels = ((b - a) / FRAC_PI_4).ceil().max(1.0) as usize;
        let width = (b - a) / panels as f64;
        let rule = quadrature::gl16();
        debug_assert_eq!(rule.nodes.len(), MODULATED_POINTS);
        let (mut num, mut den) = ([0.0; 3], [0.0; 3]);
        for panel in 0..panels {
            let start = a + width * panel as f64;
            for (x, w) in rule.nodes.iter().zip(&rule.weights) {
                let theta = start + width * x;
                let t = g0.t_at_angle(theta);
                let to = e.position - (o + d * t);
                let wi = to.normalize();
                let phase = henyey_greenstein((-d).dot(wi) as f32, k.g) as f64;
                let m = phase * emission_factor(&e.emission, wi);
                for c in 0..k.channels {
                    let att = if glows[c].sigma_t > 0.0 {
                        glows[c].attenuation_at_angle(theta)
                    } else {
                        1.0
                    };
                    let m = match e.emission {
                        Emission::Sphere { radius } => {
                            m * sphere_factor(to.length(), radius, glows[c].sigma_t)
                        }
                        _ => m,
                    };
                    num[c] += w * att * m;
                    den[c] += w * att;
                }
            }
        }
        std::array::from_fn(|c| if den[c] > 0.0 { num[c] / den[c] } else { 0.0 })
    }

    /// Adds the ray parameters where the light's visibility may change.
    fn shadow_boundaries(
        &self,
        scene: &Scene,
        e: &PointEmitter,
        o: DVec3,
        d: DVec3,
        range: (f64, f64),
        out: &mut Vec<f64>,
    ) {
        let p = e.position;
        for (occluder, emitter) in scene.geometry.occluders() {
            if emitter == Some(e.light) {
                continue;
            }
            match occluder {
                Occluder::Sphere { center, radius } => {
                    sphere_boundaries(p, center.as_dvec3(), radius as f64, o, d, range, out)
                }
                Occluder::Box { min, max } => {
                    box_boundaries(p, min.as_dvec3(), max.as_dvec3(), o, d, range, out)
                }
                Occluder::Quad {
                    corner,
                    edge_u,
                    edge_v,
                } => {
                    let (c, u, v) = (corner.as_dvec3(), edge_u.as_dvec3(), edge_v.as_dvec3());
                    polygon_boundaries(p, &[c, c + u, c + u + v, c + v], o, d, range, out)
                }
                Occluder::Plane { point, normal } => {
                    plane_boundaries(point.as_dvec3(), normal.as_dvec3(), o, d, range, out)
                }
                Occluder::InstancedSphere {
                    local_from_world,
                    center,
                    radius,
                } => {
                    let m = to_f64(&local_from_world);
                    let (lp, lo, ld) = (
                        m.transform_point3(p),
                        m.transform_point3(o),
                        m.transform_vector3(d),
                    );
                    sphere_boundaries(lp, center.as_dvec3(), radius as f64, lo, ld, range, out)
                }
                Occluder::InstancedBox {
                    local_from_world,
                    min,
                    max,
                } => {
                    let m = to_f64(&local_from_world);
                    let (lp, lo, ld) = (
                        m.transform_point3(p),
                        m.transform_point3(o),
                        m.transform_vector3(d),
                    );
                    box_boundaries(lp, min.as_dvec3(), max.as_dvec3(), lo, ld, range, out)
                }
                // Meshes: below, by marching.
                Occluder::Triangle { .. } => {}
            }
        }
        if self.meshes {
            march_boundaries(scene, e, o, d, range, out);
        }
    }
}

/// Brackets visibility changes with MESH_MARCH_STEPS samples at the middles
/// of equal steps, then bisects each bracket. A shadow thinner than a step
/// can be missed; every boundary found is exact to 2^−40 of a step.
fn march_boundaries(
    scene: &Scene,
    e: &PointEmitter,
    o: DVec3,
    d: DVec3,
    (t0, t1): (f64, f64),
    out: &mut Vec<f64>,
) {
    let n = MESH_MARCH_STEPS;
    let dt = (t1 - t0) / n as f64;
    let sees = |t: f64| visible(scene, o + d * t, e);
    let mut prev_t = t0 + 0.5 * dt;
    let mut prev = sees(prev_t);
    for i in 1..n {
        let t = t0 + (i as f64 + 0.5) * dt;
        let v = sees(t);
        if v != prev {
            let (mut lo, mut hi) = (prev_t, t);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if sees(mid) == prev {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            out.push(0.5 * (lo + hi));
        }
        prev = v;
        prev_t = t;
    }
}

/// Whether `x` sees the emitter: one shadow ray, stopping short of it.
fn visible(scene: &Scene, x: DVec3, e: &PointEmitter) -> bool {
    let to = e.position - x;
    let dist = to.length();
    let reach = (dist - e.gap) * (1.0 - 1e-4);
    if reach.is_nan() || reach <= 0.0 {
        return true;
    }
    !scene
        .geometry
        .occluded(x.as_vec3(), (to / dist).as_vec3(), reach as f32)
}

/// The emitter's intensity factor toward −wi (wi: unit, from the point to
/// the emitter): the spot's falloff, the cosine of a quad light, or 1.
fn emission_factor(emission: &Emission, wi: DVec3) -> f64 {
    match *emission {
        Emission::Isotropic => 1.0,
        Emission::Spot {
            axis,
            cos_outer,
            cos_inner,
            cone,
            start,
            profile,
        } => {
            let cos = -wi.dot(axis);
            if cos < cos_outer {
                0.0
            } else if cos >= cos_inner {
                1.0
            } else {
                spot_falloff(profile, cos as f32, cone, start) as f64
            }
        }
        Emission::Cosine { normal } => (-wi.dot(normal)).max(0.0),
        Emission::Sphere { .. } => 1.0,
    }
}

/// The light a sphere light (radius R, radiance L) sends to a point at
/// distance r from its centre, over that of a point light of intensity πR²L
/// at the centre, e^{−σt r}·πR²L/r²: with ℓ(α) = r cos α − √(R² − r² sin²α)
/// the distance to the sphere along a direction at angle α from the centre's,
///
///   f = ∫_{cos θmax}^1 e^{−σt (ℓ − r)} 2π dμ / (π R² / r²),  μ = cos α, sin θmax = R/r.
///
/// Without extinction f = 2 (1 − cos θmax) r²/R² = 2 / (1 + cos θmax): the
/// fluence of a sphere, which an isotropic medium scatters, exceeds the
/// point light's by up to 2× next to the surface; f → 1 far away. With
/// extinction the path from the sphere's near side is shorter than r, by
/// about R. The μ integral is taken by 8-point Gauss–Legendre (it has a
/// square-root end at the tangent; the error is O((σt R)² / 64)). The phase
/// function is taken along the direction to the centre.
pub fn sphere_factor(r: f64, radius: f64, sigma_t: f64) -> f64 {
    let sin2 = (radius * radius / (r * r)).min(1.0);
    let cos_max = (1.0 - sin2).sqrt();
    if sigma_t == 0.0 {
        return 2.0 / (1.0 + cos_max);
    }
    let rule = quadrature::gl8();
    let mut sum = 0.0;
    for (x, w) in rule.nodes.iter().zip(&rule.weights) {
        let mu = cos_max + (1.0 - cos_max) * x;
        let along = r * mu - (radius * radius - r * r * (1.0 - mu * mu)).max(0.0).sqrt();
        sum += w * (-sigma_t * (along - r)).exp();
    }
    // ∫ dμ = (1 − cos θmax) · mean; divide by R²/(2 r²).
    sum * (1.0 - cos_max) * 2.0 / sin2
}

fn to_f64(m: &glam::Affine3A) -> DAffine3 {
    DAffine3 {
        matrix3: DMat3::from_cols(
            m.matrix3.x_axis.as_dvec3(),
            m.matrix3.y_axis.as_dvec3(),
            m.matrix3.z_axis.as_dvec3(),
        ),
        translation: m.translation.as_dvec3(),
    }
}

/// The medium's numbers in f64; `channels` is 1 when σt is grey.
struct MediumConsts {
    sigma_t: [f64; 3],
    channels: usize,
    g: f32,
}

impl MediumConsts {
    fn new(m: &Medium) -> Self {
        let st = m.sigma_t().as_dvec3();
        let grey = st.x == st.y && st.y == st.z;
        MediumConsts {
            sigma_t: [st.x, st.y, st.z],
            channels: if grey { 1 } else { 3 },
            g: m.g,
        }
    }
}

#[derive(Default)]
struct Scratch {
    cuts: Vec<f64>,
    k: Vec<[f64; 3]>,
}

impl Integrator for Analytic {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        let hit = scene.geometry.intersect(ray, f32::INFINITY);
        let (surface, t_end) = match hit {
            Some(hit) => {
                let s = scene.geometry.surface(ray, hit);
                (
                    surface_radiance(scene, ray, &s, sampler, scene.medium.as_ref()),
                    hit.t,
                )
            }
            None => (scene.settings.background, scene.settings.max_distance),
        };
        let Some(medium) = &scene.medium else {
            return surface;
        };
        let through = medium.transmittance(ray.origin, ray.dir, 0.0, t_end);
        // As raymarch: the medium is integrated up to max_distance at most.
        let end = t_end.min(scene.settings.max_distance);
        surface * through + self.in_scattered(scene, medium, ray, end)
    }
}
