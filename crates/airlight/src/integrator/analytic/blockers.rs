//! The scene's occluders in f64, prepared once per render, with what the
//! exact volumetric shadows need of each: its shadow boundaries along a ray,
//! whether it blocks the segment from a point to the light, and a bounding
//! sphere to skip it for rays whose shadow segments cannot touch it.
//!
//! Every occluder here is a surface: a ray of light is stopped where it
//! crosses a sphere, a box's faces, a quad or a plane, as the other
//! integrators' shadow rays are. For a closed convex surface ∂B (sphere,
//! box, and their affine images) lit from a point L:
//!
//! - L outside B: a segment from L that meets B crosses ∂B, so the shadow
//!   set {x : [x, L] meets ∂B} is {x : [x, L] meets B}, which is convex (the
//!   union of the segments from the points of B away from L); an affine map
//!   keeps this true. A ray's shadowed part is one interval.
//! - L inside B (a room, a dome): [x, L] stays inside B exactly when x does
//!   (B is convex) and crosses ∂B otherwise, so the shadow set is the
//!   complement of B's interior: along a ray, everything but its chord
//!   through B. Its ends are the ray's crossings of ∂B.
//!
//! Either way the ends of the shadowed parts are among the candidates of
//! [`super::boundaries`], and one segment–surface test per piece between
//! candidates ([`Blocker::blocks`], with no acceleration structure) finds
//! them. Quads and planes are open surfaces: a segment is stopped when it
//! crosses them, from either side. The union over occluders is the ray's
//! shadow, with no shadow rays at all; triangles are in triangles.rs.

use super::boundaries::{box_boundaries, plane_boundaries, polygon_boundaries, sphere_boundaries};
use crate::geometry::Shape as SceneShape;
use crate::scene::Scene;
use glam::{DAffine3, DMat3, DVec3};

/// An occluder in f64; instanced shapes keep their world-to-local map.
#[derive(Clone, Copy, Debug)]
pub(super) enum Shape {
    Sphere { center: DVec3, radius: f64 },
    Box { min: DVec3, max: DVec3 },
    Quad { corner: DVec3, edge_u: DVec3, edge_v: DVec3 },
    Plane { point: DVec3, normal: DVec3 },
    InstancedSphere { local_from_world: DAffine3, center: DVec3, radius: f64 },
    InstancedBox { local_from_world: DAffine3, min: DVec3, max: DVec3 },
}

/// One occluder: its shape, a world bounding sphere (radius infinite for
/// planes), and the light it is the surface of.
#[derive(Clone, Copy, Debug)]
pub(super) struct Blocker {
    pub shape: Shape,
    pub center: DVec3,
    pub radius: f64,
    pub emitter: Option<u32>,
}

/// The scene's surfaces as occluders, in f64: its objects and its area
/// lights' surfaces, made from the scene's own shapes. Triangles are in
/// triangles.rs; SDF objects have no exact shadow boundary (the integrator
/// refuses shadows with them).
pub(super) fn blockers(scene: &Scene) -> Vec<Blocker> {
    let mut out = Vec::new();
    for surface in scene.surfaces() {
        let emitter = surface.emitter;
        let (shape, center, radius) = match surface.shape {
            SceneShape::Sphere { center, radius } => sphere(center, radius),
            SceneShape::Box { min, max } => cuboid(min, max),
            SceneShape::Quad { corner, edge_u, edge_v } => {
                let (c, u, v) = (corner.as_dvec3(), edge_u.as_dvec3(), edge_v.as_dvec3());
                let r = 0.5 * (u + v).length().max((u - v).length());
                (Shape::Quad { corner: c, edge_u: u, edge_v: v }, c + 0.5 * (u + v), r)
            }
            SceneShape::Plane { point, normal } => {
                (Shape::Plane { point: point.as_dvec3(), normal: normal.as_dvec3() }, DVec3::ZERO, f64::INFINITY)
            }
            // `Shape::transformed` keeps only spheres and boxes under a
            // transform; the rest it bakes into world space.
            SceneShape::Transformed { shape, world_from_local } => {
                let m = to_f64(&world_from_local.inverse());
                match *shape {
                    SceneShape::Sphere { center, radius } => {
                        let (c, r) = (center.as_dvec3(), radius as f64);
                        let (wc, wr) = world_sphere(&m, c, r);
                        (Shape::InstancedSphere { local_from_world: m, center: c, radius: r }, wc, wr)
                    }
                    SceneShape::Box { min, max } => {
                        let (a, b) = (min.as_dvec3(), max.as_dvec3());
                        let (wc, wr) = world_sphere(&m, 0.5 * (a + b), 0.5 * (b - a).length());
                        (Shape::InstancedBox { local_from_world: m, min: a, max: b }, wc, wr)
                    }
                    _ => continue,
                }
            }
            SceneShape::Mesh { .. } | SceneShape::Sdf(_) => continue,
        };
        out.push(Blocker { shape, center, radius, emitter });
    }
    out
}

fn sphere(center: glam::Vec3, radius: f32) -> (Shape, DVec3, f64) {
    let (c, r) = (center.as_dvec3(), radius as f64);
    (Shape::Sphere { center: c, radius: r }, c, r)
}

fn cuboid(min: glam::Vec3, max: glam::Vec3) -> (Shape, DVec3, f64) {
    let (a, b) = (min.as_dvec3(), max.as_dvec3());
    (Shape::Box { min: a, max: b }, 0.5 * (a + b), 0.5 * (b - a).length())
}

/// A world sphere holding the local sphere (c, r): the centre mapped back,
/// the radius scaled by the Frobenius norm of the local-to-world matrix (at
/// least its largest stretch).
fn world_sphere(local_from_world: &DAffine3, c: DVec3, r: f64) -> (DVec3, f64) {
    let world_from_local = local_from_world.inverse();
    let m = world_from_local.matrix3;
    let norm = (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt();
    (world_from_local.transform_point3(c), r * norm * (1.0 + 1e-9))
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

impl Blocker {
    /// Whether no segment from the light to a point of the ray segment
    /// o + t d, t in [t₀, t₁], can meet the bounding sphere: the triangle
    /// (light, o + t₀ d, o + t₁ d) that those segments sweep lies farther
    /// than the radius from the centre, in its plane's normal direction or
    /// beyond one of its edges; for a plane, when the triangle lies on one
    /// side of it. Conservative (never true when the occluder meets the
    /// triangle).
    pub fn misses(&self, light: DVec3, o: DVec3, d: DVec3, (t0, t1): (f64, f64)) -> bool {
        let (a, b) = (o + d * t0, o + d * t1);
        if let Shape::Plane { point, normal } = self.shape {
            // The triangle lies on the light's side of the plane (a
            // half-space is convex).
            let side = |x: DVec3| normal.dot(x - point);
            let s = side(light);
            return (s > 0.0 && side(a) > 0.0 && side(b) > 0.0) || (s < 0.0 && side(a) < 0.0 && side(b) < 0.0);
        }
        let tri = [light, a, b];
        let n = (a - light).cross(b - light);
        let n2 = n.length_squared();
        if n2 <= 1e-24 * (a - light).length_squared() * (b - light).length_squared() {
            return false;
        }
        let c = self.center - light;
        let r = self.radius;
        if c.dot(n).powi(2) > r * r * n2 {
            return true;
        }
        // Each edge's outward normal in the triangle's plane: (q − p) × n
        // points away from the third vertex for a counter-clockwise order.
        for i in 0..3 {
            let (p, q) = (tri[i], tri[(i + 1) % 3]);
            let m = (q - p).cross(n);
            let along = m.dot(self.center - p);
            if along > 0.0 && along * along > r * r * m.length_squared() {
                return true;
            }
        }
        false
    }

    /// Adds this occluder's candidate shadow boundaries for the light at
    /// `light` along o + t d, t in `range`.
    pub fn boundaries(&self, light: DVec3, o: DVec3, d: DVec3, range: (f64, f64), out: &mut Vec<f64>) {
        match self.shape {
            Shape::Sphere { center, radius } => sphere_boundaries(light, center, radius, o, d, range, out),
            Shape::Box { min, max } => box_boundaries(light, min, max, o, d, range, out),
            Shape::Quad { corner: c, edge_u: u, edge_v: v } => {
                polygon_boundaries(light, &[c, c + u, c + u + v, c + v], o, d, range, out)
            }
            Shape::Plane { point, normal } => plane_boundaries(point, normal, o, d, range, out),
            Shape::InstancedSphere { local_from_world: m, center, radius } => {
                let (lp, lo, ld) = (m.transform_point3(light), m.transform_point3(o), m.transform_vector3(d));
                sphere_boundaries(lp, center, radius, lo, ld, range, out)
            }
            Shape::InstancedBox { local_from_world: m, min, max } => {
                let (lp, lo, ld) = (m.transform_point3(light), m.transform_point3(o), m.transform_vector3(d));
                box_boundaries(lp, min, max, lo, ld, range, out)
            }
        }
    }

    /// Whether the segment x + s (y − x), s in (0, 1), crosses the
    /// occluder's surface.
    pub fn blocks(&self, x: DVec3, y: DVec3) -> bool {
        match self.shape {
            Shape::Sphere { center, radius } => segment_crosses_sphere(x, y, center, radius),
            Shape::Box { min, max } => segment_crosses_box(x, y, min, max),
            Shape::Quad { corner, edge_u, edge_v } => segment_meets_quad(x, y, corner, edge_u, edge_v),
            Shape::Plane { point, normal } => {
                let (a, b) = (normal.dot(x - point), normal.dot(y - point));
                (a > 0.0 && b < 0.0) || (a < 0.0 && b > 0.0)
            }
            Shape::InstancedSphere { local_from_world: m, center, radius } => {
                segment_crosses_sphere(m.transform_point3(x), m.transform_point3(y), center, radius)
            }
            Shape::InstancedBox { local_from_world: m, min, max } => {
                segment_crosses_box(m.transform_point3(x), m.transform_point3(y), min, max)
            }
        }
    }
}

/// Whether the segment (x, y) crosses the sphere: it meets the closed ball
/// (the point of the segment's line nearest the centre, clamped to the
/// segment, lies within R) and does not lie inside it (a segment with both
/// ends inside a convex solid stays inside).
fn segment_crosses_sphere(x: DVec3, y: DVec3, center: DVec3, radius: f64) -> bool {
    let r2 = radius * radius;
    let inside = |p: DVec3| (p - center).length_squared() < r2;
    if inside(x) && inside(y) {
        return false;
    }
    let v = y - x;
    let s = (v.dot(center - x) / v.length_squared()).clamp(0.0, 1.0);
    (x + v * s - center).length_squared() <= r2
}

/// Whether the segment (x, y) crosses the box's faces: it meets the box
/// (slabs, Kay and Kajiya 1986, on s in [0, 1]) and does not lie inside it.
fn segment_crosses_box(x: DVec3, y: DVec3, min: DVec3, max: DVec3) -> bool {
    let inside = |p: DVec3| p.cmpgt(min).all() && p.cmplt(max).all();
    if inside(x) && inside(y) {
        return false;
    }
    let v = y - x;
    let inv = v.recip();
    let (ta, tb) = ((min - x) * inv, (max - x) * inv);
    let near = ta.min(tb).max_element().max(0.0);
    let far = ta.max(tb).min_element().min(1.0);
    near <= far
}

/// Whether the segment (x, y) crosses the parallelogram corner + a u + b v,
/// a, b in [0, 1].
fn segment_meets_quad(x: DVec3, y: DVec3, corner: DVec3, u: DVec3, v: DVec3) -> bool {
    let n = u.cross(v);
    let (sx, sy) = (n.dot(x - corner), n.dot(y - corner));
    if (sx > 0.0) == (sy > 0.0) || sx == sy {
        return false;
    }
    let p = x + (y - x) * (sx / (sx - sy)) - corner;
    // Coordinates of p in (u, v) within the plane.
    let (uu, uv, vv) = (u.dot(u), u.dot(v), v.dot(v));
    let (pu, pv) = (p.dot(u), p.dot(v));
    let det = uu * vv - uv * uv;
    let a = (pu * vv - pv * uv) / det;
    let b = (pv * uu - pu * uv) / det;
    (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)
}
