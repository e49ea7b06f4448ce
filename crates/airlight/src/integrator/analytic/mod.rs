//! Closed-form single-scatter airlight, after Packard 2004 (the
//! seed: Packard, "Efficient Rendering of Glowing Lights", 2004) and Sun, Ramamoorthi, Narasimhan
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
//!   lit), the integral is exact: [`glow_vacuum`] (Packard's atan form) for
//!   σt = 0, [`Glow`] (Sun et al.'s F through the complex exponential
//!   integral) for σt > 0. The renderer reads Im S = Im e^z E₁(z), the one
//!   special function in it, from a table (as Sun et al. tabulate F; see
//!   table.rs: relative error ≤ [`TABLE_ERROR`] = 2e-7), once per piece
//!   boundary for all three channels when σt is grey; the public closed
//!   forms ([`Glow::between`], [`glow_extinction`], [`sun_f`]) stay exact;
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
//! `light_steps` points per dimension), as Packard superposes them. A fixed
//! set of points fails for rays that pass closer to the light than a few
//! point spacings (each point then shows its own glow), so per ray a piece
//! of the light that the ray passes close to is halved (line, up to 8
//! times) or quartered (quad and triangle, up to 5 times) and the rule applied on each
//! part: an adaptive composite rule, which leaves far rays with n points.
//! A sphere light of radiance L and
//! radius R is, for points outside it, a point light of intensity
//! πR²L at its centre (a Lambertian sphere's radiant intensity), with a
//! factor for its near field ([`sphere_factor`]); exact for isotropic
//! scattering in vacuum, off by O(σt R) and, with g ≠ 0, by the phase taken
//! toward the centre. Where an occluder that can cast a penumbra comes
//! within [`NEAR_RADII`] radii of it (the point's hard shadows would
//! misplace the wide penumbrae there), it is a sum of Lambertian points on
//! its surface, like a quad light's (`light_steps`/2 points per dimension
//! in z and φ, split up to twice where a ray passes close).
//!
//! Shadows (`shadows = true`): each occluder's shadow along the ray is
//! found exactly, with no shadow rays, for any arrangement of lights,
//! camera and occluders (a light or the camera inside a box, a sphere or a
//! closed mesh, between planes): spheres, boxes, quads and planes from
//! their boundaries and one segment–surface test per piece (blockers.rs),
//! triangles by clipping the ray against each one's shadow volume, found
//! through a bounding volume hierarchy (triangles.rs); occluders whose
//! bounds cannot touch the triangle swept by the ray's shadow segments are
//! skipped (shadows.rs).
//!
//! What it refuses, with a message naming the light or object and the
//! integrator to use instead ([`Analytic::new`]): height fog (the closed form
//! needs a homogeneous medium), volume lights, distant lights in a medium,
//! lights with a real-time attenuation model other than `physical` (the
//! closed form integrates 1/r²), and when `shadows` is on SDF objects (they
//! have no exact shadow boundaries; without shadows they only end rays) and
//! sphere lights that a surface cuts through (see clearance.rs).

mod blockers;
mod boundaries;
mod clearance;
mod closed_form;
mod expint;
mod lights;
mod modulation;
mod quadrature;
mod shadows;
mod table;
mod triangles;

pub use boundaries::{
    box_boundaries, box_edges, cone_crossings, edge_boundaries, plane_boundaries, polygon_boundaries, quadratic_roots,
    sphere_boundaries,
};
pub use closed_form::{Glow, P_FLOOR, glow_extinction, glow_vacuum, glow_vacuum_f32, seed_coordinates, sun_f};
pub use expint::{Complex, scaled_e1};
pub use lights::{NEAR_RADII, sphere_factor};
pub use quadrature::Rule;
pub use table::{TABLE_ERROR, im_s as im_s_tabulated, sun_f_tabulated};

use blockers::Blocker;
use lights::{Extended, Share, SphereLight, ViewSegment};
use modulation::MediumConsts;
use shadows::in_intervals;
use triangles::MeshShadows;

use super::{Integrator, IntegratorError, IntegratorKind, RadianceParts, no_extra, single_scattering_parts};
use crate::Rgb;
use crate::geometry::Ray;
use crate::light::{AttenuationModel, Light, SpotProfile};
use crate::medium::{Density, Medium};
use crate::sampling::Sampler;
use crate::scene::Scene;
use glam::{DVec3, Vec3};

/// How the points of a line or quad light are placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LightQuadrature {
    /// Gauss–Legendre nodes and weights along each edge.
    #[default]
    Gauss,
    /// Packard's uniform stepping: the middles of equal cells, equal weights.
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

impl LightQuadrature {
    /// The name a scene file gives it.
    pub fn name(self) -> &'static str {
        match self {
            LightQuadrature::Gauss => "gauss",
            LightQuadrature::Uniform => "uniform",
        }
    }
}

impl std::str::FromStr for LightQuadrature {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "gauss" => Ok(LightQuadrature::Gauss),
            "uniform" => Ok(LightQuadrature::Uniform),
            _ => Err(format!("unknown light quadrature `{s}`; expected gauss or uniform")),
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

/// The closed-form airlight integrator (see the module documentation).
pub struct Analytic {
    pub options: AnalyticOptions,
    emitters: Vec<PointEmitter>,
    /// Line and quad lights, superposed per ray.
    extended: Vec<Extended>,
    /// The rule over each piece of a line or quad light, on [0, 1].
    rule: Rule,
    /// The rule over each piece of a sphere light's surface, in z and φ.
    sphere_rule: Rule,
    /// The occluders other than triangles, in f64 (for shadows).
    blockers: Vec<Blocker>,
    /// The meshes' triangles (for shadows).
    meshes: MeshShadows,
}

/// Gauss–Legendre points per panel for a non-constant phase or emission.
const MODULATED_POINTS: usize = 16;

impl Analytic {
    fn parts(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> RadianceParts {
        single_scattering_parts(scene, ray, sampler, no_extra, |medium, length, _| {
            self.in_scattered(scene, medium, ray, length)
        })
    }

    /// The integrator for `scene`, or why it cannot render it (a message for
    /// the user, never a panic): height fog, volume lights, distant lights
    /// in a medium, non-physical attenuation models, and with shadows SDF
    /// objects and sphere lights cut by a surface are refused (see the
    /// module documentation).
    pub fn new(scene: &Scene, options: AnalyticOptions) -> Result<Analytic, String> {
        let in_medium = scene.medium().is_some_and(|m| m.sigma_s != Rgb::ZERO);
        if options.shadows && scene.geometry().has_sdf() {
            return Err("the analytic integrator finds no exact shadow boundaries for SDF objects: \
                        use raymarch or stochastic, or render without shadows"
                .into());
        }
        if options.shadows && scene.has_cutouts() {
            return Err("the analytic integrator's exact shadow boundaries are the occluders' edges and cannot \
                        follow a texture's alpha (this scene has cut-out materials, glTF's alphaMode MASK or \
                        BLEND): use raymarch or stochastic, or render without shadows"
                .into());
        }
        if let Some(m) = scene.medium() {
            let kind = match m.density {
                Density::Homogeneous => None,
                Density::Height { .. } => Some("height fog"),
                Density::Grid(_) => Some("a density grid"),
                Density::Noise(_) => Some("noise fog"),
            };
            if let Some(kind) = kind {
                return Err(format!(
                    "the analytic integrator needs a homogeneous medium; this scene's is {kind}: use raymarch"
                ));
            }
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
        for (i, light) in scene.lights().iter().enumerate() {
            let index = i as u32;
            if let Some(a) = light.attenuation()
                && a.model != AttenuationModel::Physical
            {
                let name = match a.model {
                    AttenuationModel::Physical => "physical",
                    AttenuationModel::Sphere => "sphere",
                    AttenuationModel::Cutoff => "cutoff",
                    AttenuationModel::WindowTan => "window_tan",
                    AttenuationModel::WindowRational => "window_rational",
                    AttenuationModel::WindowUe4 => "window_ue4",
                };
                return Err(format!(
                    "the analytic integrator integrates the physical inverse-square falloff only; lights[{i}] \
                     has attenuation = \"{name}\": use raymarch, or attenuation = \"physical\""
                ));
            }
            let point = |position: Vec3, intensity: Rgb, emission, gap| PointEmitter {
                position: position.as_dvec3(),
                intensity: intensity.as_dvec3(),
                emission,
                light: index,
                gap,
            };
            match *light {
                Light::Point { position, intensity, .. } => {
                    emitters.push(point(position, intensity, Emission::Isotropic, 0.0))
                }
                Light::Spot { position, direction, intensity, cone_angle, falloff_start, profile, .. } => emitters
                    .push(point(
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
                Light::Sphere { center, radius, radiance, .. } => extended.push(Extended::Sphere {
                    sphere: SphereLight {
                        center: center.as_dvec3(),
                        radius: radius as f64,
                        radiance: radiance.as_dvec3(),
                        light: index,
                    },
                    // Set below, once the occluders are known.
                    near_surface: false,
                }),
                Light::Line { start, end, intensity } => {
                    let (a, b) = (start.as_dvec3(), end.as_dvec3());
                    extended.push(Extended::Line {
                        start: a,
                        end: b,
                        share: Share { intensity: intensity.as_dvec3() * (b - a).length(), light: index },
                    });
                }
                Light::Quad { corner, edge_u, edge_v, radiance } => {
                    let (u, v) = (edge_u.as_dvec3(), edge_v.as_dvec3());
                    let n = u.cross(v);
                    // dI = L cos θ dA: the intensity along the normal is L·A.
                    extended.push(Extended::Quad {
                        corner: corner.as_dvec3(),
                        edge_u: u,
                        edge_v: v,
                        normal: n.normalize(),
                        share: Share { intensity: radiance.as_dvec3() * n.length(), light: index },
                    });
                }
                Light::Triangle { a, edge_1, edge_2, radiance } => {
                    let (e1, e2) = (edge_1.as_dvec3(), edge_2.as_dvec3());
                    let n = e1.cross(e2);
                    extended.push(Extended::Triangle {
                        a: a.as_dvec3(),
                        edge_1: e1,
                        edge_2: e2,
                        normal: n.normalize(),
                        share: Share { intensity: radiance.as_dvec3() * (0.5 * n.length()), light: index },
                    });
                }
                Light::Volume { .. } => {
                    return Err(format!(
                        "the analytic integrator has no closed form for a volume light (lights[{i}]): use stochastic"
                    ));
                }
                Light::Sky { .. } => {
                    return Err(format!(
                        "the analytic integrator has no closed form for a sky light (lights[{i}]): use direct, \
                         raymarch or path"
                    ));
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
        let blockers = blockers::blockers(scene);
        let meshes = if options.shadows { MeshShadows::of_scene(scene) } else { MeshShadows::default() };
        if options.shadows {
            clearance::check_sphere_lights(scene.lights(), &blockers, &meshes)?;
            for x in &mut extended {
                if let Extended::Sphere { sphere, near_surface } = x {
                    *near_surface =
                        clearance::surface_near(sphere.center, sphere.radius, sphere.light, &blockers, &meshes);
                }
            }
        }
        // Half the points of a quad light per dimension: the sphere's rule
        // spans its whole surface, but only where surfaces cast penumbrae.
        let sphere_points = (n / 2).max(2);
        let sphere_rule = match options.quadrature {
            LightQuadrature::Gauss => Rule::gauss_legendre(sphere_points),
            LightQuadrature::Uniform => Rule::uniform(sphere_points),
        };
        Ok(Analytic { options, emitters, extended, rule, sphere_rule, blockers, meshes })
    }

    /// Whether every light is one point to a ray (point and spot lights,
    /// and sphere lights seen as their centres): the glow then costs a ray
    /// one closed form a light. A line, quad or triangle light (each of an
    /// emitting mesh's triangles is one), or a sphere light near a surface
    /// with shadows, is a sum of `light_steps` or its square of them, and
    /// more where a ray passes close and a piece is split.
    pub fn lights_are_points(&self) -> bool {
        self.extended.iter().all(|x| matches!(x, Extended::Sphere { near_surface: false, .. }))
    }

    /// Single-scattered radiance along `ray` over [0, t_end] from all lights.
    /// The scene's occluders were prepared by [`Analytic::new`]; `_scene` is
    /// kept for the callers' sake (the other integrators' signature).
    pub fn in_scattered(&self, _scene: &Scene, medium: &Medium, ray: &Ray, t_end: f32) -> Rgb {
        if medium.sigma_s == Rgb::ZERO || t_end.is_nan() || t_end <= 0.0 {
            return Rgb::ZERO;
        }
        let o = ray.origin.as_dvec3();
        let d = ray.dir.as_dvec3().normalize();
        let consts = MediumConsts::new(medium);
        let t_end = t_end as f64;
        // Buffers reused across rays on this thread (a fresh set if nested).
        thread_local! {
            static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
        }
        let segment = &ViewSegment { o, d, t_end };
        let run = |scratch: &mut Scratch| {
            let mut total = DVec3::ZERO;
            for e in &self.emitters {
                total += self.emitter_light(&consts, segment, e, scratch);
            }
            for x in &self.extended {
                let mut each = |e: &PointEmitter| {
                    total += self.emitter_light(&consts, segment, e, scratch);
                };
                match *x {
                    Extended::Line { start, end, share } => {
                        self.line_pieces(segment, (start, end), share, 0, &mut each)
                    }
                    Extended::Quad { corner, edge_u, edge_v, normal, share } => {
                        self.quad_pieces(segment, (corner, edge_u, edge_v), normal, share, 0, &mut each)
                    }
                    Extended::Triangle { a, edge_1, edge_2, normal, share } => {
                        self.triangle_pieces(segment, (a, edge_1, edge_2), normal, share, 0, &mut each)
                    }
                    Extended::Sphere { sphere, near_surface } => {
                        self.sphere_light(segment, &sphere, near_surface, &mut each)
                    }
                }
            }
            total
        };
        let total = crate::scratch::with_scratch(&SCRATCH, run);
        (total * medium.sigma_s.as_dvec3()).as_vec3()
    }

    /// ∫ e^{−σt (t + r)} · phase · m / r² dt · I over [0, t_end], per channel.
    fn emitter_light(&self, k: &MediumConsts, segment: &ViewSegment, e: &PointEmitter, s: &mut Scratch) -> DVec3 {
        let ViewSegment { o, d, t_end } = *segment;
        let p = e.position;
        let first = Glow::new(k.sigma_t[0], p, o, d, t_end);
        let glows: [Glow; 3] =
            std::array::from_fn(|c| if c < k.channels { Glow { sigma_t: k.sigma_t[c], ..first } } else { first });
        let range = (0.0, t_end);
        s.cuts.clear();
        s.cuts.push(0.0);
        s.cuts.push(t_end);
        match e.emission {
            Emission::Isotropic | Emission::Sphere { .. } => {}
            Emission::Spot { axis, cos_outer, cos_inner, cone, start, .. } => {
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
            self.shadow_intervals(e, o, d, range, &mut s.cands, &mut s.shadow);
            if s.shadow.first().is_some_and(|&(a, b)| a <= 0.0 && b >= t_end) {
                return DVec3::ZERO;
            }
            for &(a, b) in &s.shadow {
                s.cuts.extend([a, b].into_iter().filter(|&t| t > 0.0 && t < t_end));
            }
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
            let tm = 0.5 * (ta + tb);
            let x = o + d * tm;
            let Some(constant) = self.modulation_class(k, x, e) else {
                continue;
            };
            if self.options.shadows && in_intervals(&s.shadow, tm) {
                continue;
            }
            let mut piece = [0.0; 3];
            for c in 0..k.channels {
                let g = &glows[c];
                if g.sigma_t > 0.0 {
                    for j in [i, i + 1] {
                        if s.k[j][c].is_nan() {
                            s.k[j][c] = g.antiderivative_tabulated(s.cuts[j]);
                        }
                    }
                }
                piece[c] = g.between_with(ta, tb, s.k[i][c], s.k[i + 1][c]);
            }
            let factor = match constant {
                Some(m) => [m; 3],
                None => self.weighted_mean(k, &glows, segment, (ta, tb), e),
            };
            for c in 0..3 {
                let from = c.min(k.channels - 1);
                sum[c] += piece[from] * factor[from];
            }
        }
        sum * e.intensity
    }
}

#[derive(Default)]
struct Scratch {
    cuts: Vec<f64>,
    /// One occluder's candidate shadow boundaries.
    cands: Vec<f64>,
    /// The ray's shadowed intervals for the current emitter.
    shadow: Vec<(f64, f64)>,
    k: Vec<[f64; 3]>,
}

impl Integrator for Analytic {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Rgb {
        self.parts(scene, ray, sampler).total()
    }

    fn radiance_parts(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler) -> Option<RadianceParts> {
        Some(self.parts(scene, ray, sampler))
    }

    /// Emitters and blockers are placed where the lights are: rebuilt.
    fn lights_changed(&mut self, scene: &Scene) -> Result<(), IntegratorError> {
        *self = Analytic::new(scene, self.options)
            .map_err(|reason| IntegratorError::Unsupported { integrator: IntegratorKind::Analytic, reason })?;
        Ok(())
    }
}
