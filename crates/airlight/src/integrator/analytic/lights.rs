//! Line, quad, triangle and sphere lights as sums of point emitters, chosen
//! per ray.

use super::{Analytic, Emission, PointEmitter, quadrature};
use glam::DVec3;

/// A line, quad or triangle light: its points are chosen per ray.
#[derive(Clone, Copy, Debug)]
pub(super) enum Extended {
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
    Triangle {
        a: DVec3,
        edge_1: DVec3,
        edge_2: DVec3,
        normal: DVec3,
        /// radiance × area: the intensity along the normal, W/sr.
        intensity: DVec3,
        light: u32,
    },
}

impl Extended {
    pub(super) fn intensity(&self) -> DVec3 {
        match *self {
            Extended::Line { intensity, .. }
            | Extended::Quad { intensity, .. }
            | Extended::Triangle { intensity, .. } => intensity,
        }
    }
}

/// How many times a line light's piece may be halved for one ray.
const MAX_LINE_SPLITS: u32 = 8;
/// How many times a quad or triangle light's piece may be quartered for
/// one ray.
const MAX_QUAD_SPLITS: u32 = 5;

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
    #[allow(clippy::too_many_arguments)]
    fn must_split(&self, o: DVec3, d: DVec3, t_end: f64, c: DVec3, half: f64, depth: u32, max: u32) -> bool {
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
    pub(super) fn line_pieces(
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
    pub(super) fn quad_pieces(
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
                self.quad_pieces(o, d, t_end, (corner, hu, hv), normal, intensity * 0.25, light, depth + 1, each);
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
    /// The points of a piece of a triangle light (vertex `a`, edges), split
    /// in four at its edges' midpoints where the ray passes close. The rule
    /// is the square's, carried onto the triangle by Duffy's map
    /// (x, y) ↦ a + x(1 − y)·e₁ + x·y·e₂, whose Jacobian 2x (as a share of
    /// the area) multiplies the weights: exact for the constant, and as
    /// accurate as the square's rule for smooth kernels.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn triangle_pieces(
        &self,
        o: DVec3,
        d: DVec3,
        t_end: f64,
        (a, e1, e2): (DVec3, DVec3, DVec3),
        normal: DVec3,
        intensity: DVec3,
        light: u32,
        depth: u32,
        each: &mut dyn FnMut(&PointEmitter),
    ) {
        let centre = a + (e1 + e2) / 3.0;
        let half = [a, a + e1, a + e2].iter().map(|v| (*v - centre).length()).fold(0.0, f64::max);
        if self.must_split(o, d, t_end, centre, half, depth, MAX_QUAD_SPLITS) {
            let (h1, h2) = (0.5 * e1, 0.5 * e2);
            // Three corner triangles and the middle one, turned about but
            // with the same normal ((−h₁) × (−h₂) = h₁ × h₂).
            for piece in [(a, h1, h2), (a + h1, h1, h2), (a + h2, h1, h2), (a + h1 + h2, -h1, -h2)] {
                self.triangle_pieces(o, d, t_end, piece, normal, intensity * 0.25, light, depth + 1, each);
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
