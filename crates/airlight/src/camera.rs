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
        self.rays(width, height).ray(film, lens)
    }

    /// The rays of a `width`×`height` image, with what they share worked
    /// out once (the tangent of the half field of view): for many rays.
    pub fn rays(&self, width: u32, height: u32) -> CameraRays {
        let half = match self.projection {
            Projection::Perspective { fov_degrees } => (0.5 * fov_degrees.to_radians()).tan(),
            Projection::Orthographic { view_height } => 0.5 * view_height,
        };
        CameraRays { camera: *self, width: width as f32, height: height as f32, half }
    }
}

/// A camera's rays through one image size ([`Camera::rays`]).
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    camera: Camera,
    width: f32,
    height: f32,
    /// Half the image's height: the tangent of half the field of view, or
    /// half the orthographic view height.
    half: f32,
}

impl CameraRays {
    /// The ray through film point `film` and lens point `lens`: see [`Camera::ray`].
    #[inline]
    pub fn ray(&self, film: Vec2, lens: Vec2) -> Ray {
        let c = &self.camera;
        let (origin, dir) = match c.projection {
            Projection::Perspective { .. } => (c.position, self.pinhole_direction(film)),
            Projection::Orthographic { .. } => {
                let (right, up) = self.film_offsets(film);
                (c.position + c.right * right + c.up * up, c.forward)
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

    /// The rays through film points `films` and lens points `lenses`, as
    /// [`CameraRays::ray`] gives them one by one, bit for bit, appended to
    /// `out`. A pinhole's directions are worked out eight at a time
    /// in arrays, a loop that the compiler turns into SIMD lanes with the
    /// same IEEE operations. One by one, each ray's two divisions, square
    /// root and reciprocal waited on each other: a direct render of a 1.1
    /// M-triangle mesh at one thread spent 18% of its sampling time on
    /// camera rays and their samplers, and 12% with the lanes (perf).
    pub fn rays_into(&self, films: &[Vec2], lenses: &[Vec2], out: &mut Vec<Ray>) {
        assert_eq!(films.len(), lenses.len(), "one lens point per film point");
        let c = &self.camera;
        if !matches!(c.projection, Projection::Perspective { .. }) || c.aperture > 0.0 {
            out.extend(films.iter().zip(lenses).map(|(&film, &lens)| self.ray(film, lens)));
            return;
        }
        for chunk in films.chunks(RAY_LANES) {
            // Past the chunk's end, film point (0, 0): a finite direction,
            // computed and dropped.
            let (mut film_x, mut film_y) = ([0.0f32; RAY_LANES], [0.0f32; RAY_LANES]);
            for (k, film) in chunk.iter().enumerate() {
                (film_x[k], film_y[k]) = (film.x, film.y);
            }
            let dir = self.pinhole_directions(&film_x, &film_y);
            out.extend((0..chunk.len()).map(|k| Ray::new(c.position, Vec3::new(dir[0][k], dir[1][k], dir[2][k]))));
        }
    }

    /// A pinhole's unit directions through film points (x, y), lane by
    /// lane [`CameraRays::pinhole_direction`]. Not inlined: inlined into
    /// its caller's loop, the compiler left it one lane at a time.
    #[inline(never)]
    fn pinhole_directions(&self, film_x: &[f32; RAY_LANES], film_y: &[f32; RAY_LANES]) -> [[f32; RAY_LANES]; 3] {
        let mut dir = [[0.0f32; RAY_LANES]; 3];
        for k in 0..RAY_LANES {
            let d = self.pinhole_direction(Vec2::new(film_x[k], film_y[k]));
            (dir[0][k], dir[1][k], dir[2][k]) = (d.x, d.y, d.z);
        }
        dir
    }

    /// A pinhole's unit direction through film point `film`.
    #[inline(always)]
    fn pinhole_direction(&self, film: Vec2) -> Vec3 {
        let c = &self.camera;
        let (right, up) = self.film_offsets(film);
        (c.forward + c.right * right + c.up * up).normalize()
    }

    /// How far along the camera's right and up axes film point `film`
    /// lies: on the image plane at distance 1 for a pinhole, in world units
    /// for an orthographic camera.
    #[inline(always)]
    fn film_offsets(&self, film: Vec2) -> (f32, f32) {
        let (half, aspect) = (self.half, self.width / self.height);
        let ndc_x = 2.0 * film.x / self.width - 1.0;
        let ndc_y = 1.0 - 2.0 * film.y / self.height;
        (ndc_x * half * aspect, ndc_y * half)
    }
}

/// Camera rays worked out together in [`CameraRays::rays_into`]: two SSE
/// registers' worth (the instructions every x86-64 processor has, which
/// the crate is compiled for).
const RAY_LANES: usize = 8;

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

    #[test]
    fn rays_made_together_are_the_rays_made_one_by_one_bit_for_bit() {
        let pinhole = Camera::look_at(Vec3::new(0.3, 2.0, -6.0), Vec3::new(-0.2, 1.0, 0.5), Vec3::Y, 47.0);
        let cameras = [pinhole, pinhole.with_lens(0.2, 5.0), Camera::isometric(Vec3::new(1.0, 0.0, 2.0), 10.0, 50.0)];
        // Every length up to two chunks and a bit, so that partial chunks
        // (and their dropped lanes) are covered; points across the film and
        // beyond its edges.
        let mut rng = crate::sampling::Sampler::for_pixel(7, 0, 0);
        let points: Vec<(Vec2, Vec2)> = (0..2 * RAY_LANES + 3)
            .map(|_| (rng.next2() * Vec2::new(130.0, 90.0) - Vec2::splat(3.0), rng.next2()))
            .collect();
        for camera in cameras {
            let rays = camera.rays(123, 77);
            for n in 0..=points.len() {
                let (films, lenses): (Vec<Vec2>, Vec<Vec2>) = points[..n].iter().copied().unzip();
                let mut together = vec![];
                rays.rays_into(&films, &lenses, &mut together);
                let one_by_one: Vec<Ray> = points[..n].iter().map(|&(film, lens)| rays.ray(film, lens)).collect();
                let bits = |rays: &[Ray]| -> Vec<[u32; 6]> {
                    rays.iter()
                        .map(|r| {
                            let [a, b, c] = r.origin.to_array().map(f32::to_bits);
                            let [d, e, f] = r.dir.to_array().map(f32::to_bits);
                            [a, b, c, d, e, f]
                        })
                        .collect()
                };
                assert_eq!(bits(&together), bits(&one_by_one), "{camera:?}, {n} rays");
            }
        }
    }
}
