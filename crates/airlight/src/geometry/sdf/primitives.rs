//! Exact signed distances of the primitives, each in closed form: negative
//! inside, zero on the surface, positive outside, and equal in magnitude to the
//! Euclidean distance to the surface. The forms are the standard ones collected
//! by Inigo Quilez ("distance functions", iquilezles.org/articles/distfunctions)
//! and derived in Hart, "Sphere Tracing" (The Visual Computer, 1996).

use glam::{Vec2, Vec3};

/// Sphere of radius r about c: |p − c| − r.
#[inline]
pub fn sphere(p: Vec3, center: Vec3, radius: f32) -> f32 {
    (p - center).length() - radius
}

/// Axis-aligned box with centre c and half extents h: with q = |p − c| − h,
/// |max(q, 0)| + min(max(qx, qy, qz), 0). Outside, the first term is the
/// distance to the nearest point of the box; inside, the second is minus the
/// distance to the nearest face.
#[inline]
pub fn cuboid(p: Vec3, center: Vec3, half: Vec3) -> f32 {
    let q = (p - center).abs() - half;
    q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
}

/// A box with half extents h whose edges and corners are rounded with radius
/// r ≤ min(h): the box of half extents h − r grown by r (a Minkowski sum with
/// a ball), so its outer extent stays h.
#[inline]
pub fn round_box(p: Vec3, center: Vec3, half: Vec3, rounding: f32) -> f32 {
    cuboid(p, center, half - Vec3::splat(rounding)) - rounding
}

/// Torus about the y axis through c: major radius R (centre of the tube to the
/// axis), minor radius r (the tube): |(|p_xz| − R, p_y)| − r.
#[inline]
pub fn torus(p: Vec3, center: Vec3, major: f32, minor: f32) -> f32 {
    let q = p - center;
    Vec2::new(Vec2::new(q.x, q.z).length() - major, q.y).length() - minor
}

/// Capsule: all points within r of the segment [a, b]. The closest point of
/// the segment is a + h(b − a) with h = clamp((p − a)·(b − a)/|b − a|², 0, 1).
#[inline]
pub fn capsule(p: Vec3, a: Vec3, b: Vec3, radius: f32) -> f32 {
    let pa = p - a;
    let ba = b - a;
    let len2 = ba.length_squared();
    let h = if len2 > 0.0 { (pa.dot(ba) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (pa - ba * h).length() - radius
}

/// Capped cylinder of radius r whose axis runs from a to b. In the plane of
/// the axis and p the solid is a rectangle, so the distance is the 2D box
/// distance of (radial distance − r, |axial offset from the middle| − L/2).
#[inline]
pub fn cylinder(p: Vec3, a: Vec3, b: Vec3, radius: f32) -> f32 {
    let axis = b - a;
    let len = axis.length();
    let u = axis / len;
    let pa = p - a;
    let along = pa.dot(u);
    let radial = (pa - u * along).length();
    let q = Vec2::new(radial - radius, (along - 0.5 * len).abs() - 0.5 * len);
    q.max(Vec2::ZERO).length() + q.max_element().min(0.0)
}

/// Plane through a point with unit normal n, solid below it: n·(p − point).
#[inline]
pub fn plane(p: Vec3, point: Vec3, normal: Vec3) -> f32 {
    normal.dot(p - point)
}
