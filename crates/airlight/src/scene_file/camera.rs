//! The `[camera]` table: where it stands and looks, checked so that the
//! camera it makes frames an image in f32 (positions within range, the
//! view direction and up made and compared in f64).

use super::check::{Checker, Result};
use super::desc::*;
use crate::camera::{Camera, Projection};
use crate::scene::default_camera;
use crate::scene::limits;
use glam::Vec3;

impl Checker<'_> {
    /// The camera `[camera]` describes, read by its type.
    pub(super) fn camera(&self) -> Result<Camera> {
        let read = self.read_table::<CameraDesc>(self.section("camera")?, "camera")?;
        let span = read.table.span();
        let c = &read.shared;
        let point = |v: Option<Point>, name: &str, default: Vec3| -> Result<Vec3> {
            self.finite3(span.clone(), &format!("camera.{name}"), v.map_or(default, |p| p.0))
        };
        let default = default_camera();
        let look_at = point(c.look_at, "look_at", Vec3::new(0.0, 1.0, 0.0))?;
        let up = self.direction(span.clone(), "camera.up", c.up.map_or(Vec3::Y, |p| p.0))?;
        let view_height = |h: Option<f32>| self.positive(span.clone(), "camera.view_height", h.unwrap_or(10.0));
        let (position, projection) = match &read.kind {
            CameraDesc::Perspective(p) => {
                let fov = p.fov.unwrap_or(40.0);
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(self.err_field(
                        span,
                        "fov",
                        format!("camera.fov must be between 0 and 180 degrees, got {fov}"),
                    ));
                }
                (point(p.position, "position", default.position)?, Projection::Perspective { fov_degrees: fov })
            }
            CameraDesc::Orthographic(o) => (
                point(o.position, "position", default.position)?,
                Projection::Orthographic { view_height: view_height(o.view_height)? },
            ),
            CameraDesc::Isometric(i) => {
                let distance = self.positive(span.clone(), "camera.distance", i.distance.unwrap_or(50.0))?;
                (
                    look_at - crate::camera::ISOMETRIC_VIEW * distance,
                    Projection::Orthographic { view_height: view_height(i.view_height)? },
                )
            }
        };
        let isometric = matches!(read.kind, CameraDesc::Isometric(_));
        for (name, p) in [("position", position), ("look_at", look_at)] {
            let extent = limits::reach_of(p);
            if extent > limits::MAX_COORDINATE {
                // An isometric camera's position comes from its distance.
                let name = if isometric && name == "position" { "distance" } else { name };
                return Err(self.err_field(span.clone(), name, limits::too_far(&format!("camera.{name}"), extent)));
            }
        }
        let forward = look_at - position;
        if forward == Vec3::ZERO {
            return Err(self.err_field(span, "look_at", "camera.position and camera.look_at must differ"));
        }
        if forward.try_normalize().is_none() {
            return Err(self.err_field(
                span,
                "look_at",
                format!(
                    "camera.position and camera.look_at are only {:e} apart, too close for a direction in 32-bit floats",
                    forward.as_dvec3().length()
                ),
            ));
        }
        if limits::sin_between(forward, up) < 1e-6 {
            return Err(self.err_field(span, "up", "camera.up must not be parallel to the view direction"));
        }
        let aperture = self.non_negative(span.clone(), "camera.aperture", c.aperture.unwrap_or(0.0))?;
        let focus = c.focus_distance.unwrap_or(forward.length());
        let focus = self.positive(span.clone(), "camera.focus_distance", focus)?;
        // Beyond the scene's reach a focus is at infinity; far beyond it its
        // square overflows f32 and every lens ray is lost.
        if focus > limits::MAX_COORDINATE {
            return Err(self.err_field(
                span,
                "focus_distance",
                format!(
                    "camera.focus_distance must be at most {:e}, the scene's reach (a focus that far is at \
                     infinity), got {focus:e}",
                    limits::MAX_COORDINATE
                ),
            ));
        }
        let camera = Camera::oriented(position, look_at, up, projection).with_lens(aperture, focus);
        if ![camera.forward, camera.right, camera.up].iter().all(|v| v.is_finite() && v.is_normalized()) {
            return Err(self.err(span, "the camera's view direction and up do not frame an image in 32-bit floats"));
        }
        Ok(camera)
    }
}
