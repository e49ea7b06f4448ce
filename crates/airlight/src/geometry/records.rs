//! The primitives the geometry holds, as flat records: what each is, how a
//! ray meets it, its normal and its bounding box.

use super::sdf::{Sdf, sphere_trace};
use super::shape::{box_normal, intersect_box, intersect_quad, intersect_sphere, intersect_triangle};
use glam::{Affine3A, Mat3, Vec2, Vec3, Vec3A};
use obvhs::{Boundable, aabb::Aabb};

/// One primitive the BVH holds.
#[derive(Clone, Debug)]
pub(super) enum Prim {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    Quad {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    Box {
        min: Vec3,
        max: Vec3,
    },
    Triangle {
        v0: Vec3,
        e1: Vec3,
        e2: Vec3,
    },
    /// A sphere or box in its own space.
    Instance(std::boxed::Box<Instance>),
    /// A signed distance field, sphere traced inside its bounding box.
    Sdf(std::boxed::Box<SdfPrim>),
}

#[derive(Clone, Debug)]
pub(super) struct SdfPrim {
    pub sdf: Sdf,
    pub min: Vec3,
    pub max: Vec3,
}

#[derive(Clone, Debug)]
pub(super) struct Instance {
    pub prim: Prim,
    pub local_from_world: Affine3A,
    /// Maps local normals to world normals: the inverse transpose of the
    /// linear part of world_from_local.
    pub normal_to_world: Mat3,
    pub bounds: Aabb,
}

impl Instance {
    /// The unit world normal of a local normal.
    #[inline]
    pub fn world_normal(&self, local: Vec3) -> Vec3 {
        (self.normal_to_world * local).normalize()
    }
}

#[derive(Clone, Debug)]
pub(super) struct Record {
    pub prim: Prim,
    pub material: u32,
    pub emitter: Option<u32>,
    /// A triangle's texture coordinates and vertex normals: its index in
    /// `Geometry::triangle_attributes`, or [`NO_ATTRIBUTES`]. (The field
    /// fits in the record's padding: meshes without them cost nothing more.)
    pub attributes: u32,
}

/// A record without texture coordinates or vertex normals of its own.
pub(super) const NO_ATTRIBUTES: u32 = u32::MAX;

/// What a mesh's triangle carries beyond its corners, each when its mesh
/// has them: texture coordinates and vertex normals, at its three corners.
#[derive(Clone, Debug)]
pub(super) struct TriangleAttributes {
    pub uvs: Option<[Vec2; 3]>,
    pub normals: Option<[Vec3; 3]>,
}

/// An SDF that no box bounds (it holds a plane): traced on its own.
#[derive(Clone, Debug)]
pub(super) struct UnboundedSdf {
    pub sdf: Sdf,
    pub material: u32,
}

/// How far an unbounded SDF is traced when the ray has no end.
pub(super) const UNBOUNDED_FAR: f32 = 1e5;

#[derive(Clone, Debug)]
pub(super) struct PlaneRecord {
    pub point: Vec3,
    pub normal: Vec3,
    pub material: u32,
}

impl Prim {
    #[inline]
    pub fn intersect(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> f32 {
        match self {
            // A segment within the sphere ends before the sphere does: the
            // fog scenes' enclosing sphere, for shadow rays and for rays
            // that meet something inside it first.
            Prim::Sphere { center, radius } if sphere_holds_segment(*center, *radius, o, d, tmax) => f32::INFINITY,
            Prim::Sphere { center, radius } => intersect_sphere(*center, *radius, o, d, tmin, tmax),
            Prim::Quad { corner, edge_u, edge_v } => intersect_quad(*corner, *edge_u, *edge_v, o, d, tmin, tmax),
            Prim::Box { min, max } => intersect_box(*min, *max, o, d, tmin, tmax),
            Prim::Triangle { v0, e1, e2 } => intersect_triangle(*v0, *e1, *e2, o, d, tmin, tmax),
            Prim::Instance(inst) => {
                let lo = inst.local_from_world.transform_point3(o);
                let ld = inst.local_from_world.transform_vector3(d);
                inst.prim.intersect(lo, ld, tmin, tmax)
            }
            Prim::Sdf(s) => {
                // Trace only where the ray is inside the bounding box.
                let inv = d.recip();
                let (ta, tb) = ((s.min - o) * inv, (s.max - o) * inv);
                let near = ta.min(tb).max_element().max(tmin);
                let far = ta.max(tb).min_element().min(tmax);
                if near.is_nan() || far.is_nan() || near > far {
                    return f32::INFINITY;
                }
                let t = sphere_trace(&s.sdf, o, d, near, far);
                if t > tmin && t < tmax { t } else { f32::INFINITY }
            }
        }
    }

    /// The outward unit normal at a point `p` on the primitive.
    pub fn normal(&self, p: Vec3) -> Vec3 {
        match self {
            Prim::Sphere { center, .. } => (p - *center).normalize(),
            Prim::Quad { edge_u, edge_v, .. } => edge_u.cross(*edge_v).normalize(),
            Prim::Box { min, max } => box_normal(*min, *max, p),
            Prim::Triangle { e1, e2, .. } => e1.cross(*e2).normalize(),
            Prim::Instance(inst) => inst.world_normal(inst.prim.normal(inst.local_from_world.transform_point3(p))),
            Prim::Sdf(s) => s.sdf.normal(p),
        }
    }

    pub fn bounds(&self) -> Aabb {
        match self {
            Prim::Sphere { center, radius } => {
                Aabb::new(Vec3A::from(*center - *radius), Vec3A::from(*center + *radius))
            }
            Prim::Quad { corner, edge_u, edge_v } => Aabb::from_points(&[
                (*corner).into(),
                (*corner + *edge_u).into(),
                (*corner + *edge_v).into(),
                (*corner + *edge_u + *edge_v).into(),
            ]),
            Prim::Box { min, max } => Aabb::new((*min).into(), (*max).into()),
            Prim::Triangle { v0, e1, e2 } => Aabb::from_points(&[(*v0).into(), (*v0 + *e1).into(), (*v0 + *e2).into()]),
            Prim::Instance(inst) => inst.bounds,
            Prim::Sdf(s) => Aabb::new(s.min.into(), s.max.into()),
        }
    }
}

impl Boundable for Record {
    fn aabb(&self) -> Aabb {
        // Pad every box: a quad or triangle lying in an axis plane has a flat
        // box, which a ray along that plane's normal would pass as empty.
        let b = self.prim.bounds();
        let pad = 1e-5 * (1.0 + b.min.abs().max(b.max.abs()).max_element());
        Aabb::new(b.min - pad, b.max + pad)
    }
}

/// The coordinates (a, b) of `rel = a·e1 + b·e2` for a point in the plane
/// of `e1` and `e2`, by least squares (the 2×2 normal equations).
#[inline]
pub(crate) fn barycentric(rel: Vec3, e1: Vec3, e2: Vec3) -> [f32; 2] {
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (r1, r2) = (rel.dot(e1), rel.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det == 0.0 {
        return [0.0, 0.0];
    }
    [(d22 * r1 - d12 * r2) / det, (d11 * r2 - d12 * r1) / det]
}

/// Whether both ends of the segment `o + t·d`, 0 ≤ t ≤ tmax, lie inside
/// the sphere, each by a thousandth of r² in squared distance: then the
/// segment cannot cross the sphere (it is convex), and the root that
/// [`intersect_sphere`] would find, the exit, lies beyond tmax by at
/// least a four-thousandth of itself, far more than its rounding error
/// (a few units in the last place), so the shortcut gives its answer. A
/// shadow ray in a scene closed by a sphere around it (the fog comparison
/// scenes) so skips that sphere's square root and divisions, and so does
/// a ray that meets the floor inside it (tested first, it sets tmax). An
/// unbounded segment (tmax infinite) is never held.
#[inline]
pub(super) fn sphere_holds_segment(center: Vec3, radius: f32, o: Vec3, d: Vec3, tmax: f32) -> bool {
    let inner = 0.999 * radius * radius;
    let start = o - center;
    let end = start + d * tmax;
    start.length_squared() < inner && end.length_squared() < inner
}

#[inline]
pub(super) fn intersect_plane(plane: &PlaneRecord, o: Vec3, d: Vec3) -> f32 {
    let denom = plane.normal.dot(d);
    if denom.abs() < 1e-20 {
        return f32::INFINITY;
    }
    plane.normal.dot(plane.point - o) / denom
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Sampler, uniform_sphere};

    /// The shortcut must give the full test's answer: segments from
    /// inside a sphere, ending anywhere from deep inside to just past the
    /// surface, where a wrong shortcut would hide a crossing.
    #[test]
    fn a_sphere_meets_exactly_the_segments_its_full_test_does() {
        let (center, radius) = (Vec3::new(0.3, -0.2, 0.5), 12.0);
        let sphere = Prim::Sphere { center, radius };
        let mut s = Sampler::for_pixel(5, 0, 0);
        let (mut crossed, mut shortcut) = (0, 0);
        for _ in 0..200_000 {
            let start = center + uniform_sphere(s.next2()) * radius * s.next().sqrt();
            let d = uniform_sphere(s.next2()) * (0.5 + 2.0 * s.next());
            // The exit, then a length about it: within a hair of the
            // surface for a third of the segments.
            let exit = intersect_sphere(center, radius, start, d, 0.0, f32::INFINITY);
            assert_eq!(sphere.intersect(start, d, 0.0, f32::INFINITY).to_bits(), exit.to_bits());
            let scale = if s.next() < 0.33 { 1.0 + 1e-4 * (2.0 * s.next() - 1.0) } else { 1.5 * s.next() };
            let tmax = exit * scale;
            let want = intersect_sphere(center, radius, start, d, 0.0, tmax);
            assert_eq!(sphere.intersect(start, d, 0.0, tmax).to_bits(), want.to_bits(), "{start} {d} {tmax}");
            crossed += (want < tmax) as u32;
            shortcut += sphere_holds_segment(center, radius, start, d, tmax) as u32;
        }
        // Both answers were asked often, and the shortcut taken often.
        assert!(crossed > 40_000 && shortcut > 40_000, "crossed {crossed}, shortcut {shortcut}");
    }
}
