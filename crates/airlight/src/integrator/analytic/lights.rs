//! Line, quad, triangle and sphere lights as sums of point emitters, chosen
//! per ray.

use super::{Analytic, Emission, PointEmitter, Rule, quadrature};
use glam::DVec3;

/// A line, quad or triangle light: its points are chosen per ray.
#[derive(Clone, Copy, Debug)]
pub(super) enum Extended {
    Line {
        start: DVec3,
        end: DVec3,
        /// Intensity per unit length × length, W/sr.
        share: Share,
    },
    Quad {
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
        normal: DVec3,
        /// Radiance × area: the intensity along the normal, W/sr.
        share: Share,
    },
    Triangle {
        a: DVec3,
        edge_1: DVec3,
        edge_2: DVec3,
        normal: DVec3,
        /// Radiance × area: the intensity along the normal, W/sr.
        share: Share,
    },
    /// A sphere light: a point at its centre ([`sphere_factor`]), or points
    /// on its surface where a surface near it casts penumbrae.
    Sphere {
        sphere: SphereLight,
        /// Whether a surface that can cast a penumbra comes within
        /// [`NEAR_RADII`] radii of the sphere (with shadows): its penumbrae
        /// are then wide, and the hard shadow of a point at the centre would
        /// misplace them.
        near_surface: bool,
    },
}

/// The part of a view ray that the glow is integrated over: o + t·d (d a
/// unit vector), t in [0, t_end].
#[derive(Clone, Copy, Debug)]
pub(super) struct ViewSegment {
    pub o: DVec3,
    pub d: DVec3,
    pub t_end: f64,
}

/// What a light, or a piece of a line, quad or triangle light, emits: its
/// share of the light's intensity (W/sr), and which light it is part of.
#[derive(Clone, Copy, Debug)]
pub(super) struct Share {
    pub intensity: DVec3,
    pub light: u32,
}

/// A sphere light (centre, radius, radiance) and its index.
#[derive(Clone, Copy, Debug)]
pub(super) struct SphereLight {
    pub center: DVec3,
    pub radius: f64,
    pub radiance: DVec3,
    pub light: u32,
}

impl Extended {
    pub(super) fn intensity(&self) -> DVec3 {
        match *self {
            Extended::Line { share, .. } | Extended::Quad { share, .. } | Extended::Triangle { share, .. } => {
                share.intensity
            }
            Extended::Sphere { sphere, .. } => sphere.radiance,
        }
    }
}

/// How close, in radii of the light, an occluder that can cast a
/// penumbra may come to a sphere light's surface before its point at the
/// centre gives way to points on its surface. Beyond it the point's hard
/// shadow misplaces penumbrae whose width over the occluder's distance is
/// 2R/distance, and whose light cancels to first order; within it the
/// error reaches tens of percent (a sphere light 2.8 radii from a ball: a
/// quarter of a 6×6 image 36% dark, in the differential test's seed 3374).
pub const NEAR_RADII: f64 = 4.0;

/// How many times a line light's piece may be halved for one ray.
const MAX_LINE_SPLITS: u32 = 8;
/// How many times a quad or triangle light's piece may be quartered for
/// one ray.
const MAX_QUAD_SPLITS: u32 = 5;
/// How many times a sphere light's piece may be quartered for one ray
/// (more costs much and gains little: tests/analytic_enclosures.rs).
const MAX_SPHERE_SPLITS: u32 = 2;

impl Analytic {
    /// Whether a piece of a light with centre `c` and half-size `half`
    /// must be split for the ray segment o + t d, t in [0, t_end]: when the
    /// segment passes closer to the piece than 8·half/n (n = light_steps).
    /// An n-point Gauss–Legendre rule on an interval of half-length L
    /// converges like ρ^(−2n) for a kernel whose singularity lies at
    /// distance δ from it, ρ = δ/L + √(1 + δ²/L²); δ ≥ 8L/n keeps ρ^(−2n)
    /// below about 1e-6 for every n, and for the uniform rule it keeps the
    /// ray several point spacings away. A rule of n > 16 points splits
    /// log2(n/16) times fewer.
    fn must_split(&self, segment: &ViewSegment, (c, half): (DVec3, f64), depth: u32, max: u32, rule: &Rule) -> bool {
        if depth >= max {
            return false;
        }
        let ViewSegment { o, d, t_end } = *segment;
        let t = d.dot(c - o).clamp(0.0, t_end);
        let gap = (o + d * t - c).length() - half;
        gap < 8.0 * half / rule.nodes.len() as f64
    }

    /// The points of a piece [a, b] of a line light, split where the ray
    /// passes close (see must_split).
    pub(super) fn line_pieces(
        &self,
        segment: &ViewSegment,
        (a, b): (DVec3, DVec3),
        Share { intensity, light }: Share,
        depth: u32,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let half = 0.5 * (b - a).length();
        if self.must_split(segment, (0.5 * (a + b), half), depth, MAX_LINE_SPLITS, &self.rule) {
            let (m, share) = (0.5 * (a + b), Share { intensity: intensity * 0.5, light });
            self.line_pieces(segment, (a, m), share, depth + 1, each);
            self.line_pieces(segment, (m, b), share, depth + 1, each);
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
    pub(super) fn quad_pieces(
        &self,
        segment: &ViewSegment,
        (c, u, v): (DVec3, DVec3, DVec3),
        normal: DVec3,
        Share { intensity, light }: Share,
        depth: u32,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let half = 0.5 * (u + v).length().max((u - v).length());
        if self.must_split(segment, (c + 0.5 * (u + v), half), depth, MAX_QUAD_SPLITS, &self.rule) {
            let (hu, hv) = (0.5 * u, 0.5 * v);
            let share = Share { intensity: intensity * 0.25, light };
            for corner in [c, c + hu, c + hv, c + hu + hv] {
                self.quad_pieces(segment, (corner, hu, hv), normal, share, depth + 1, each);
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
}

impl Analytic {
    /// The light of a sphere light (centre, radius, radiance L) for one
    /// ray: the point at its centre of intensity πR²L (with
    /// [`sphere_factor`]) when no surface near it casts penumbrae (see
    /// [`NEAR_RADII`]), else points on its surface. (Taking the point's
    /// light unshadowed less the light that the surface points' shadows take
    /// away was tried: the point's phase, taken toward the centre, errs where
    /// forward scattering looks past a shadowing box at the light, and the
    /// difference no longer cancels: 4.7× the differential test's allowance
    /// in its seed 2402.)
    pub(super) fn sphere_light(
        &self,
        segment: &ViewSegment,
        sphere: &SphereLight,
        near_surface: bool,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let SphereLight { center, radius, radiance, light } = *sphere;
        if near_surface {
            let whole = (-1.0, 1.0, 0.0, std::f64::consts::TAU);
            return self.sphere_pieces(segment, sphere, whole, 0, each);
        }
        each(&PointEmitter {
            position: center,
            intensity: radiance * (std::f64::consts::PI * radius * radius),
            emission: Emission::Sphere { radius },
            light,
            gap: radius,
        })
    }

    /// The points of a piece z ∈ [z0, z1], φ ∈ [φ0, φ1] of a sphere's
    /// surface (z along the world's z axis, φ about it), split in four where
    /// the ray passes close. The area element is R² dz dφ (Archimedes), so
    /// the rule in (z, φ) has constant weights; each point emits as a piece
    /// of a Lambertian surface, L cos θ dA.
    fn sphere_pieces(
        &self,
        segment: &ViewSegment,
        sphere: &SphereLight,
        (z0, z1, phi0, phi1): (f64, f64, f64, f64),
        depth: u32,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let SphereLight { center, radius, radiance, light } = *sphere;
        let on_sphere = |z: f64, phi: f64| {
            let s = (1.0 - z * z).max(0.0).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), z)
        };
        let (zm, phim) = (0.5 * (z0 + z1), 0.5 * (phi0 + phi1));
        let middle = center + radius * on_sphere(zm, phim);
        let half = [(z0, phi0), (z0, phi1), (z1, phi0), (z1, phi1), (z0, phim), (z1, phim), (zm, phi0), (zm, phi1)]
            .iter()
            .map(|&(z, phi)| (center + radius * on_sphere(z, phi) - middle).length())
            .fold(0.0, f64::max);
        if self.must_split(segment, (middle, half), depth, MAX_SPHERE_SPLITS, &self.sphere_rule) {
            for (za, zb) in [(z0, zm), (zm, z1)] {
                for (pa, pb) in [(phi0, phim), (phim, phi1)] {
                    self.sphere_pieces(segment, sphere, (za, zb, pa, pb), depth + 1, each);
                }
            }
            return;
        }
        let rule = &self.sphere_rule;
        let area = radius * radius * (z1 - z0) * (phi1 - phi0);
        for (x, wx) in rule.nodes.iter().zip(&rule.weights) {
            for (y, wy) in rule.nodes.iter().zip(&rule.weights) {
                let normal = on_sphere(z0 + (z1 - z0) * x, phi0 + (phi1 - phi0) * y);
                each(&PointEmitter {
                    position: center + radius * normal,
                    intensity: radiance * (area * wx * wy),
                    emission: Emission::Cosine { normal },
                    light,
                    gap: 0.0,
                });
            }
        }
    }

    /// The points of a piece of a triangle light (vertex `a`, edges), split
    /// in four at its edges' midpoints where the ray passes close. The rule
    /// is the square's, carried onto the triangle by Duffy's map
    /// (x, y) ↦ a + x(1 − y)·e₁ + x·y·e₂, whose Jacobian 2x (as a share of
    /// the area) multiplies the weights: exact for the constant, and as
    /// accurate as the square's rule for smooth kernels.
    pub(super) fn triangle_pieces(
        &self,
        segment: &ViewSegment,
        (a, e1, e2): (DVec3, DVec3, DVec3),
        normal: DVec3,
        Share { intensity, light }: Share,
        depth: u32,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let centre = a + (e1 + e2) / 3.0;
        let half = [a, a + e1, a + e2].iter().map(|v| (*v - centre).length()).fold(0.0, f64::max);
        if self.must_split(segment, (centre, half), depth, MAX_QUAD_SPLITS, &self.rule) {
            let (h1, h2) = (0.5 * e1, 0.5 * e2);
            let share = Share { intensity: intensity * 0.25, light };
            // Three corner triangles and the middle one, turned about but
            // with the same normal ((−h₁) × (−h₂) = h₁ × h₂).
            for piece in [(a, h1, h2), (a + h1, h1, h2), (a + h2, h1, h2), (a + h1 + h2, -h1, -h2)] {
                self.triangle_pieces(segment, piece, normal, share, depth + 1, each);
            }
            return;
        }
        let rule = &self.rule;
        for (x, wx) in rule.nodes.iter().zip(&rule.weights) {
            for (y, wy) in rule.nodes.iter().zip(&rule.weights) {
                each(&PointEmitter {
                    position: a + e1 * (x * (1.0 - y)) + e2 * (x * y),
                    intensity: intensity * (2.0 * x * wx * wy),
                    emission: Emission::Cosine { normal },
                    light,
                    gap: 0.0,
                });
            }
        }
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
