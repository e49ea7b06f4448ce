//! Which closed shapes hold a light, and so need patches on their inside.
//!
//! A box or a sphere (or an affine image of one) is a closed surface: no
//! light crosses it. Its inner side is lit only by lights inside it, and a
//! camera inside it sees nothing else; with no light inside, the inner side
//! is black, as the integrator renders a surface that no patch covers. So
//! its inner side is cut into patches exactly when some light lies inside
//! it (or on it) where the scene places it or at one of its keyframes: a
//! room made of one box with a lamp in it, a dome, a lamp shade. Solid
//! blocks keep their outer side only, also when a light's path merely
//! crosses them between keys (a lamp carried through a table top): inner
//! patches there would only join the hierarchy's clusters with the outer
//! ones, whose mean radiosity they dilute (in scenes/room_moving_lights.toml
//! that took the image 3% darker than the path tracer). Meshes, open or
//! closed, are two-sided anyway (see [`super::patches`]).

use crate::geometry::Shape;
use crate::light::{Keyframes, Light};
use glam::{Affine3A, Vec3};

/// Whether `shape` is a closed box or sphere that holds one of `lights`
/// (within a relative 1e-4 of its surface, so that a lamp flush with a
/// ceiling counts), where the scene places it or at a key of its path in
/// `paths` (one per light).
pub fn holds_light(shape: &Shape, lights: &[Light], paths: &[Option<Keyframes>]) -> bool {
    lights.iter().enumerate().any(|(i, light)| {
        let Some(position) = light.position() else {
            return false;
        };
        let keys = paths.get(i).and_then(Option::as_ref).map_or(&[][..], |path| path.keys());
        std::iter::once(position).chain(keys.iter().map(|&(_, p)| p)).any(|p| solid_meets_segment(shape, p, p))
    })
}

/// Whether the segment [a, b] meets the closed solid of a box or sphere
/// grown by a relative 1e-4; false for shapes that are not closed solids.
fn solid_meets_segment(shape: &Shape, a: Vec3, b: Vec3) -> bool {
    match shape {
        Shape::Box { min, max } => {
            let grow = 1e-4 * (*max - *min).max_element() + 1e-6;
            segment_meets_box(a, b, *min - grow, *max + grow)
        }
        Shape::Sphere { center, radius } => {
            let grow = 1e-4 * radius + 1e-6;
            segment_distance(*center, a, b) <= radius + grow
        }
        Shape::Transformed { shape, world_from_local } => {
            let local: Affine3A = world_from_local.inverse();
            solid_meets_segment(shape, local.transform_point3(a), local.transform_point3(b))
        }
        _ => false,
    }
}

/// Whether the segment [a, b] meets the box [min, max] (slabs, Kay and
/// Kajiya 1986, on s in [0, 1]; a point when a = b).
fn segment_meets_box(a: Vec3, b: Vec3, min: Vec3, max: Vec3) -> bool {
    let d = b - a;
    let (mut near, mut far) = (0.0f32, 1.0f32);
    for axis in 0..3 {
        if d[axis] == 0.0 {
            if a[axis] < min[axis] || a[axis] > max[axis] {
                return false;
            }
            continue;
        }
        let (t0, t1) = ((min[axis] - a[axis]) / d[axis], (max[axis] - a[axis]) / d[axis]);
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    near <= far
}

/// Distance from `p` to the segment [a, b].
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 { (ab.dot(p - a) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * s).distance(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;
    use glam::{Quat, vec3};

    #[test]
    fn boxes_and_spheres_hold_the_lights_placed_or_keyed_inside_them() {
        let room = Shape::cuboid(Vec3::ZERO, vec3(4.0, 3.0, 4.0));
        let ball = Shape::sphere(vec3(10.0, 1.0, 0.0), 1.0);
        let tilted = Shape::Transformed {
            shape: Box::new(Shape::cuboid(Vec3::splat(-1.0), Vec3::splat(1.0))),
            world_from_local: Affine3A::from_scale_rotation_translation(
                vec3(2.0, 0.5, 1.0),
                Quat::from_rotation_z(0.6),
                vec3(0.0, 10.0, 0.0),
            ),
        };
        let lamp = |p: Vec3| Light::point(p, Rgb::ONE);
        let still = |p: Vec3| holds_light(&room, &[lamp(p)], &[None]);
        assert!(still(vec3(2.0, 2.0, 2.0)));
        // Flush with the ceiling, and just outside it.
        assert!(still(vec3(2.0, 3.0, 2.0)));
        assert!(!still(vec3(2.0, 3.01, 2.0)));
        assert!(holds_light(&ball, &[lamp(vec3(10.5, 1.5, 0.3))], &[None]));
        assert!(!holds_light(&ball, &[lamp(vec3(10.8, 1.8, 0.0))], &[None]));
        // (0, 10 + 0.4, 0) lies inside the tilted flat box; (0, 11, 0) does not.
        assert!(holds_light(&tilted, &[lamp(vec3(0.0, 10.4, 0.0))], &[None]));
        assert!(!holds_light(&tilted, &[lamp(vec3(0.0, 11.0, 0.0))], &[None]));
        // A light keyed inside the room, placed outside it; one whose path
        // only crosses the room between two keys outside it does not count.
        let path = Keyframes::new(vec![(0.0, vec3(-1.0, 1.0, 2.0)), (1.0, vec3(2.0, 1.0, 2.0))]);
        assert!(holds_light(&room, &[lamp(vec3(-1.0, 1.0, 2.0))], &[path]));
        let across = Keyframes::new(vec![(0.0, vec3(-1.0, 1.0, 2.0)), (1.0, vec3(5.0, 1.0, 2.0))]);
        assert!(!holds_light(&room, &[lamp(vec3(-1.0, 1.0, 2.0))], &[across]));
        // A sun is in no box; planes and quads hold nothing.
        assert!(!holds_light(&room, &[Light::distant(Vec3::NEG_Y, Rgb::ONE)], &[None]));
        assert!(!holds_light(&Shape::plane(Vec3::ZERO, Vec3::Y), &[lamp(Vec3::ZERO)], &[None]));
    }
}
