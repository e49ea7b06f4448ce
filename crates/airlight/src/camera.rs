//! Cameras: perspective with an optional thin lens, and orthographic with an
//! isometric preset. Right-handed world, y up; the image's right is
//! normalize(forward × up) and pixel (0, 0) is the top-left (docs/scene-format.md).

use crate::geometry::Ray;
use crate::sampling::concentric_disk;
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Vertical field of view in degrees.
    Perspective { fov_degrees: f32 },
    /// The image spans `view_height` world units vertically.
    Orthographic { view_height: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub forward: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    pub projection: Projection,
    /// Lens radius; 0 is a pinhole.
    pub aperture: f32,
    /// Distance along `forward` of the plane in focus.
    pub focus_distance: f32,
}

/// The direction an isometric camera looks along: down the diagonal (−1, −1, −1).
pub const ISOMETRIC_VIEW: Vec3 = Vec3::new(-0.577_350_3, -0.577_350_3, -0.577_350_3);

impl Camera {
    /// A pinhole perspective camera at `position` looking at `target`.
    pub fn look_at(position: Vec3, target: Vec3, up: Vec3, fov_degrees: f32) -> Self {
        Self::oriented(position, target, up, Projection::Perspective { fov_degrees })
    }

    /// An orthographic camera at `position` looking at `target`.
    pub fn orthographic(position: Vec3, target: Vec3, up: Vec3, view_height: f32) -> Self {
        Self::oriented(position, target, up, Projection::Orthographic { view_height })
    }

    /// The isometric view of `target`: orthographic, looking along
    /// (−1, −1, −1) from `distance` away, y up on screen.
    pub fn isometric(target: Vec3, view_height: f32, distance: f32) -> Self {
        Self::orthographic(target - ISOMETRIC_VIEW * distance, target, Vec3::Y, view_height)
    }

    /// Frames a camera; `up` need only not be parallel to the view direction.
    pub fn oriented(position: Vec3, target: Vec3, up: Vec3, projection: Projection) -> Self {
        let forward = (target - position).normalize();
        let right = forward.cross(up).normalize();
        let true_up = right.cross(forward);
        Camera {
            position,
            forward,
            right,
            up: true_up,
            projection,
            aperture: 0.0,
            focus_distance: (target - position).length(),
        }
    }

    /// The same camera with a thin lens of this radius focused at this distance.
    pub fn with_lens(mut self, aperture: f32, focus_distance: f32) -> Self {
        self.aperture = aperture;
        self.focus_distance = focus_distance;
        self
    }

    /// The ray through film point `film` (pixels, (0, 0) the top-left corner of
    /// the image, x right, y down) of a `width`×`height` image, through lens
    /// point `lens` (uniform in [0, 1)²; unused by a pinhole).
    pub fn ray(&self, film: Vec2, width: u32, height: u32, lens: Vec2) -> Ray {
        self.film(width, height).ray(film, lens)
    }

    /// The camera's rays through the film of a `width`×`height` image, with
    /// what every ray shares worked out once (the field of view's tangent).
    pub fn film(&self, width: u32, height: u32) -> CameraFilm {
        let half = match self.projection {
            Projection::Perspective { fov_degrees } => (0.5 * fov_degrees.to_radians()).tan(),
            Projection::Orthographic { view_height } => 0.5 * view_height,
        };
        CameraFilm { camera: *self, width: width as f32, height: height as f32, half }
    }
}

/// A [`Camera`] over an image of a given size ([`Camera::film`]): the same
/// rays as [`Camera::ray`], bit for bit, for a render's millions of them.
#[derive(Clone, Copy, Debug)]
pub struct CameraFilm {
    camera: Camera,
    width: f32,
    height: f32,
    /// Half the image's height on the plane at distance 1 (perspective) or
    /// in world units (orthographic).
    half: f32,
}

impl CameraFilm {
    /// The ray through film point `film` and lens point `lens`, as
    /// [`Camera::ray`] describes.
    #[inline]
    pub fn ray(&self, film: Vec2, lens: Vec2) -> Ray {
        let c = &self.camera;
        let aspect = self.width / self.height;
        let ndc_x = 2.0 * film.x / self.width - 1.0;
        let ndc_y = 1.0 - 2.0 * film.y / self.height;
        let half = self.half;
        let (origin, dir) = match c.projection {
            Projection::Perspective { .. } => {
                let d = c.forward + c.right * (ndc_x * half * aspect) + c.up * (ndc_y * half);
                (c.position, d.normalize())
            }
            Projection::Orthographic { .. } => {
                let o = c.position + c.right * (ndc_x * half * aspect) + c.up * (ndc_y * half);
                (o, c.forward)
            }
        };
        if c.aperture <= 0.0 {
            return Ray::new(origin, dir);
        }
        // Thin lens: all rays through one film point meet again on the plane
        // of focus, perpendicular to the view axis.
        let focus = origin + dir * (c.focus_distance / dir.dot(c.forward));
        let disk = concentric_disk(lens) * c.aperture;
        let lens_point = origin + c.right * disk.x + c.up * disk.y;
        Ray::new(lens_point, (focus - lens_point).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_forward_and_right_is_forward_cross_up() {
        let cam = Camera::look_at(Vec3::new(0.0, 2.0, -6.0), Vec3::new(0.0, 2.0, 0.0), Vec3::Y, 40.0);
        let r = cam.ray(Vec2::new(32.0, 24.0), 64, 48, Vec2::ZERO);
        assert!((r.dir - Vec3::Z).length() < 1e-6);
        // Looking down +z with y up, forward × up = z × y = −x: the image's right.
        assert!((cam.right - Vec3::NEG_X).length() < 1e-6);
        let top = cam.ray(Vec2::new(32.0, 0.0), 64, 48, Vec2::ZERO);
        let angle = top.dir.angle_between(Vec3::Z).to_degrees();
        assert!((angle - 20.0).abs() < 1e-3, "half the vertical fov: {angle}");
        assert!(top.dir.y > 0.0, "row 0 is the top");
    }

    #[test]
    fn thin_lens_rays_meet_on_the_focus_plane() {
        let cam = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 50.0).with_lens(0.3, 4.0);
        let film = Vec2::new(10.0, 30.0);
        let a = cam.ray(film, 64, 64, Vec2::new(0.1, 0.9));
        let b = cam.ray(film, 64, 64, Vec2::new(0.8, 0.2));
        let pa = a.at((4.0 - a.origin.z) / a.dir.z);
        let pb = b.at((4.0 - b.origin.z) / b.dir.z);
        assert!((pa - pb).length() < 1e-4);
        assert!((a.origin - b.origin).length() > 0.01);
    }

    #[test]
    fn isometric_looks_down_the_diagonal_with_parallel_rays() {
        let cam = Camera::isometric(Vec3::ZERO, 10.0, 50.0);
        let a = cam.ray(Vec2::new(0.0, 0.0), 64, 64, Vec2::ZERO);
        let b = cam.ray(Vec2::new(64.0, 64.0), 64, 64, Vec2::ZERO);
        assert_eq!(a.dir, b.dir);
        assert!((a.dir - ISOMETRIC_VIEW).length() < 1e-6);
        // The image height spans view_height world units.
        let spread = (a.origin - b.origin).dot(cam.up);
        assert!((spread - 10.0).abs() < 1e-4);
    }
}
