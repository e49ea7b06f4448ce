//! What the keys and the mouse do, free of any window library so that it
//! can be tested without a display: a fly camera driven by [`Controls`],
//! and how the arrow keys move a light.

use airlight::camera::{Camera, Projection};
use glam::{Vec2, Vec3};

/// Radians the view turns per pixel the mouse is dragged.
pub const LOOK_PER_PIXEL: f32 = 0.004;
/// Factor the speed changes by per wheel notch or +/- press.
pub const SPEED_STEP: f32 = 1.25;
/// The view stops this short of straight up or down, where "up" would be
/// parallel to the view and the camera's frame undefined.
const PITCH_LIMIT: f32 = 89.0 * std::f32::consts::PI / 180.0;

/// One frame's input, in the camera's terms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Controls {
    /// Movement wanted, each in [−1, 1]: x right (D − A), y up (E − Q), z
    /// forward (W − S).
    pub walk: Vec3,
    /// Pixels the mouse was dragged with the left button down (x right, y
    /// down), since the last frame.
    pub drag: Vec2,
    /// Wheel notches (and +/− presses) since the last frame: positive is faster.
    pub speed_steps: f32,
}

/// A camera that flies: a position, a heading (yaw about +y) and a pitch,
/// moved at `speed` world units per second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub position: Vec3,
    /// Radians about +y; 0 looks along +z.
    pub yaw: f32,
    /// Radians above the horizon.
    pub pitch: f32,
    pub speed: f32,
    projection: Projection,
    aperture: f32,
    focus_distance: f32,
}

impl FlyCamera {
    /// Takes over `camera` (its projection and lens too); `speed` in world
    /// units per second.
    pub fn from_camera(camera: &Camera, speed: f32) -> Self {
        let f = camera.forward.normalize();
        FlyCamera {
            position: camera.position,
            yaw: f.x.atan2(f.z),
            pitch: f.y.clamp(-1.0, 1.0).asin().clamp(-PITCH_LIMIT, PITCH_LIMIT),
            speed,
            projection: camera.projection,
            aperture: camera.aperture,
            focus_distance: camera.focus_distance,
        }
    }

    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(cp * sy, sp, cp * cy)
    }

    /// The horizontal forward and right directions (unit), as the image's
    /// right is forward × up (the library's camera convention).
    pub fn ground_axes(&self) -> (Vec3, Vec3) {
        let (sy, cy) = self.yaw.sin_cos();
        let forward = Vec3::new(sy, 0.0, cy);
        (forward, forward.cross(Vec3::Y))
    }

    pub fn camera(&self) -> Camera {
        let c = Camera::oriented(self.position, self.position + self.forward(), Vec3::Y, self.projection);
        c.with_lens(self.aperture, self.focus_distance)
    }

    /// Applies one frame's input over `dt` seconds; returns whether the view
    /// changed (a speed change alone does not change it).
    pub fn apply(&mut self, c: &Controls, dt: f32) -> bool {
        if c.speed_steps != 0.0 {
            self.speed = (self.speed * SPEED_STEP.powf(c.speed_steps)).clamp(1e-3, 1e4);
        }
        let before = (self.position, self.yaw, self.pitch);
        if c.drag != Vec2::ZERO {
            // Dragging right turns right, dragging up looks up.
            self.yaw -= c.drag.x * LOOK_PER_PIXEL;
            self.pitch = (self.pitch - c.drag.y * LOOK_PER_PIXEL).clamp(-PITCH_LIMIT, PITCH_LIMIT);
        }
        if c.walk != Vec3::ZERO {
            let forward = self.forward();
            let right = forward.cross(Vec3::Y).normalize();
            let step = right * c.walk.x + Vec3::Y * c.walk.y + forward * c.walk.z;
            self.position += step.normalize_or_zero() * self.speed * dt;
        }
        before != (self.position, self.yaw, self.pitch)
    }
}

/// Where the arrow keys and PageUp/PageDown take a light at `p`: `dir.x`
/// right and `dir.z` forward along the ground as the camera sees it,
/// `dir.y` straight up, at the camera's speed, over `dt` seconds.
pub fn nudge(p: Vec3, camera: &FlyCamera, dir: Vec3, dt: f32) -> Vec3 {
    let (forward, right) = camera.ground_axes();
    let step = right * dir.x + Vec3::Y * dir.y + forward * dir.z;
    p + step.normalize_or_zero() * camera.speed * dt
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::vec3;

    fn cam() -> FlyCamera {
        let c = Camera::look_at(vec3(1.0, 2.0, -5.0), vec3(1.0, 2.0, 0.0), Vec3::Y, 40.0);
        FlyCamera::from_camera(&c, 2.0)
    }

    #[test]
    fn takes_over_a_camera_unchanged() {
        let original = Camera::look_at(vec3(1.0, 2.0, -5.0), vec3(3.0, 0.5, 1.0), Vec3::Y, 40.0);
        let c = FlyCamera::from_camera(&original, 1.0).camera();
        assert!((c.position - original.position).length() < 1e-6);
        assert!((c.forward - original.forward).length() < 1e-5);
        assert!((c.right - original.right).length() < 1e-5);
    }

    #[test]
    fn w_moves_forward_at_speed_and_d_to_the_image_right() {
        let mut f = cam();
        assert!(f.apply(&Controls { walk: Vec3::Z, ..Default::default() }, 0.5));
        assert!((f.position - vec3(1.0, 2.0, -4.0)).length() < 1e-5, "{}", f.position);
        let right = f.camera().right;
        let mut g = cam();
        g.apply(&Controls { walk: Vec3::X, ..Default::default() }, 1.0);
        assert!(((g.position - cam().position) - right * 2.0).length() < 1e-5);
        let mut h = cam();
        h.apply(&Controls { walk: Vec3::Y, ..Default::default() }, 1.0);
        assert!((h.position.y - 4.0).abs() < 1e-5);
    }

    #[test]
    fn dragging_right_turns_right_and_up_looks_up_but_never_past_vertical() {
        let mut f = cam();
        let right = f.camera().right;
        f.apply(&Controls { drag: Vec2::new(50.0, 0.0), ..Default::default() }, 0.0);
        assert!(f.forward().dot(right) > 0.1);
        let mut g = cam();
        g.apply(&Controls { drag: Vec2::new(0.0, -50.0), ..Default::default() }, 0.0);
        assert!(g.forward().y > 0.1);
        g.apply(&Controls { drag: Vec2::new(0.0, -1e6), ..Default::default() }, 0.0);
        let c = g.camera();
        assert!(c.forward.is_finite() && c.right.is_finite() && c.forward.y < 1.0);
    }

    #[test]
    fn speed_steps_scale_the_speed_without_moving() {
        let mut f = cam();
        assert!(!f.apply(&Controls { speed_steps: 2.0, ..Default::default() }, 1.0));
        assert!((f.speed - 2.0 * 1.5625).abs() < 1e-5);
    }

    #[test]
    fn arrows_move_a_light_along_the_ground_as_the_camera_sees_it() {
        let f = cam();
        let p = nudge(Vec3::ZERO, &f, Vec3::Z, 1.0);
        assert!((p - vec3(0.0, 0.0, 2.0)).length() < 1e-5);
        let q = nudge(Vec3::ZERO, &f, Vec3::X, 1.0);
        assert!((q - f.camera().right * 2.0).length() < 1e-5);
        assert_eq!(nudge(Vec3::ZERO, &f, Vec3::Y, 0.5), vec3(0.0, 1.0, 0.0));
    }
}
