//! The range of world coordinates a scene may use, and directions made
//! unit length in f64, so that no value a scene file gives turns into an
//! infinity or a zero inside the f32 arithmetic of rendering (which would
//! render black without a word).
//!
//! Rendering squares lengths, and the closed forms multiply squares: with
//! every coordinate within 10⁹ of the origin, squares stay below 10¹⁹ and
//! their products below 10³⁷, inside f32's 3.4·10³⁸.

use crate::geometry::Shape;
use crate::light::Light;
use glam::{DVec3, Vec3};

/// How far from the origin any point of a scene may lie (world units).
pub const MAX_COORDINATE: f32 = 1e9;

/// Most optical depth (σt times the peak density times the scene's
/// diameter) of a medium crossed by null collisions: beyond it a mean free
/// path is below what 32-bit positions resolve in the scene (a millionth of
/// its size), no image can show the medium's inside, and tracking would
/// take about that many steps a path (σs = 10¹⁰ was reported never to finish).
pub const MAX_OPTICAL_DEPTH: f32 = 1e6;

/// Most surfaces that may share exactly the same bounds (duplicated faces,
/// objects or instances): building a BVH over identical boxes takes time
/// that grows as the square of their number (10,000 took 3.3 s and 40,000
/// 52 s, as reported); a mesh of 4,096 copies of one face loads in
/// 0.43–0.54 s (`airlight info`, release build, Zen 4).
pub const MAX_EQUAL_BOUNDS: usize = 4096;

/// `v` scaled to unit length in f64, where its squared length cannot
/// overflow or underflow; None for zero or non-finite vectors.
pub fn unit(v: Vec3) -> Option<Vec3> {
    let d = v.as_dvec3();
    let length = d.length();
    (d.is_finite() && length > 0.0).then(|| (d / length).as_vec3())
}

/// The sine of the angle between two non-zero vectors, in f64.
pub fn sin_between(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.normalize().cross(b.normalize()).length()
}

/// The message for something that reaches `extent` from the origin.
pub fn too_far(what: &str, extent: f32) -> String {
    format!(
        "{what} reaches {extent:e} world units from the origin; a scene must lie within {MAX_COORDINATE:e} of it \
         (Airlight computes in 32-bit floats)"
    )
}

/// The largest coordinate of a point (infinite if it is not finite).
pub fn reach_of(p: Vec3) -> f32 {
    reach([p])
}

/// The largest coordinate of a set of points (infinite if one is not finite).
fn reach(points: impl IntoIterator<Item = Vec3>) -> f32 {
    points.into_iter().map(|p| if p.is_finite() { p.abs().max_element() } else { f32::INFINITY }).fold(0.0, f32::max)
}

/// How far from the origin a light reaches (its position, or the corners
/// of its surface or region); 0 for a distant light.
pub fn light_extent(light: &Light) -> f32 {
    match *light {
        Light::Point { position, .. } | Light::Spot { position, .. } => reach([position]),
        Light::Sphere { center, radius, .. } => reach([center - radius, center + radius]),
        Light::Quad { corner, edge_u, edge_v, .. } => {
            reach([corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v, edge_u, edge_v])
        }
        Light::Triangle { a, edge_1, edge_2, .. } => reach([a, a + edge_1, a + edge_2, edge_1, edge_2]),
        Light::Line { start, end, .. } => reach([start, end]),
        Light::Volume { shape, .. } => {
            let (lo, hi) = shape.bounds();
            reach([lo, hi])
        }
        Light::Distant { .. } | Light::Sky { .. } => 0.0,
    }
}

/// How far from the origin a shape reaches (for a plane, its point; for
/// an unbounded distance field, 0).
pub fn shape_extent(shape: &Shape) -> f32 {
    match shape {
        Shape::Sphere { center, radius } => reach([*center - *radius, *center + *radius]),
        Shape::Plane { point, .. } => reach([*point]),
        Shape::Quad { corner, edge_u, edge_v } => {
            reach([*corner, *corner + *edge_u, *corner + *edge_v, *corner + *edge_u + *edge_v, *edge_u, *edge_v])
        }
        Shape::Box { min, max } => reach([*min, *max]),
        Shape::Mesh { positions, .. } => reach(positions.iter().copied()),
        Shape::Sdf(sdf) => sdf.bounds().map_or(0.0, |(lo, hi)| reach([lo, hi])),
        Shape::Transformed { shape, world_from_local } => {
            let inner = shape_extent(shape);
            if !inner.is_finite() {
                return inner;
            }
            let e = DVec3::splat(inner as f64);
            let m = world_from_local;
            // The corners of the cube that holds the shape, mapped.
            let corners = (0..8).map(|i| {
                let c = DVec3::new(
                    if i & 1 == 0 { -e.x } else { e.x },
                    if i & 2 == 0 { -e.y } else { e.y },
                    if i & 4 == 0 { -e.z } else { e.z },
                );
                (glam::Mat3::from(m.matrix3).as_dmat3() * c + Vec3::from(m.translation).as_dvec3()).as_vec3()
            });
            reach(corners)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_too_long_or_short_for_f32_squares_become_unit_vectors() {
        assert_eq!(unit(Vec3::new(0.0, 1e20, 0.0)), Some(Vec3::Y));
        assert_eq!(unit(Vec3::new(0.0, 0.0, -1e-40)), Some(Vec3::NEG_Z));
        assert_eq!(unit(Vec3::ZERO), None);
        assert_eq!(unit(Vec3::new(f32::NAN, 0.0, 1.0)), None);
        assert!(sin_between(Vec3::new(1e20, 0.0, 0.0), Vec3::new(0.0, 1e-30, 0.0)) > 0.999);
    }

    #[test]
    fn extents_cover_the_whole_shape() {
        let quad = Shape::quad(Vec3::ZERO, Vec3::new(1e19, 0.0, 0.0), Vec3::Z);
        assert_eq!(shape_extent(&quad), 1e19);
        assert_eq!(shape_extent(&Shape::sphere(Vec3::new(0.0, -3.0, 0.0), 2.0)), 5.0);
        let far = Shape::sphere(Vec3::ZERO, 1.0).transformed(glam::Affine3A::from_scale(Vec3::new(1e10, 1.0, 1.0)));
        assert!(shape_extent(&far) >= 1e10);
    }
}
