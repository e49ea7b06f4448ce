//! Whether a surface passes within a distance of a point. A sphere light
//! is a point at its centre while every surface that could cast a
//! penumbra keeps clear of it (see [`NEAR_RADII`]), and points on its
//! surface otherwise. A surface that cuts through its ball (a lamp half
//! sunk into a ceiling, which lights the room below with its lower half)
//! is refused: the rule over its whole surface puts too few points on a
//! small cap beyond the cut (a cap of an eighth of the sphere: 30% of its
//! light lost in the differential test's seed 124).

use super::blockers::{Blocker, Shape};
use super::boundaries::box_edges;
use super::lights::NEAR_RADII;
use super::triangles::MeshShadows;
use crate::light::Light;
use glam::DVec3;

/// Refuses a sphere light whose ball a surface (other than its own) cuts
/// through, naming it.
pub(super) fn check_sphere_lights(lights: &[Light], blockers: &[Blocker], meshes: &MeshShadows) -> Result<(), String> {
    for (i, light) in lights.iter().enumerate() {
        let Light::Sphere { center, radius, .. } = *light else { continue };
        let (c, r) = (center.as_dvec3(), radius as f64);
        let cut = blockers.iter().any(|b| b.emitter != Some(i as u32) && b.surface_within(c, r))
            || meshes.surface_within(c, r);
        if cut {
            return Err(format!(
                "lights[{i}] is a sphere light that a surface cuts through; the analytic integrator \
                 has no accurate rule for the part of its surface beyond the cut: use raymarch, or \
                 move the light clear of the surface"
            ));
        }
    }
    Ok(())
}

/// Whether a surface other than light `light`'s own comes within
/// [`NEAR_RADII`] radii of the surface of the sphere light at `center` and
/// can cast a penumbra there: a plane or a convex closed shape that the
/// sphere lies wholly on one side of or inside (a room's walls, a dome)
/// shadows every point of the sphere alike, so it cannot.
pub(super) fn surface_near(center: DVec3, radius: f64, light: u32, blockers: &[Blocker], meshes: &MeshShadows) -> bool {
    let reach = (1.0 + NEAR_RADII) * radius;
    blockers.iter().any(|b| b.emitter != Some(light) && b.casts_penumbra(center, radius, reach))
        || meshes.surface_within(center, reach)
}

impl Blocker {
    /// Whether the occluder can shadow part of a sphere (centre `p`,
    /// radius `r`) and not the rest, at points within `reach` of `p`. A
    /// penumbra is cast by a silhouette edge: a plane, a box seen from
    /// inside or a sphere holding the light casts none unless it cuts the
    /// light's ball; a quad or a box seen from outside only from its edges
    /// (its face shadows the whole light alike) or when its plane cuts the
    /// ball; a sphere from outside from its rim, anywhere within reach.
    pub fn casts_penumbra(&self, p: DVec3, r: f64, reach: f64) -> bool {
        if !self.surface_within(p, reach) {
            return false;
        }
        let edges_within = |edges: &[(DVec3, DVec3)], p: DVec3, reach: f64| {
            edges.iter().any(|&(a, b)| segment_distance(p, a, b) < reach)
        };
        match self.shape {
            Shape::Plane { point, normal } => normal.dot(p - point).abs() < r * normal.length(),
            Shape::Sphere { center, radius } => (p - center).length() + r >= radius,
            Shape::Box { min, max } => {
                let inside = p.cmpgt(min).all() && p.cmplt(max).all();
                if inside {
                    box_surface_distance(p, min, max) <= r
                } else {
                    box_surface_distance(p, min, max) <= r || edges_within(&box_edges(min, max), p, reach)
                }
            }
            Shape::Quad { corner, edge_u, edge_v } => {
                let n = edge_u.cross(edge_v).normalize();
                let corners = [corner, corner + edge_u, corner + edge_u + edge_v, corner + edge_v];
                n.dot(p - corner).abs() < r
                    || edges_within(&[0, 1, 2, 3].map(|k| (corners[k], corners[(k + 1) % 4])), p, reach)
            }
            // Transformed shapes: conservatively, unless the light lies
            // wholly inside them.
            Shape::InstancedSphere { local_from_world: m, center, radius } => {
                (m.transform_point3(p) - center).length() + r * stretch(&m.matrix3) >= radius
            }
            Shape::InstancedBox { local_from_world: m, min, max } => {
                let q = m.transform_point3(p);
                !(q.cmpgt(min).all()
                    && q.cmplt(max).all()
                    && box_surface_distance(q, min, max) > r * stretch(&m.matrix3))
            }
        }
    }

    /// Whether the occluder's surface comes closer than `radius` to `p`
    /// (instanced shapes: conservatively, within `radius` times the
    /// largest stretch of the world-to-local map, measured in local space).
    pub fn surface_within(&self, p: DVec3, radius: f64) -> bool {
        match self.shape {
            Shape::Sphere { center, radius: r } => ((p - center).length() - r).abs() < radius,
            Shape::Box { min, max } => box_surface_distance(p, min, max) < radius,
            Shape::Quad { corner, edge_u, edge_v } => quad_distance(p, corner, edge_u, edge_v) < radius,
            Shape::Plane { point, normal } => normal.dot(p - point).abs() < radius * normal.length(),
            Shape::InstancedSphere { local_from_world: m, center, radius: r } => {
                ((m.transform_point3(p) - center).length() - r).abs() < radius * stretch(&m.matrix3)
            }
            Shape::InstancedBox { local_from_world: m, min, max } => {
                box_surface_distance(m.transform_point3(p), min, max) < radius * stretch(&m.matrix3)
            }
        }
    }
}

/// An upper bound of a linear map's largest stretch: its Frobenius norm.
fn stretch(m: &glam::DMat3) -> f64 {
    (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt()
}

/// Distance from `p` to the faces of the box [min, max]: to the box from
/// outside, to the nearest face from inside.
pub fn box_surface_distance(p: DVec3, min: DVec3, max: DVec3) -> f64 {
    let outside = (min - p).max(p - max).max(DVec3::ZERO);
    if outside != DVec3::ZERO {
        return outside.length();
    }
    (p - min).min(max - p).min_element()
}

/// Distance from `p` to the parallelogram corner + a u + b v, a, b in
/// [0, 1]: to its plane when the foot falls inside, else to the nearest edge.
pub fn quad_distance(p: DVec3, corner: DVec3, u: DVec3, v: DVec3) -> f64 {
    let n = u.cross(v);
    let (uu, uv, vv) = (u.dot(u), u.dot(v), v.dot(v));
    let det = uu * vv - uv * uv;
    let rel = p - corner;
    if det > 0.0 {
        let (pu, pv) = (rel.dot(u), rel.dot(v));
        let (a, b) = ((pu * vv - pv * uv) / det, (pv * uu - pu * uv) / det);
        if (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) {
            return n.dot(rel).abs() / n.length();
        }
    }
    let corners = [corner, corner + u, corner + u + v, corner + v];
    (0..4).map(|i| segment_distance(p, corners[i], corners[(i + 1) % 4])).fold(f64::INFINITY, f64::min)
}

/// Distance from `p` to the triangle `[a, b, c]`, through its closest
/// point (Ericson, "Real-Time Collision Detection", 2005, §5.1.5): the foot
/// on the plane when it falls inside, else the nearest edge.
pub fn triangle_distance(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    if n2 > 0.0 {
        let foot = p - n * (n.dot(p - a) / n2);
        // Barycentric signs: the foot is inside when it lies on the inner
        // side of all three edges.
        let inside = [(a, b), (b, c), (c, a)].iter().all(|&(x, y)| (y - x).cross(foot - x).dot(n) >= 0.0);
        if inside {
            return (p - foot).length();
        }
    }
    segment_distance(p, a, b).min(segment_distance(p, b, c)).min(segment_distance(p, c, a))
}

/// Distance from `p` to the segment [a, b].
fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 { (ab.dot(p - a) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * s - p).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_to_boxes_quads_and_triangles_match_sampled_surfaces() {
        // The distance to a densely sampled surface bounds the exact one
        // from above, within the sampling's spacing.
        let points = [
            DVec3::new(0.3, 0.2, 0.1),
            DVec3::new(2.0, -1.0, 0.5),
            DVec3::new(0.5, 0.5, 3.0),
            DVec3::new(-0.7, 1.4, -0.2),
        ];
        let (min, max) = (DVec3::ZERO, DVec3::new(1.0, 1.5, 0.8));
        let (corner, u, v) = (DVec3::new(-0.5, 0.0, 0.2), DVec3::new(1.0, 0.2, 0.0), DVec3::new(0.3, 0.1, 1.2));
        let tri = [DVec3::ZERO, DVec3::new(1.0, 0.0, 0.3), DVec3::new(0.2, 1.1, -0.4)];
        let n = 200;
        let grid = |f: &dyn Fn(f64, f64) -> DVec3, p: DVec3| {
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n {
                    best = best.min((f(i as f64 / n as f64, j as f64 / n as f64) - p).length());
                }
            }
            best
        };
        for p in points {
            let faces = (0..6)
                .map(|k| {
                    let axis = k % 3;
                    let (e1, e2) = ((axis + 1) % 3, (axis + 2) % 3);
                    let face = |s: f64, t: f64| {
                        let mut x = min;
                        x[axis] = if k < 3 { min[axis] } else { max[axis] };
                        x[e1] = min[e1] + s * (max[e1] - min[e1]);
                        x[e2] = min[e2] + t * (max[e2] - min[e2]);
                        x
                    };
                    grid(&face, p)
                })
                .fold(f64::INFINITY, f64::min);
            let quad = grid(&|s, t| corner + u * s + v * t, p);
            let triangle = grid(
                &|s, t| {
                    if s + t <= 1.0 { tri[0] + (tri[1] - tri[0]) * s + (tri[2] - tri[0]) * t } else { DVec3::INFINITY }
                },
                p,
            );
            let tol = 0.02;
            let exact = [box_surface_distance(p, min, max), quad_distance(p, corner, u, v), triangle_distance(p, tri)];
            for (e, s) in exact.iter().zip([faces, quad, triangle]) {
                assert!(*e <= s + 1e-12 && *e > s - tol, "{p}: {e} vs sampled {s}");
            }
        }
    }
}
