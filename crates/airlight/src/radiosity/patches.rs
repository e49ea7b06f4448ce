//! Cutting a scene's surfaces into patches.
//!
//! A patch is one side of a small piece of surface: a parallelogram or a
//! triangle with its centre, the unit normal of the side it stands for, its
//! area and its material. Surfaces that enclose a solid (boxes, spheres) get
//! patches on their outside, and on their inside too when a light is
//! inside them (a room, a dome: see [`super::enclosures`]); open surfaces
//! (quads, planes, meshes) are two-sided (every diffuse surface reflects
//! on both sides), so each piece gives two patches, one per side.
//!
//! Sizes: a quad is cut into ⌈|u|/h⌉ × ⌈|v|/h⌉ parallelograms, so no patch
//! edge is longer than `h` = `patch_size`; a triangle into n² similar
//! triangles with n = ⌈longest edge / h⌉; a box into its six faces, each cut
//! as a quad; a sphere into a latitude–longitude grid with ⌈πr/h⌉ bands;
//! an infinite plane is cut in a square (see [`plane_square`]) and in
//! coarser rings around it out to 64 times its size (see
//! [`PLANE_RINGS`]).

use crate::geometry::Shape;
use glam::{Affine3A, Mat3, Vec3};
use std::f32::consts::PI;

/// The piece of surface a patch covers, for placing points on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchShape {
    pub origin: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
    /// A triangle (origin, origin + e1, origin + e2) rather than the
    /// parallelogram origin + s·e1 + t·e2.
    pub triangle: bool,
}

impl PatchShape {
    /// The point at (s, t) in [0, 1]²: on the parallelogram, or on the
    /// triangle by the square-to-triangle map (1 − √s, t√s), uniform in area.
    #[inline]
    pub fn point(&self, s: f32, t: f32) -> Vec3 {
        if self.triangle {
            let r = s.sqrt();
            self.origin + self.e1 * (1.0 - r) + self.e2 * (t * r)
        } else {
            self.origin + self.e1 * s + self.e2 * t
        }
    }

    /// n² points of equal area weight covering the shape: the midpoints of
    /// an n×n grid of the parallelogram, or the centroids of the n² similar
    /// sub-triangles of the triangle.
    pub fn quadrature_points(&self, n: usize, out: &mut Vec<Vec3>) {
        out.clear();
        let inv = 1.0 / n as f32;
        if self.triangle {
            for i in 0..n {
                for j in 0..n - i {
                    // Upward sub-triangle with corner (i, j) in edge units.
                    let (a, b) = (i as f32, j as f32);
                    out.push(self.origin + (self.e1 * (a + 1.0 / 3.0) + self.e2 * (b + 1.0 / 3.0)) * inv);
                    if i + j + 1 < n {
                        out.push(self.origin + (self.e1 * (a + 2.0 / 3.0) + self.e2 * (b + 2.0 / 3.0)) * inv);
                    }
                }
            }
        } else {
            for i in 0..n {
                for j in 0..n {
                    let (s, t) = ((i as f32 + 0.5) * inv, (j as f32 + 0.5) * inv);
                    out.push(self.point(s, t));
                }
            }
        }
    }
}

/// One side of a small piece of surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    pub center: Vec3,
    /// Unit normal of the side this patch stands for.
    pub normal: Vec3,
    pub area: f32,
    /// Largest distance from the centre to a point of the patch.
    pub radius: f32,
    pub material: u32,
    /// Index of the object in `Scene::objects` the patch was cut from.
    pub object: u32,
    pub shape: PatchShape,
}

/// Appends the patches of `shape` (material `material`, object `object`),
/// cut to size `h`; a box or sphere gets inner sides too when `inner`.
/// Planes are clipped to the square of [`plane_square`] around `center`
/// with half side `half`.
pub fn cut(
    shape: &Shape,
    material: u32,
    object: u32,
    h: f32,
    (center, half): (Vec3, f32),
    inner: bool,
    out: &mut Vec<Patch>,
) {
    let start = out.len();
    match shape {
        // Signed distance fields are not cut into patches (yet): they
        // neither receive nor pass on bounce light.
        Shape::Sdf(_) => {}
        Shape::Quad { corner, edge_u, edge_v } => cut_quad(*corner, *edge_u, *edge_v, h, true, out),
        Shape::Plane { point, normal } => {
            let (corner, u, v) = plane_square(*point, *normal, center, half);
            cut_quad(corner, u, v, h, true, out);
            cut_plane_rings(corner + 0.5 * (u + v), 0.5 * u, 0.5 * v, out);
        }
        Shape::Box { min, max } => cut_box(*min, *max, h, inner, out),
        Shape::Sphere { center, radius } => cut_sphere(*center, *radius, h, inner, out),
        Shape::Mesh { positions, triangles, .. } => {
            for tri in triangles {
                let [a, b, c] = tri.map(|i| positions[i as usize]);
                cut_triangle(a, b, c, h, out);
            }
        }
        Shape::Transformed { shape, world_from_local } => {
            let linear = Mat3::from(world_from_local.matrix3);
            let stretch = linear.x_axis.length().max(linear.y_axis.length()).max(linear.z_axis.length());
            let mut local = Vec::new();
            cut(shape, material, object, h / stretch, (center, half), inner, &mut local);
            out.extend(local.iter().map(|p| transform(p, *world_from_local)));
        }
    }
    for p in &mut out[start..] {
        p.material = material;
        p.object = object;
    }
}

/// How many patches [`cut`] makes of `shape` (without making them), so
/// that a patch size far too small for the scene is refused before memory
/// runs out; boxes and spheres are counted with both sides.
pub fn count(shape: &Shape, h: f32, (center, half): (Vec3, f32)) -> f64 {
    let quad = |u: Vec3, v: Vec3| cells(u.length(), h) as f64 * cells(v.length(), h) as f64;
    match shape {
        Shape::Sdf(_) => 0.0,
        Shape::Quad { edge_u, edge_v, .. } => 2.0 * quad(*edge_u, *edge_v),
        Shape::Plane { point, normal } => {
            let (_, u, v) = plane_square(*point, *normal, center, half);
            2.0 * (quad(u, v) + (PLANE_RINGS * RING_CELLS) as f64)
        }
        Shape::Box { min, max } => {
            let d = *max - *min;
            let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
            2.0 * (quad(x, y) + quad(y, z) + quad(x, z))
        }
        Shape::Sphere { radius, .. } => {
            let bands = cells(PI * radius, h).max(2) as f64;
            2.0 * bands * (cells(2.0 * PI * radius, h).max(3) as f64)
        }
        Shape::Mesh { positions, triangles, .. } => triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                let longest = (b - a).length().max((c - a).length()).max((c - b).length());
                2.0 * (cells(longest, h).min(256) as f64).powi(2)
            })
            .sum(),
        Shape::Transformed { shape, world_from_local } => {
            let linear = Mat3::from(world_from_local.matrix3);
            let stretch = linear.x_axis.length().max(linear.y_axis.length()).max(linear.z_axis.length());
            count(shape, h / stretch, (center, half))
        }
    }
}

/// The square an infinite plane is clipped to: centred on the projection of
/// `center` onto the plane, with half side `half`; returns (corner, u, v)
/// with u × v along `normal`.
pub fn plane_square(point: Vec3, normal: Vec3, center: Vec3, half: f32) -> (Vec3, Vec3, Vec3) {
    let n = normal.normalize();
    let c = center - n * n.dot(center - point);
    let (t, b) = crate::sampling::basis(n);
    // basis gives t × b = n.
    (c - (t + b) * half, t * (2.0 * half), b * (2.0 * half))
}

fn transform(p: &Patch, m: Affine3A) -> Patch {
    let linear = Mat3::from(m.matrix3);
    let normal_to_world = linear.inverse().transpose();
    let shape = PatchShape {
        origin: m.transform_point3(p.shape.origin),
        e1: linear * p.shape.e1,
        e2: linear * p.shape.e2,
        triangle: p.shape.triangle,
    };
    let old = p.shape.e1.cross(p.shape.e2).length();
    let new = shape.e1.cross(shape.e2).length();
    let scale = if old > 0.0 { new / old } else { 1.0 };
    let center = m.transform_point3(p.center);
    Patch {
        center,
        normal: (normal_to_world * p.normal).normalize(),
        area: p.area * scale,
        radius: corners(&shape).iter().map(|c| c.distance(center)).fold(0.0, f32::max),
        shape,
        ..*p
    }
}

fn corners(s: &PatchShape) -> Vec<Vec3> {
    if s.triangle {
        vec![s.origin, s.origin + s.e1, s.origin + s.e2]
    } else {
        vec![s.origin, s.origin + s.e1, s.origin + s.e2, s.origin + s.e1 + s.e2]
    }
}

fn push_flat(shape: PatchShape, normal: Vec3, two_sided: bool, out: &mut Vec<Patch>) {
    let cross = shape.e1.cross(shape.e2).length();
    let (area, center) = if shape.triangle {
        (0.5 * cross, shape.origin + (shape.e1 + shape.e2) / 3.0)
    } else {
        (cross, shape.origin + 0.5 * (shape.e1 + shape.e2))
    };
    if area.is_nan() || area <= 0.0 {
        return;
    }
    let radius = corners(&shape).iter().map(|c| c.distance(center)).fold(0.0, f32::max);
    let patch = Patch { center, normal, area, radius, material: 0, object: 0, shape };
    out.push(patch);
    if two_sided {
        out.push(Patch { normal: -normal, ..patch });
    }
}

fn cells(length: f32, h: f32) -> usize {
    ((length / h).ceil() as usize).clamp(1, 1 << 16)
}

fn cut_quad(corner: Vec3, u: Vec3, v: Vec3, h: f32, two_sided: bool, out: &mut Vec<Patch>) {
    let n = u.cross(v).normalize();
    let (nu, nv) = (cells(u.length(), h), cells(v.length(), h));
    let (du, dv) = (u / nu as f32, v / nv as f32);
    for i in 0..nu {
        for j in 0..nv {
            let shape = PatchShape { origin: corner + du * i as f32 + dv * j as f32, e1: du, e2: dv, triangle: false };
            push_flat(shape, n, two_sided, out);
        }
    }
}

/// How many square rings of coarse patches surround a plane's square,
/// each twice as wide as the one inside it: out to 2⁶ = 64 times the
/// square's half side.
pub const PLANE_RINGS: u32 = 6;
/// Patches per ring (per side): an 8 × 8 grid less its 4 × 4 middle.
const RING_CELLS: u32 = 48;

/// Cuts the rings around a plane's square (centre `c`, half sides `hu`,
/// `hv`): ring k spans 2^(k−1) to 2^k half sides, as 48 patches of a
/// quarter of its width, two-sided. The light an infinite plane sends up
/// from beyond a distance D falls only as h/(2D) on a wall at height h
/// facing along it, so a square around the objects alone misses much of a
/// sunlit floor's bounce (a box's side 3 units above the floor got a fifth
/// of the path tracer's light, the differential test's seed 3122); far
/// away the floor's light is smooth, so patches as large as their distance
/// over two suffice there.
fn cut_plane_rings(c: Vec3, hu: Vec3, hv: Vec3, out: &mut Vec<Patch>) {
    let n = hu.cross(hv).normalize();
    for k in 1..=PLANE_RINGS {
        let scale = (1u32 << k) as f32;
        let (du, dv) = (hu * scale / 4.0, hv * scale / 4.0);
        let corner = c - (hu + hv) * scale;
        for i in 0..8 {
            for j in 0..8 {
                if (2..6).contains(&i) && (2..6).contains(&j) {
                    continue;
                }
                let shape =
                    PatchShape { origin: corner + du * i as f32 + dv * j as f32, e1: du, e2: dv, triangle: false };
                push_flat(shape, n, true, out);
            }
        }
    }
}

fn cut_box(min: Vec3, max: Vec3, h: f32, inner: bool, out: &mut Vec<Patch>) {
    let d = max - min;
    let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
    // Each face as (corner, u, v) with u × v pointing outward.
    let faces = [
        (min, z, y),     // −x
        (min + x, y, z), // +x
        (min, x, z),     // −y
        (min + y, z, x), // +y
        (min, y, x),     // −z
        (min + z, x, y), // +z
    ];
    for (corner, u, v) in faces {
        cut_quad(corner, u, v, h, inner, out);
    }
}

fn cut_triangle(a: Vec3, b: Vec3, c: Vec3, h: f32, out: &mut Vec<Patch>) {
    let normal = (b - a).cross(c - a);
    if normal.length_squared() == 0.0 {
        return;
    }
    let normal = normal.normalize();
    let longest = (b - a).length().max((c - a).length()).max((c - b).length());
    let n = cells(longest, h).min(256);
    let (e1, e2) = ((b - a) / n as f32, (c - a) / n as f32);
    for i in 0..n {
        for j in 0..n - i {
            let o = a + e1 * i as f32 + e2 * j as f32;
            push_flat(PatchShape { origin: o, e1, e2, triangle: true }, normal, true, out);
            if i + j + 1 < n {
                // The downward triangle between the three upward ones.
                push_flat(PatchShape { origin: o + e1 + e2, e1: -e1, e2: -e2, triangle: true }, normal, true, out);
            }
        }
    }
}

/// Latitude–longitude patches; each has the exact area of its zone piece,
/// r²·Δφ·(cos θ0 − cos θ1), and a parallelogram shape tangent at its centre
/// with that area. With `inner`, each piece also gives an inward patch,
/// whose shape is moved inward by 1.5 sagittas (ρ²/2r for a shape of
/// half-diagonal ρ): a tangent parallelogram bulges out of the sphere, so
/// the points near its corners lie behind the inner side, where rays
/// between neighbouring inner patches would be stopped by the sphere.
fn cut_sphere(center: Vec3, r: f32, h: f32, inner: bool, out: &mut Vec<Patch>) {
    let bands = cells(PI * r, h).max(2);
    for i in 0..bands {
        let (t0, t1) = (PI * i as f32 / bands as f32, PI * (i + 1) as f32 / bands as f32);
        let tm = 0.5 * (t0 + t1);
        let ring = 2.0 * PI * r * tm.sin().max((t1 - t0) * 0.5);
        let slices = cells(ring, h).max(3);
        let dphi = 2.0 * PI / slices as f32;
        let area = r * r * dphi * (t0.cos() - t1.cos());
        for j in 0..slices {
            let pm = (j as f32 + 0.5) * dphi;
            let n = Vec3::new(tm.sin() * pm.cos(), tm.cos(), tm.sin() * pm.sin());
            let c = center + n * r;
            let along_phi = Vec3::new(-pm.sin(), 0.0, pm.cos());
            let along_theta = n.cross(along_phi).normalize_or(Vec3::X);
            let height = r * (t1 - t0);
            let width = area / height;
            let shape = PatchShape {
                origin: c - 0.5 * (along_phi * width + along_theta * height),
                e1: along_phi * width,
                e2: along_theta * height,
                triangle: false,
            };
            let patch = Patch {
                center: c,
                normal: n,
                area,
                radius: 0.5 * (width * width + height * height).sqrt(),
                material: 0,
                object: 0,
                shape,
            };
            out.push(patch);
            if inner {
                let sagitta = patch.radius * patch.radius / (2.0 * r);
                let shape = PatchShape { origin: shape.origin - n * (1.5 * sagitta), ..shape };
                out.push(Patch { normal: -n, shape, ..patch });
            }
        }
    }
}

/// What may lie in front of a patch: an object's convex hull or a convex
/// solid around it, given by its support function, or an infinite plane.
/// A box or sphere (or an affine image of one) is its own hull, so that
/// its outer side, with nothing else in front of it, sees nothing of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extent {
    /// The parallelepiped center + M u, u in [−1, 1]³ (M's columns: the
    /// half edges): a box, a transformed box, or the bounding box of
    /// anything else.
    Box {
        center: Vec3,
        half_edges: Mat3,
    },
    /// The ellipsoid center + M u, |u| ≤ 1: a sphere, a transformed sphere.
    Ellipsoid {
        center: Vec3,
        axes: Mat3,
    },
    Plane {
        point: Vec3,
        normal: Vec3,
    },
}

impl Extent {
    /// The extent of `shape`.
    pub fn of(shape: &Shape) -> Extent {
        match shape {
            Shape::Sdf(sdf) => match sdf.bounds() {
                Some((lo, hi)) => Extent::bounds(lo, hi),
                None => Extent::bounds(Vec3::ZERO, Vec3::ZERO),
            },
            Shape::Plane { point, normal } => Extent::Plane { point: *point, normal: *normal },
            Shape::Sphere { center, radius } => {
                Extent::Ellipsoid { center: *center, axes: Mat3::from_diagonal(Vec3::splat(*radius)) }
            }
            Shape::Quad { corner, edge_u, edge_v } => {
                Extent::points(&[*corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v])
            }
            Shape::Box { min, max } => Extent::bounds(*min, *max),
            Shape::Mesh { positions, .. } => Extent::points(positions),
            Shape::Transformed { shape, world_from_local } => {
                let linear = Mat3::from(world_from_local.matrix3);
                match Extent::of(shape) {
                    Extent::Box { center, half_edges } => Extent::Box {
                        center: world_from_local.transform_point3(center),
                        half_edges: linear * half_edges,
                    },
                    Extent::Ellipsoid { center, axes } => {
                        Extent::Ellipsoid { center: world_from_local.transform_point3(center), axes: linear * axes }
                    }
                    // Shape::transformed bakes planes; an instanced one is
                    // mapped here all the same.
                    Extent::Plane { point, normal } => Extent::Plane {
                        point: world_from_local.transform_point3(point),
                        normal: (linear.inverse().transpose() * normal).normalize(),
                    },
                }
            }
        }
    }

    fn bounds(lo: Vec3, hi: Vec3) -> Extent {
        Extent::Box { center: 0.5 * (lo + hi), half_edges: Mat3::from_diagonal(0.5 * (hi - lo)) }
    }

    fn points(points: &[Vec3]) -> Extent {
        let lo = points.iter().copied().fold(Vec3::MAX, Vec3::min);
        let hi = points.iter().copied().fold(Vec3::MIN, Vec3::max);
        Extent::bounds(lo, hi)
    }

    /// Whether some of it lies strictly in front of the plane through `p`
    /// with unit normal `n` (beyond a tolerance `eps`): its support
    /// function h(n) = max over its points x of n·x exceeds n·p. For the
    /// parallelepiped h(n) = n·c + Σ_i |n·m_i|, for the ellipsoid
    /// h(n) = n·c + |Mᵀ n|.
    pub fn in_front(&self, p: Vec3, n: Vec3, eps: f32) -> bool {
        match *self {
            Extent::Box { center, half_edges: m } => {
                let reach = n.dot(m.x_axis).abs() + n.dot(m.y_axis).abs() + n.dot(m.z_axis).abs();
                n.dot(center - p) + reach > eps
            }
            Extent::Ellipsoid { center, axes } => n.dot(center - p) + (axes.transpose() * n).length() > eps,
            Extent::Plane { point, normal } => {
                let parallel = n.cross(normal).length_squared() < 1e-12;
                !parallel || n.dot(point - p) > eps
            }
        }
    }
}

/// Whether any object's extent lies in front of patch `p`. A side with
/// nothing in front of it sees nothing and is seen by nothing, so it
/// exchanges no light (the outside of a closed room or dome, the underside
/// of a floor): such sides are dropped before linking. Conservative: a side
/// is kept whenever an extent reaches in front of it.
pub fn faces_anything(p: &Patch, extents: &[Extent]) -> bool {
    let eps = 1e-5 * (1.0 + p.center.abs().max_element());
    extents.iter().any(|e| e.in_front(p.center, p.normal, eps))
}
