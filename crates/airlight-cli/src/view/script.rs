//! Scripted flights for `airlight view --headless --path FILE`: where the
//! camera and the lights are at each frame.
//!
//! ```toml
//! # All keys are optional; frames count from 0.
//! integrator = "preview"   # preview (default), raymarch or stochastic
//! scene_keyframes = true   # lights with no [[light]] keys below follow the
//!                          # scene's own keyframes, time = frame / (frames − 1);
//!                          # false (the default): they stay where the scene puts them
//!
//! [[camera]]               # camera keys, in increasing frame order
//! frame = 0
//! position = [2.78, 2.73, -8.0]
//! look_at = [2.78, 2.73, 0.0]
//! fov = 39.3               # optional: degrees, else the scene camera's
//!
//! [[camera]]
//! frame = 59
//! position = [1.0, 2.73, -6.0]
//! look_at = [2.78, 2.0, 2.8]
//!
//! [[light]]                # light keys: `light` is the index of the scene's
//! light = 0                # [[lights]] table, from 0; frames increase per light
//! frame = 0
//! position = [2.78, 5.487, 2.795]   # as a light's keyframes: a point or spot
//!                                   # light's position, a quad's or sphere's centre
//! ```
//!
//! Between two keys the position, look-at point and field of view are
//! interpolated linearly in the frame number; before the first key and
//! after the last they stay at the end key. Without camera keys the scene's
//! camera is used. Errors name the file, line and column, as the scene
//! loader's do.

use super::engine::Mode;
use airlight::Camera;
use airlight::assets::read_text;
use airlight::camera::Projection;
use airlight::light::{Keyframes, Light};
use airlight::scene::limits::{MAX_COORDINATE, light_extent, too_far};
use airlight::scene::{Scene, SceneError};
use glam::Vec3;
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScriptDesc {
    integrator: Option<Spanned<String>>,
    #[serde(default)]
    scene_keyframes: bool,
    #[serde(default)]
    camera: Vec<Spanned<CameraKey>>,
    #[serde(default)]
    light: Vec<Spanned<LightKey>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraKey {
    frame: Spanned<i64>,
    position: Spanned<[f32; 3]>,
    look_at: Spanned<[f32; 3]>,
    fov: Option<Spanned<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightKey {
    light: Spanned<i64>,
    frame: Spanned<i64>,
    position: Spanned<[f32; 3]>,
}

/// Largest path file read.
pub const MAX_PATH_BYTES: u64 = 16 << 20;

/// A camera key's position, look-at point and vertical fov (degrees).
type Pose = (Vec3, Vec3, Option<f32>);

/// A checked script.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    pub integrator: Option<Mode>,
    pub scene_keyframes: bool,
    camera: Vec<(u32, Pose)>,
    /// Per scene light: its keys (frame, position), empty when it has none.
    lights: Vec<Vec<(u32, Vec3)>>,
}

/// Reads and checks a script for `scene`.
pub fn load(path: &Path, scene: &Scene) -> Result<Script, SceneError> {
    let text = read_text(path, MAX_PATH_BYTES, "path file").map_err(|e| e.in_file(path))?;
    parse(&text, scene).map_err(|e| e.in_file(path))
}

/// Parses and checks a script's text for `scene`'s lights.
pub fn parse(text: &str, scene: &Scene) -> Result<Script, SceneError> {
    let at = |span: std::ops::Range<usize>, message: String| SceneError::at(text, span.start, message);
    let desc: ScriptDesc = toml::from_str(text).map_err(|e| {
        let message = e.message().trim_end().to_string();
        match e.span() {
            Some(span) => at(span, message),
            None => SceneError::new(message),
        }
    })?;
    let integrator = match &desc.integrator {
        Some(name) => Some(Mode::parse(name.get_ref()).map_err(|m| at(name.span(), m))?),
        None => None,
    };
    let point = |v: &Spanned<[f32; 3]>, what: &str| -> Result<Vec3, SceneError> {
        let p = Vec3::from_array(*v.get_ref());
        if !p.is_finite() {
            return Err(at(v.span(), format!("{what} must be three finite numbers")));
        }
        let reach = p.abs().max_element();
        if reach > MAX_COORDINATE { Err(at(v.span(), too_far(what, reach))) } else { Ok(p) }
    };
    let frame = |v: &Spanned<i64>, what: &str, last: Option<u32>| -> Result<u32, SceneError> {
        let f = u32::try_from(*v.get_ref())
            .map_err(|_| at(v.span(), format!("{what}.frame must be an integer ≥ 0, got {}", v.get_ref())))?;
        match last {
            Some(last) if f <= last => Err(at(
                v.span(),
                format!("{what}.frame must be greater than the previous key's frame ({last}), got {f}"),
            )),
            _ => Ok(f),
        }
    };

    let mut camera: Vec<(u32, Pose)> = Vec::new();
    for key in &desc.camera {
        let k = key.get_ref();
        let f = frame(&k.frame, "camera", camera.last().map(|c| c.0))?;
        let position = point(&k.position, "camera.position")?;
        let look_at = point(&k.look_at, "camera.look_at")?;
        if (look_at - position).length() < 1e-6 {
            return Err(at(k.look_at.span(), "camera.look_at must differ from camera.position".into()));
        }
        let dir = (look_at - position).normalize();
        if dir.cross(Vec3::Y).length() < 1e-4 {
            return Err(at(k.look_at.span(), "the camera cannot look straight up or down (y is up)".into()));
        }
        let fov = match &k.fov {
            Some(v) if !(v.get_ref().is_finite() && *v.get_ref() > 0.0 && *v.get_ref() < 180.0) => {
                return Err(at(v.span(), format!("camera.fov must be in (0, 180) degrees, got {}", v.get_ref())));
            }
            Some(v) if matches!(scene.camera().projection, Projection::Orthographic { .. }) => {
                return Err(at(
                    v.span(),
                    "camera.fov is for perspective cameras; this scene's camera is orthographic".into(),
                ));
            }
            Some(v) => Some(*v.get_ref()),
            None => None,
        };
        if let Some(&previous) = camera.last() {
            check_between(previous, (f, (position, look_at, fov))).map_err(|m| at(k.frame.span(), m))?;
        }
        camera.push((f, (position, look_at, fov)));
    }

    let mut lights = vec![Vec::new(); scene.lights().len()];
    for key in &desc.light {
        let k = key.get_ref();
        let index = *k.light.get_ref();
        let n = scene.lights().len();
        let light = usize::try_from(index).ok().filter(|&i| i < n).ok_or_else(|| {
            at(k.light.span(), format!("light = {index}: the scene has {n} lights, numbered 0 to {}", n as i64 - 1))
        })?;
        if scene.lights()[light].position().is_none() {
            return Err(at(k.light.span(), format!("light {light} is a distant light, which has no position to move")));
        }
        let keys: &mut Vec<(u32, Vec3)> = &mut lights[light];
        let f = frame(&k.frame, &format!("light {light}"), keys.last().map(|k| k.0))?;
        let position = point(&k.position, "light.position")?;
        let reach = light_extent(&scene.lights()[light].moved_to(position));
        if reach > MAX_COORDINATE {
            return Err(at(k.position.span(), too_far(&format!("light {light} moved there"), reach)));
        }
        keys.push((f, position));
    }
    Ok(Script { integrator, scene_keyframes: desc.scene_keyframes, camera, lights })
}

/// Why a camera at `position` looking at `look_at` (y up) cannot be framed.
fn unframeable(position: Vec3, look_at: Vec3) -> Option<&'static str> {
    if (look_at - position).length() < 1e-6 {
        return Some("would stand on its look_at point");
    }
    let dir = (look_at - position).normalize();
    (dir.cross(Vec3::Y).length() < 1e-4).then_some("would look straight up or down (y is up)")
}

/// Refuses two consecutive camera keys whose interpolation passes through
/// a camera that cannot be framed at some frame between them. The
/// direction d(s) = look_at − position is linear in s, and the frames
/// where it turns vertical are those where |d_xz|² − ε²|d|² < 0, a
/// quadratic in s: where it dips below zero at any frame, it does at the
/// frames either side of its lowest point, so only those are tried.
fn check_between(a: (u32, Pose), b: (u32, Pose)) -> Result<(), String> {
    let ((f0, (p0, l0, _)), (f1, (p1, l1, _))) = (a, b);
    let (d0, d1) = ((l0 - p0).as_dvec3(), (l1 - p1).as_dvec3());
    let e = d1 - d0;
    let eps2 = 1e-8;
    let quad = |u: glam::DVec3, v: glam::DVec3| (1.0 - eps2) * (u.x * v.x + u.z * v.z) - eps2 * u.y * v.y;
    let (qa, qb) = (quad(e, e), 2.0 * quad(d0, e));
    let vertex = if qa > 0.0 { (-qb / (2.0 * qa)).clamp(0.0, 1.0) } else { 0.0 };
    let at = f0 as f64 + vertex * (f1 - f0) as f64;
    for frame in [at.floor() as u32, at.ceil() as u32] {
        if frame <= f0 || frame >= f1 {
            continue;
        }
        let t = (frame - f0) as f32 / (f1 - f0) as f32;
        if let Some(why) = unframeable(p0.lerp(p1, t), l0.lerp(l1, t)) {
            return Err(format!(
                "between the camera keys at frames {f0} and {f1}, the camera at frame {frame} {why}: \
                 add a key between them or move one"
            ));
        }
    }
    Ok(())
}

/// The value of keyed `(frame, value)` pairs at `frame`: linear between
/// keys, held beyond the ends. `keys` is not empty and increases in frame.
fn interpolate<T: Copy>(keys: &[(u32, T)], frame: u32, lerp: impl Fn(T, T, f32) -> T) -> T {
    let i = keys.partition_point(|k| k.0 <= frame);
    if i == 0 {
        return keys[0].1;
    }
    if i == keys.len() {
        return keys[i - 1].1;
    }
    let ((f0, a), (f1, b)) = (keys[i - 1], keys[i]);
    lerp(a, b, (frame - f0) as f32 / (f1 - f0) as f32)
}

impl Script {
    /// The script used without `--path`: the scene's camera, its lights
    /// along their own keyframes.
    pub fn scene_keyframes() -> Script {
        Script { scene_keyframes: true, ..Script::default() }
    }

    /// The camera at `frame`: `scene_camera` when the script has no camera
    /// keys, else the keys' pose (with the scene camera's projection and
    /// the keys' fov where given).
    pub fn camera_at(&self, frame: u32, scene_camera: &Camera) -> Camera {
        if self.camera.is_empty() {
            return *scene_camera;
        }
        let scene_fov = match scene_camera.projection {
            Projection::Perspective { fov_degrees } => Some(fov_degrees),
            Projection::Orthographic { .. } => None,
        };
        let keys: Vec<(u32, Pose)> =
            self.camera.iter().map(|&(f, (p, l, fov))| (f, (p, l, fov.or(scene_fov)))).collect();
        let (position, look_at, fov) = interpolate(&keys, frame, |a, b, t| {
            let fov = match (a.2, b.2) {
                (Some(x), Some(y)) => Some(x + (y - x) * t),
                _ => a.2.or(b.2),
            };
            (a.0.lerp(b.0, t), a.1.lerp(b.1, t), fov)
        });
        let projection = match scene_camera.projection {
            Projection::Perspective { fov_degrees } => {
                Projection::Perspective { fov_degrees: fov.unwrap_or(fov_degrees) }
            }
            orthographic => orthographic,
        };
        Camera::oriented(position, look_at, Vec3::Y, projection)
            .with_lens(scene_camera.aperture, scene_camera.focus_distance)
    }

    /// The scene's `lights` (with their keyframe `paths`) at `frame` of
    /// `frames`: moved along the script's keys, or the scene's keyframes
    /// (with `scene_keyframes`), or as they are.
    pub fn lights_at(&self, frame: u32, frames: u32, lights: &[Light], paths: &[Option<Keyframes>]) -> Vec<Light> {
        let time = if frames > 1 { frame as f32 / (frames - 1) as f32 } else { 0.0 };
        lights
            .iter()
            .enumerate()
            .map(|(i, light)| {
                let keys = self.lights.get(i).map(Vec::as_slice).unwrap_or(&[]);
                if !keys.is_empty() {
                    light.moved_to(interpolate(keys, frame, |a, b, t| a.lerp(b, t)))
                } else if self.scene_keyframes
                    && let Some(Some(path)) = paths.get(i)
                {
                    light.moved_to(path.at(time))
                } else {
                    *light
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod fuzz;
#[cfg(test)]
mod tests;
