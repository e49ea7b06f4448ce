//! Lights, in the units of docs/scene-format.md: point and spot `intensity` in W/sr,
//! distant `irradiance` on a facing surface, sphere, quad and triangle `radiance`, line
//! `intensity` per unit length (W/(sr·m)).

mod attenuation;
pub mod environment;
mod keyframes;
mod spot;
mod volume;

pub use attenuation::{
    Attenuation, AttenuationModel, cutoff_falloff, cutoff_range, sphere_falloff, window_rational, window_tan,
    window_ue4,
};
pub use keyframes::Keyframes;
pub use spot::{SpotProfile, spot_falloff};
pub use volume::LightVolume;
use volume::third_dimension;

use crate::Rgb;
use crate::sampling::{basis, uniform_cone};
use glam::{Vec2, Vec3, Vec3Swizzles};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    Point {
        position: Vec3,
        intensity: Rgb,
        attenuation: Attenuation,
    },
    Spot {
        position: Vec3,
        /// Unit axis of the cone.
        direction: Vec3,
        intensity: Rgb,
        /// Half angle of the cone, radians.
        cone_angle: f32,
        /// Half angle where the falloff begins, radians.
        falloff_start: f32,
        profile: SpotProfile,
        attenuation: Attenuation,
    },
    /// A sun: parallel light travelling along the unit vector `direction`.
    Distant {
        direction: Vec3,
        irradiance: Rgb,
    },
    Sphere {
        center: Vec3,
        radius: f32,
        radiance: Rgb,
        attenuation: Attenuation,
    },
    /// Emits on the side of normalize(edge_u × edge_v) only.
    Quad {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        radiance: Rgb,
    },
    /// An emitting triangle `a`, `a + edge_1`, `a + edge_2` (one of an
    /// emissive mesh's): emits `radiance` on the side of
    /// normalize(edge_1 × edge_2) only, the side its vertices wind
    /// counter-clockwise around, as OBJ and glTF front faces do.
    Triangle {
        a: Vec3,
        edge_1: Vec3,
        edge_2: Vec3,
        radiance: Rgb,
    },
    /// A glowing segment, a neon tube too thin to see or hit: each element
    /// dl of it radiates `intensity`·dl (W/sr) equally in all directions, so
    /// `intensity` is W/(sr·m), and the whole line seen from afar acts as a
    /// point light of intensity `intensity`·length.
    Line {
        start: Vec3,
        end: Vec3,
        intensity: Rgb,
    },
    /// A glowing region of air of total intensity `intensity` (W/sr) spread
    /// uniformly over it (volume.rs states the units).
    Volume {
        shape: LightVolume,
        intensity: Rgb,
    },
    /// A uniform sky: `radiance` arriving from every direction from beyond
    /// the scene, and seen by rays that leave it. Sampled uniformly over
    /// the sphere of directions (pdf 1/4π); in a medium, attenuated over
    /// the scene's bounding sphere as a sun is.
    Sky {
        radiance: Rgb,
    },
}

/// Light arriving at a point from one sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the point toward the light.
    pub wi: Vec3,
    /// Distance to the sampled point of the light (infinite for a sun).
    pub distance: f32,
    /// Incident radiance divided by the solid-angle pdf; for delta lights,
    /// the irradiance on a surface facing the light (I/d² for a point).
    /// Multiply by BRDF·|cos| (or phase) for the direct-light estimate.
    pub weight: Rgb,
    /// Solid-angle pdf of `wi`; 0 for delta and volume lights (lights that no
    /// ray can hit).
    pub pdf: f32,
}

impl Light {
    pub fn point(position: Vec3, intensity: Rgb) -> Self {
        Light::Point { position, intensity, attenuation: Attenuation::PHYSICAL }
    }

    /// A spot light; angles in degrees, profile smoothstep.
    pub fn spot(position: Vec3, target: Vec3, intensity: Rgb, cone_deg: f32, falloff_start_deg: f32) -> Self {
        Light::Spot {
            position,
            direction: (target - position).normalize(),
            intensity,
            cone_angle: cone_deg.to_radians(),
            falloff_start: falloff_start_deg.to_radians(),
            profile: SpotProfile::Smoothstep,
            attenuation: Attenuation::PHYSICAL,
        }
    }

    pub fn distant(direction: Vec3, irradiance: Rgb) -> Self {
        Light::Distant { direction: direction.normalize(), irradiance }
    }

    /// A uniform sky of `radiance`.
    pub fn sky(radiance: Rgb) -> Self {
        Light::Sky { radiance }
    }

    pub fn sphere(center: Vec3, radius: f32, radiance: Rgb) -> Self {
        let attenuation = Attenuation { radius, ..Attenuation::PHYSICAL };
        Light::Sphere { center, radius, radiance, attenuation }
    }

    /// The same light with another falloff (point, spot and sphere lights;
    /// others are returned unchanged). A sphere light keeps its own radius.
    pub fn with_attenuation(mut self, a: Attenuation) -> Self {
        match &mut self {
            Light::Point { attenuation, .. } | Light::Spot { attenuation, .. } => *attenuation = a,
            Light::Sphere { attenuation, radius, .. } => *attenuation = Attenuation { radius: *radius, ..a },
            _ => {}
        }
        self
    }

    /// The light's falloff, for point, spot and sphere lights.
    pub fn attenuation(&self) -> Option<Attenuation> {
        match *self {
            Light::Point { attenuation, .. } | Light::Spot { attenuation, .. } | Light::Sphere { attenuation, .. } => {
                Some(attenuation)
            }
            _ => None,
        }
    }

    /// Where a light with a finite range reaches: its centre and the
    /// distance from the centre beyond which it gives nothing. None for
    /// lights that reach everywhere.
    pub fn reach(&self) -> Option<(Vec3, f32)> {
        match *self {
            Light::Point { position: c, attenuation: a, .. }
            | Light::Spot { position: c, attenuation: a, .. }
            | Light::Sphere { center: c, attenuation: a, .. }
                if a.range.is_finite() =>
            {
                Some((c, a.radius + a.range))
            }
            _ => None,
        }
    }

    /// Radiant intensity (W/sr) of a point, spot or volume light, and the
    /// equivalent π r² L of a sphere light.
    pub fn intensity(&self) -> Rgb {
        match *self {
            Light::Point { intensity, .. } | Light::Spot { intensity, .. } | Light::Volume { intensity, .. } => {
                intensity
            }
            Light::Sphere { radius, radiance, .. } => radiance * (std::f32::consts::PI * radius * radius),
            _ => Rgb::ZERO,
        }
    }

    pub fn quad(corner: Vec3, edge_u: Vec3, edge_v: Vec3, radiance: Rgb) -> Self {
        Light::Quad { corner, edge_u, edge_v, radiance }
    }

    /// An emitting triangle with vertices `a`, `b`, `c` (counter-clockwise
    /// seen from the side it lights).
    pub fn triangle(a: Vec3, b: Vec3, c: Vec3, radiance: Rgb) -> Self {
        Light::Triangle { a, edge_1: b - a, edge_2: c - a, radiance }
    }

    /// The triangle lights of an emitting mesh, one per triangle that has
    /// an area in f32 (degenerate ones emit nothing and are left out).
    pub fn triangles_of(positions: &[Vec3], triangles: &[[u32; 3]], radiance: Rgb) -> Vec<Light> {
        triangles
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .filter(|[a, b, c]| (*b - *a).cross(*c - *a).length_squared().is_normal())
            .map(|[a, b, c]| Light::triangle(a, b, c, radiance))
            .collect()
    }

    pub fn line(start: Vec3, end: Vec3, intensity: Rgb) -> Self {
        Light::Line { start, end, intensity }
    }

    /// A glowing box of total intensity I (W/sr).
    pub fn volume_box(min: Vec3, max: Vec3, intensity: Rgb) -> Self {
        Light::Volume { shape: LightVolume::Box { min: min.min(max), max: min.max(max) }, intensity }
    }

    /// A glowing ball of total intensity I (W/sr).
    pub fn volume_sphere(center: Vec3, radius: f32, intensity: Rgb) -> Self {
        Light::Volume { shape: LightVolume::Sphere { center, radius }, intensity }
    }

    /// A point that stands for the light when choosing where along a ray to
    /// look from, and a spread: equiangular sampling draws t in proportion to
    /// 1/(max(h, spread)² + (t − t_c)²) about it. The light's own point
    /// (spread 0) for point and spot lights; the centre of sphere lights
    /// (spread 0: outside, a sphere's light falls as from its centre); for
    /// volume and quad lights the centre and R/√3, R the radius of the ball
    /// (disk) of equal volume (area), or half a line light's length, so
    /// that the Cauchy profile I/(R²/3 + s²)
    /// matches a uniform ball's light, 3I/R² at its centre and I/s² far
    /// away; none for a sun.
    pub fn anchor(&self) -> Option<(Vec3, f32)> {
        let spread = |r: f32| r / 3f32.sqrt();
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some((position, 0.0)),
            Light::Volume { shape, .. } => Some((shape.center(), spread(shape.equivalent_radius()))),
            Light::Sphere { center, .. } => Some((center, 0.0)),
            Light::Quad { corner, edge_u, edge_v, .. } => {
                let radius = (edge_u.cross(edge_v).length() / std::f32::consts::PI).sqrt();
                Some((corner + 0.5 * (edge_u + edge_v), spread(radius)))
            }
            Light::Triangle { a, edge_1, edge_2, .. } => {
                let radius = (0.5 * edge_1.cross(edge_2).length() / std::f32::consts::PI).sqrt();
                Some((a + (edge_1 + edge_2) / 3.0, spread(radius)))
            }
            Light::Line { start, end, .. } => Some((0.5 * (start + end), spread(0.5 * (end - start).length()))),
            Light::Distant { .. } | Light::Sky { .. } => None,
        }
    }

    /// Like [`sample`](Self::sample) with three uniform numbers: volume
    /// lights use all three (a direction in the cone holding the region and
    /// a distance on the chord, volume.rs: weight ε·Ω_c·(r₁ − r₀) with
    /// ε = I/V); other lights use the first two.
    pub fn sample3(&self, p: Vec3, u: Vec3) -> Option<LightSample> {
        match *self {
            Light::Volume { shape, intensity } => {
                let (y, per_emission) = shape.sample_from(p, u)?;
                let to = y - p;
                let distance = to.length();
                if !(distance > 0.0 && distance.is_finite()) {
                    return None;
                }
                let weight = intensity * (per_emission / shape.volume());
                Some(LightSample { wi: to / distance, distance, weight, pdf: 0.0 })
            }
            _ => self.sample(p, u.xy()),
        }
    }

    /// Whether the light is a point or direction (no area to hit or sample).
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Point { .. } | Light::Spot { .. } | Light::Distant { .. } | Light::Line { .. })
    }

    /// Whether the light is a delta light with a place (point, spot and line
    /// lights, not a sun): the lights whose scattered light the path tracer
    /// gathers equiangularly along segments in fog.
    pub fn is_placed_delta(&self) -> bool {
        self.is_delta() && self.anchor().is_some()
    }

    /// Samples light arriving at `p`; `u` uniform in [0, 1)². None when no light
    /// arrives from the sample (outside a spot's cone, behind a quad light).
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        match *self {
            Light::Point { position, intensity, attenuation } => {
                let (wi, distance, falloff) = point_falloff(position, p, &attenuation)?;
                Some(LightSample { wi, distance, weight: intensity * falloff, pdf: 0.0 })
            }
            Light::Spot { position, direction, intensity, cone_angle, falloff_start, profile, attenuation } => {
                let (wi, distance, falloff) = point_falloff(position, p, &attenuation)?;
                let cone = spot_falloff(profile, -wi.dot(direction), cone_angle, falloff_start);
                (cone > 0.0).then(|| LightSample { wi, distance, weight: intensity * (cone * falloff), pdf: 0.0 })
            }
            Light::Distant { direction, irradiance } => {
                Some(LightSample { wi: -direction, distance: f32::INFINITY, weight: irradiance, pdf: 0.0 })
            }
            Light::Sphere { center, radius, radiance, attenuation } => match attenuation.model {
                AttenuationModel::Physical => sample_sphere(center, radius, radiance, p, u),
                // The approximations treat the sphere as a point at its
                // centre with intensity π r² L (see attenuation.rs).
                _ => {
                    let (wi, distance, falloff) = point_falloff(center, p, &attenuation)?;
                    let weight = radiance * (std::f32::consts::PI * radius * radius * falloff);
                    Some(LightSample { wi, distance: (distance - radius).max(0.0), weight, pdf: 0.0 })
                }
            },
            Light::Line { start, end, intensity } => {
                // A point uniform along the line (pdf 1/length): its
                // intensity·length, as a point light, over the squared distance.
                let x = start + (end - start) * u.x;
                let to = x - p;
                let d2 = to.length_squared();
                if d2 == 0.0 {
                    return None;
                }
                let distance = d2.sqrt();
                Some(LightSample {
                    wi: to / distance,
                    distance,
                    weight: intensity * ((end - start).length() / d2),
                    pdf: 0.0,
                })
            }
            Light::Quad { corner, edge_u, edge_v, radiance } => {
                area_sample(corner + edge_u * u.x + edge_v * u.y, edge_u.cross(edge_v), radiance, p)
            }
            Light::Triangle { a, edge_1, edge_2, radiance } => {
                // Uniform by area: √u₀ is the distance fraction from `a`
                // toward the far edge, u₁ the place along it.
                let s = u.x.sqrt();
                let x = a + edge_1 * (s * (1.0 - u.y)) + edge_2 * (s * u.y);
                area_sample(x, 0.5 * edge_1.cross(edge_2), radiance, p)
            }
            // Two numbers given: the third is a hash of them (volume.rs).
            Light::Volume { .. } => self.sample3(p, u.extend(third_dimension(u))),
            Light::Sky { radiance } => {
                let wi = crate::sampling::uniform_sphere(u);
                Some(LightSample { wi, distance: f32::INFINITY, weight: radiance * SPHERE, pdf: 1.0 / SPHERE })
            }
        }
    }

    /// Solid-angle pdf with which [`Light::sample`] picks direction `wi` from
    /// `p`, for an area light that the ray p + t·wi meets at distance `t`;
    /// 0 for lights sampled as points.
    pub fn pdf(&self, p: Vec3, wi: Vec3, t: f32) -> f32 {
        match *self {
            Light::Sphere { center, radius, attenuation, .. } if attenuation.model == AttenuationModel::Physical => {
                let dc2 = (center - p).length_squared();
                let r2 = radius * radius;
                if dc2 <= r2 {
                    return 1.0 / (4.0 * std::f32::consts::PI);
                }
                let sin2 = r2 / dc2;
                let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt());
                1.0 / (2.0 * std::f32::consts::PI * one_minus_cos)
            }
            Light::Quad { edge_u, edge_v, .. } => area_pdf(edge_u.cross(edge_v), wi, t),
            Light::Triangle { edge_1, edge_2, .. } => area_pdf(0.5 * edge_1.cross(edge_2), wi, t),
            Light::Sky { .. } => 1.0 / SPHERE,
            _ => 0.0,
        }
    }

    /// The surface the camera sees and shadows meet, for sphere, quad and
    /// triangle lights; other lights have none (points, directions, glowing air).
    pub fn surface(&self) -> Option<crate::geometry::Shape> {
        match *self {
            Light::Sphere { center, radius, .. } => Some(crate::geometry::Shape::sphere(center, radius)),
            Light::Quad { corner, edge_u, edge_v, .. } => Some(crate::geometry::Shape::quad(corner, edge_u, edge_v)),
            Light::Triangle { a, edge_1, edge_2, .. } => Some(crate::geometry::Shape::Mesh {
                positions: vec![a, a + edge_1, a + edge_2],
                triangles: vec![[0, 1, 2]],
                uvs: Vec::new(),
                normals: Vec::new(),
            }),
            _ => None,
        }
    }

    /// Radiance leaving the light's surface toward `-dir` at a point whose
    /// outward normal is `n` (area lights; a sky's radiance anywhere; zero
    /// for others).
    pub fn emitted(&self, n: Vec3, dir: Vec3) -> Rgb {
        match *self {
            Light::Sphere { radiance, .. } | Light::Sky { radiance } => radiance,
            Light::Quad { radiance, .. } | Light::Triangle { radiance, .. } if n.dot(dir) < 0.0 => radiance,
            _ => Rgb::ZERO,
        }
    }
}

/// The solid angle of the sphere of directions, 4π.
const SPHERE: f32 = 4.0 * std::f32::consts::PI;

/// Direction and distance from `p` to a point light at `position`, and the
/// factor that turns its intensity into irradiance on a facing surface:
/// 1/D² for the physical law, else f(d)/r² with d = D − r (attenuation.rs).
/// None beyond the light's range.
#[inline]
fn point_falloff(position: Vec3, p: Vec3, a: &Attenuation) -> Option<(Vec3, f32, f32)> {
    let to = position - p;
    let d2 = to.length_squared();
    let distance = d2.sqrt();
    let falloff = match a.model {
        AttenuationModel::Physical => 1.0 / d2,
        _ => {
            let d = distance - a.radius;
            if !a.reaches(d) {
                return None;
            }
            a.factor(d) / (a.radius * a.radius)
        }
    };
    Some((to / distance, distance, falloff))
}

/// The sample of a one-sided area light (normal_area: its normal times its
/// area) at its point `x`, drawn uniformly by area, seen from `p`: the pdf
/// 1/area turned into solid angle, d²/(area·cos θ_light). None behind it.
fn area_sample(x: Vec3, normal_area: Vec3, radiance: Rgb, p: Vec3) -> Option<LightSample> {
    let to = x - p;
    let d2 = to.length_squared();
    let distance = d2.sqrt();
    let wi = to / distance;
    let pdf = area_pdf(normal_area, wi, distance);
    (pdf > 0.0 && pdf.is_finite()).then(|| LightSample { wi, distance, weight: radiance / pdf, pdf })
}

/// Solid-angle pdf of direction `wi` toward a one-sided area light sampled
/// uniformly by area, met at distance `t`; 0 from behind. `normal_area` is
/// the normal scaled by the area A, so −wi·normal_area is A·cos θ_light:
/// the pdf t²/(A·cos θ_light) without the area's square root.
fn area_pdf(normal_area: Vec3, wi: Vec3, t: f32) -> f32 {
    let projected_area = -wi.dot(normal_area);
    if projected_area <= 0.0 { 0.0 } else { t * t / projected_area }
}

/// Samples a sphere light over the cone of directions it subtends from `p`
/// (pbrt-v4, Sphere::Sample with a reference point): uniform in that cone,
/// pdf = 1/(2π(1 − cos θmax)). From inside the sphere, directions are uniform
/// over the whole sphere of directions.
fn sample_sphere(center: Vec3, radius: f32, radiance: Rgb, p: Vec3, u: Vec2) -> Option<LightSample> {
    let to_center = center - p;
    let dc2 = to_center.length_squared();
    let r2 = radius * radius;
    let axis;
    // 1 − cos θmax, accurate also for small cones: sin²θmax / (1 + cos θmax).
    let one_minus_cos;
    if dc2 <= r2 {
        axis = Vec3::Z;
        one_minus_cos = 2.0;
    } else {
        axis = to_center / dc2.sqrt();
        let sin2 = r2 / dc2;
        let cos_max = (1.0 - sin2).max(0.0).sqrt();
        one_minus_cos = sin2 / (1.0 + cos_max);
    }
    let local = uniform_cone(u, 1.0 - one_minus_cos);
    let (t, b) = basis(axis);
    let wi = (t * local.x + b * local.y + axis * local.z).normalize();
    // Distance to the sphere's near surface along wi (the far one from inside).
    let along = to_center.dot(wi);
    let closest2 = (dc2 - along * along).max(0.0);
    let half_chord = (r2 - closest2).max(0.0).sqrt();
    let distance = if dc2 <= r2 { along + half_chord } else { (along - half_chord).max(0.0) };
    let pdf = 1.0 / (2.0 * std::f32::consts::PI * one_minus_cos);
    Some(LightSample { wi, distance, weight: radiance / pdf, pdf })
}

#[cfg(test)]
mod tests;
