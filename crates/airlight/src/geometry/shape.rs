//! Shapes as a user describes them, and the pure ray–shape intersection
//! functions. Each intersection function takes a ray `o + t·d` whose `d` need
//! not be unit length (instanced shapes intersect in their own space), and
//! returns the smallest `t` in `(tmin, tmax)`, or `f32::INFINITY` on a miss, the
//! convention of the BVH traversal.

use glam::{Affine3A, Mat3, Vec2, Vec3};

/// A shape of the scene, in world space once built.
#[derive(Clone, PartialEq)]
pub enum Shape {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// An infinite plane through `point` with the given normal.
    Plane {
        point: Vec3,
        normal: Vec3,
    },
    /// A parallelogram `corner + u·edge_u + v·edge_v`, u, v in [0, 1];
    /// its normal is `normalize(edge_u × edge_v)`.
    Quad {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    /// An axis-aligned box.
    Box {
        min: Vec3,
        max: Vec3,
    },
    /// A triangle mesh; `triangles` index `positions`, and `uvs` and
    /// `normals` too when the mesh has texture coordinates or vertex
    /// normals (one per position; empty when it has none). Vertex normals
    /// shade the surface smoothly (see [`crate::material::shading`]).
    Mesh {
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        uvs: Vec<Vec2>,
        normals: Vec<Vec3>,
    },
    /// A signed distance field, sphere traced (see `geometry::sdf`).
    Sdf(super::sdf::Sdf),
    /// A sphere or box under a transform that does not keep it a sphere or an
    /// axis-aligned box (non-uniform scale, rotation).
    Transformed {
        shape: std::boxed::Box<Shape>,
        world_from_local: Affine3A,
    },
}

/// A mesh's data in its debug text (and so in a render's fingerprint,
/// `airlight::fingerprint`) as counts and a checksum of the bit patterns:
/// exact like the numbers themselves, without formatting millions of them.
impl std::fmt::Debug for Shape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Shape::Sphere { center, radius } => {
                f.debug_struct("Sphere").field("center", center).field("radius", radius).finish()
            }
            Shape::Plane { point, normal } => {
                f.debug_struct("Plane").field("point", point).field("normal", normal).finish()
            }
            Shape::Quad { corner, edge_u, edge_v } => {
                f.debug_struct("Quad").field("corner", corner).field("edge_u", edge_u).field("edge_v", edge_v).finish()
            }
            Shape::Box { min, max } => f.debug_struct("Box").field("min", min).field("max", max).finish(),
            Shape::Mesh { positions, triangles, uvs, normals } => {
                let words = positions.iter().flat_map(|p| p.to_array().map(f32::to_bits));
                let words = words.chain(triangles.iter().flatten().copied());
                let words = words.chain(uvs.iter().flat_map(|uv| uv.to_array().map(f32::to_bits)));
                let words = words.chain(normals.iter().flat_map(|n| n.to_array().map(f32::to_bits)));
                let mut d = f.debug_struct("Mesh");
                d.field("positions", &positions.len()).field("triangles", &triangles.len()).field("uvs", &uvs.len());
                // Listed only when there are some: a mesh without them keeps
                // the text (a render's fingerprint) it had before they were read.
                if !normals.is_empty() {
                    d.field("normals", &normals.len());
                }
                d.field("checksum", &format_args!("{:016x}", checksum(words))).finish()
            }
            Shape::Sdf(sdf) => f.debug_tuple("Sdf").field(sdf).finish(),
            Shape::Transformed { shape, world_from_local } => {
                f.debug_struct("Transformed").field("shape", shape).field("world_from_local", world_from_local).finish()
            }
        }
    }
}

/// FNV-1a (Fowler, Noll and Vo) over 32-bit words, a word at a time: the
/// same on every machine. Four interleaved streams combined at the end, so
/// that the multiplications of one do not wait for the others'.
pub(crate) fn checksum(words: impl Iterator<Item = u32>) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h = [0, 1, 2, 3].map(|i| 0xcbf2_9ce4_8422_2325u64 ^ i);
    for (i, w) in words.enumerate() {
        h[i % 4] = (h[i % 4] ^ w as u64).wrapping_mul(PRIME);
    }
    h[1..].iter().fold(h[0], |acc, &x| (acc ^ x).wrapping_mul(PRIME))
}

impl Shape {
    pub fn sphere(center: Vec3, radius: f32) -> Self {
        Shape::Sphere { center, radius }
    }
    pub fn plane(point: Vec3, normal: Vec3) -> Self {
        Shape::Plane { point, normal: normal.normalize() }
    }
    pub fn quad(corner: Vec3, edge_u: Vec3, edge_v: Vec3) -> Self {
        Shape::Quad { corner, edge_u, edge_v }
    }
    pub fn cuboid(min: Vec3, max: Vec3) -> Self {
        Shape::Box { min: min.min(max), max: min.max(max) }
    }
    pub fn sdf(sdf: super::sdf::Sdf) -> Self {
        Shape::Sdf(sdf)
    }

    /// The shape under `world_from_local`. Planes, quads and meshes are mapped
    /// exactly (an affine map keeps them planes, parallelograms and triangles);
    /// a sphere stays a sphere under a similarity, a box stays a box under
    /// scale and translation; otherwise the shape is instanced.
    pub fn transformed(self, m: Affine3A) -> Shape {
        if m == Affine3A::IDENTITY {
            return self;
        }
        let linear = Mat3::from(m.matrix3);
        match self {
            Shape::Plane { point, normal } => {
                let n = linear.inverse().transpose() * normal;
                Shape::Plane { point: m.transform_point3(point), normal: n.normalize() }
            }
            Shape::Quad { corner, edge_u, edge_v } => {
                Shape::Quad { corner: m.transform_point3(corner), edge_u: linear * edge_u, edge_v: linear * edge_v }
            }
            Shape::Mesh { positions, triangles, uvs, normals } => {
                // Normals by the inverse transpose, as a plane's.
                let normal_map = linear.inverse().transpose();
                Shape::Mesh {
                    positions: positions.iter().map(|&p| m.transform_point3(p)).collect(),
                    triangles,
                    uvs,
                    normals: normals.iter().map(|&n| (normal_map * n).normalize_or_zero()).collect(),
                }
            }
            Shape::Sphere { center, radius } if is_similarity(linear) => {
                Shape::Sphere { center: m.transform_point3(center), radius: radius * linear.x_axis.length() }
            }
            Shape::Box { min, max } if is_diagonal(linear) => {
                let a = m.transform_point3(min);
                let b = m.transform_point3(max);
                Shape::cuboid(a, b)
            }
            Shape::Transformed { shape, world_from_local } => {
                Shape::Transformed { shape, world_from_local: m * world_from_local }
            }
            Shape::Sdf(sdf) => Shape::Sdf(sdf.transformed(m)),
            other => Shape::Transformed { shape: std::boxed::Box::new(other), world_from_local: m },
        }
    }
}

fn is_diagonal(m: Mat3) -> bool {
    let off = [m.x_axis.y, m.x_axis.z, m.y_axis.x, m.y_axis.z, m.z_axis.x, m.z_axis.y];
    off.iter().all(|v| v.abs() < 1e-6)
}

/// Orthogonal columns of one length: a rotation times a uniform scale.
fn is_similarity(m: Mat3) -> bool {
    let (a, b, c) = (m.x_axis, m.y_axis, m.z_axis);
    let s = a.length();
    let tol = 1e-5 * s.max(1e-20);
    (b.length() - s).abs() < tol
        && (c.length() - s).abs() < tol
        && a.dot(b).abs() < tol * s
        && a.dot(c).abs() < tol * s
        && b.dot(c).abs() < tol * s
}

/// Ray–sphere intersection, solving |o + t·d − c|² = r² in the numerically
/// robust form of Haines et al., "Precision Improvements for Ray/Sphere
/// Intersection" (Ray Tracing Gems, 2019): the discriminant is computed from
/// the distance of the centre to the ray's line, not as b² − ac.
#[inline]
pub fn intersect_sphere(center: Vec3, radius: f32, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> f32 {
    let oc = o - center;
    let a = d.length_squared();
    let b = oc.dot(d);
    let c = oc.length_squared() - radius * radius;
    // From outside and moving away both roots are negative (q < 0 below,
    // so c/q and q/a are): the answer the rest would give, sooner.
    if c > 0.0 && b > 0.0 && tmin >= 0.0 {
        return f32::INFINITY;
    }
    let foot = oc - d * (b / a);
    let disc = a * (radius * radius - foot.length_squared());
    if disc < 0.0 {
        return f32::INFINITY;
    }
    let q = -b - disc.sqrt().copysign(b);
    let (mut t0, mut t1) = (c / q, q / a);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > tmin && t0 < tmax {
        t0
    } else if t1 > tmin && t1 < tmax {
        t1
    } else {
        f32::INFINITY
    }
}

/// Ray–parallelogram intersection: the ray meets the plane at `p`, and `p −
/// corner = α·edge_u + β·edge_v` with α = ((p−c)×v)·n/|n|², β = (u×(p−c))·n/|n|²
/// where n = u×v; inside when both lie in [0, 1].
#[inline]
pub fn intersect_quad(corner: Vec3, edge_u: Vec3, edge_v: Vec3, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> f32 {
    let n = edge_u.cross(edge_v);
    let denom = n.dot(d);
    if denom.abs() < 1e-20 {
        return f32::INFINITY;
    }
    let t = n.dot(corner - o) / denom;
    if !(t > tmin && t < tmax) {
        return f32::INFINITY;
    }
    let rel = o + d * t - corner;
    let inv_nn = 1.0 / n.length_squared();
    let alpha = rel.cross(edge_v).dot(n) * inv_nn;
    let beta = edge_u.cross(rel).dot(n) * inv_nn;
    if (0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta) { t } else { f32::INFINITY }
}

/// Ray–box intersection by slabs (Kay and Kajiya 1986). A ray starting inside
/// returns the exit distance.
#[inline]
pub fn intersect_box(min: Vec3, max: Vec3, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> f32 {
    let inv = d.recip();
    let t_a = (min - o) * inv;
    let t_b = (max - o) * inv;
    let near = t_a.min(t_b).max_element();
    let far = t_a.max(t_b).min_element();
    if near > far {
        return f32::INFINITY;
    }
    if near > tmin && near < tmax {
        near
    } else if far > tmin && far < tmax {
        far
    } else {
        f32::INFINITY
    }
}

/// Ray–triangle intersection of Möller and Trumbore (1997), with the triangle
/// given as `v0` and its edges `e1 = v1 − v0`, `e2 = v2 − v0`.
#[inline]
pub fn intersect_triangle(v0: Vec3, e1: Vec3, e2: Vec3, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> f32 {
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    if det.abs() < 1e-20 {
        return f32::INFINITY;
    }
    let inv_det = 1.0 / det;
    let tvec = o - v0;
    let u = tvec.dot(pvec) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return f32::INFINITY;
    }
    let qvec = tvec.cross(e1);
    let v = d.dot(qvec) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return f32::INFINITY;
    }
    let t = e2.dot(qvec) * inv_det;
    if t > tmin && t < tmax { t } else { f32::INFINITY }
}

/// Whether the triangle blocks the open segment 0 < t < `tmax` of the ray:
/// [`intersect_triangle`]'s test without its division. With s the sign of
/// the determinant, u·|det|, v·|det| and t·|det| are its numerators times
/// s (exact), compared with |det| and `tmax`·|det|: the same answer but in
/// the last bit of a rounding, one division fewer on every shadow ray's
/// every triangle. Shadow packets repeat it operation for operation.
#[inline]
pub fn triangle_blocks(v0: Vec3, e1: Vec3, e2: Vec3, o: Vec3, d: Vec3, tmax: f32) -> bool {
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    if det.abs() < 1e-20 {
        return false;
    }
    let flip = |x: f32| f32::from_bits(x.to_bits() ^ (det.to_bits() & 0x8000_0000));
    let abs_det = det.abs();
    let tvec = o - v0;
    let u = flip(tvec.dot(pvec));
    if !(0.0 <= u && u <= abs_det) {
        return false;
    }
    let qvec = tvec.cross(e1);
    let v = flip(d.dot(qvec));
    if v < 0.0 || abs_det < u + v {
        return false;
    }
    let t = flip(e2.dot(qvec));
    0.0 < t && t < tmax * abs_det
}

/// The outward normal of an axis-aligned box at a point on its surface: the
/// axis of the face the point lies closest to.
pub fn box_normal(min: Vec3, max: Vec3, p: Vec3) -> Vec3 {
    box_face(min, max, p).map_or(Vec3::ZERO, box_face_normal)
}

/// The face of the box nearest `p`: 2·axis for the face at `min`, 2·axis +
/// 1 for the one at `max`, the first of equals; None where no distance is
/// finite (a NaN point).
#[inline]
pub(crate) fn box_face(min: Vec3, max: Vec3, p: Vec3) -> Option<usize> {
    let to_min = (p - min).abs();
    let to_max = (max - p).abs();
    let mut best = (f32::INFINITY, None);
    for axis in 0..3 {
        if to_min[axis] < best.0 {
            best = (to_min[axis], Some(2 * axis));
        }
        if to_max[axis] < best.0 {
            best = (to_max[axis], Some(2 * axis + 1));
        }
    }
    best.1
}

/// The outward normal of face `face` ([`box_face`]) of an axis-aligned box.
#[inline]
pub(crate) fn box_face_normal(face: usize) -> Vec3 {
    let e = Vec3::AXES[face / 2];
    if face % 2 == 1 { e } else { -e }
}
