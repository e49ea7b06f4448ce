//! Moving lights: one keyframe form, shared by every command that animates
//! (`airlight gi`, frame sequences, a viewer).
//!
//! In a scene file a light moves by a `keyframes` array on its `[[lights]]`
//! table:
//!
//! ```toml
//! [[lights]]
//! type = "point"
//! position = [0, 4, 0]          # the pose a still render uses
//! intensity = 20
//! keyframes = [
//!   { time = 0.0, position = [-2, 4, 0] },
//!   { time = 0.5, position = [ 0, 4, 2] },
//!   { time = 1.0, position = [ 2, 4, 0] },
//! ]
//! ```
//!
//! `time` runs over [0, 1] across the whole animation, keys in increasing
//! order; `position` is where the light is at that time: a point or spot
//! light's position, a sphere light's centre, a quad light's centre (the
//! quad is translated, its edges kept). A spot keeps its direction. Between
//! keys the position is interpolated linearly; before the first key and after
//! the last it stays at the end key. Distant lights have no position and take
//! no keyframes. A still render (`airlight render`) uses the light as written,
//! without its keyframes.

use super::{Light, LightVolume};
use glam::Vec3;

/// A light's path: positions at times in [0, 1], sorted by time.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframes {
    keys: Vec<(f32, Vec3)>,
}

impl Keyframes {
    /// A path through `(time, position)` keys; None when there are no keys,
    /// a time is outside [0, 1] or not finite, times do not increase strictly,
    /// or a position is not finite.
    pub fn new(keys: Vec<(f32, Vec3)>) -> Option<Self> {
        let ok = !keys.is_empty()
            && keys.iter().all(|(t, p)| (0.0..=1.0).contains(t) && p.is_finite())
            && keys.windows(2).all(|w| w[0].0 < w[1].0);
        ok.then_some(Keyframes { keys })
    }

    pub fn keys(&self) -> &[(f32, Vec3)] {
        &self.keys
    }

    /// The position at `time`: linear between the keys around it, held
    /// constant outside them.
    pub fn at(&self, time: f32) -> Vec3 {
        let keys = &self.keys;
        let first = keys[0];
        let last = keys[keys.len() - 1];
        // Before the first key, or NaN: the first key.
        if time.partial_cmp(&first.0) != Some(std::cmp::Ordering::Greater) {
            return first.1;
        }
        if time >= last.0 {
            return last.1;
        }
        // The first key at or after `time`; it has a predecessor since
        // time > first.0.
        let i = keys.partition_point(|k| k.0 < time);
        let (t0, p0) = keys[i - 1];
        let (t1, p1) = keys[i];
        p0.lerp(p1, (time - t0) / (t1 - t0))
    }
}

impl Light {
    /// The position that keyframes move: a point or spot light's position, a
    /// sphere's centre, a quad's centre; None for a distant light.
    pub fn position(&self) -> Option<Vec3> {
        match *self {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(position),
            Light::Sphere { center, .. } => Some(center),
            Light::Quad { corner, edge_u, edge_v, .. } => Some(corner + 0.5 * (edge_u + edge_v)),
            Light::Triangle { a, edge_1, edge_2, .. } => Some(a + (edge_1 + edge_2) / 3.0),
            Light::Line { start, end, .. } => Some(0.5 * (start + end)),
            Light::Volume { shape: LightVolume::Box { min, max }, .. } => Some(0.5 * (min + max)),
            Light::Volume { shape: LightVolume::Sphere { center, .. }, .. } => Some(center),
            Light::Distant { .. } | Light::Sky { .. } => None,
        }
    }

    /// The same light moved so that [`Light::position`] is `p` (a distant
    /// light is returned unchanged).
    pub fn moved_to(mut self, p: Vec3) -> Light {
        match &mut self {
            Light::Point { position, .. } | Light::Spot { position, .. } => *position = p,
            Light::Sphere { center, .. } => *center = p,
            Light::Quad { corner, edge_u, edge_v, .. } => *corner = p - 0.5 * (*edge_u + *edge_v),
            Light::Triangle { a, edge_1, edge_2, .. } => *a = p - (*edge_1 + *edge_2) / 3.0,
            Light::Line { start, end, .. } => {
                let half = 0.5 * (*end - *start);
                (*start, *end) = (p - half, p + half);
            }
            Light::Volume { shape: LightVolume::Box { min, max }, .. } => {
                let half = 0.5 * (*max - *min);
                (*min, *max) = (p - half, p + half);
            }
            Light::Volume { shape: LightVolume::Sphere { center, .. }, .. } => *center = p,
            Light::Distant { .. } | Light::Sky { .. } => {}
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;
    use glam::vec3;

    #[test]
    fn interpolates_linearly_and_holds_the_ends() {
        let k =
            Keyframes::new(vec![(0.2, vec3(0.0, 0.0, 0.0)), (0.6, vec3(4.0, 0.0, 0.0)), (1.0, vec3(4.0, 2.0, 0.0))])
                .unwrap();
        assert_eq!(k.at(0.0), Vec3::ZERO);
        assert_eq!(k.at(0.2), Vec3::ZERO);
        assert!((k.at(0.3) - vec3(1.0, 0.0, 0.0)).length() < 1e-6);
        assert!((k.at(0.8) - vec3(4.0, 1.0, 0.0)).length() < 1e-6);
        assert_eq!(k.at(1.0), vec3(4.0, 2.0, 0.0));
        assert_eq!(k.at(f32::NAN), Vec3::ZERO);
    }

    #[test]
    fn rejects_bad_keys() {
        assert!(Keyframes::new(vec![]).is_none());
        assert!(Keyframes::new(vec![(0.5, Vec3::ZERO), (0.5, Vec3::ONE)]).is_none());
        assert!(Keyframes::new(vec![(1.5, Vec3::ZERO)]).is_none());
        assert!(Keyframes::new(vec![(0.0, Vec3::NAN)]).is_none());
    }

    #[test]
    fn a_quad_light_moves_by_its_centre() {
        let q = Light::quad(Vec3::ZERO, Vec3::X * 2.0, Vec3::Z, Rgb::ONE);
        assert_eq!(q.position(), Some(vec3(1.0, 0.0, 0.5)));
        let moved = q.moved_to(vec3(5.0, 3.0, 5.0));
        assert_eq!(moved.position(), Some(vec3(5.0, 3.0, 5.0)));
        let Light::Quad { corner, .. } = moved else { unreachable!() };
        assert_eq!(corner, vec3(4.0, 3.0, 4.5));
    }
}
