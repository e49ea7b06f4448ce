//! Scenes that can only render black: said up front (as a warning, since
//! such a scene is valid), instead of a black image and no word.

use super::Scene;
use crate::light::Light;

impl Scene {
    /// Why every pixel of this scene will be black, if it will: no light,
    /// no light that emits anything, or nothing the light can reach the
    /// camera through. `sees_medium`: whether the integrator renders the
    /// medium (`direct` does not). A non-black background is always seen.
    pub fn darkness(&self, sees_medium: bool) -> Option<String> {
        if self.settings.background.max_element() > 0.0 {
            return None;
        }
        if self.lights.is_empty() {
            return Some("the scene has no lights and a black background: the image will be black".into());
        }
        if !self.lights.iter().any(emits) {
            return Some("every light of the scene emits nothing (its power is 0): the image will be black".into());
        }
        let medium = sees_medium && self.medium.is_some();
        let light_surface = self.lights.iter().any(|l| l.surface().is_some());
        if self.objects.is_empty() && !medium && !light_surface {
            let medium_note = match (self.medium.is_some(), sees_medium) {
                (true, false) => " (this integrator ignores the medium)",
                _ => "",
            };
            return Some(format!(
                "the scene has no objects, no medium{medium_note} and no light with a surface (sphere or quad) \
                 for the camera to see: the image will be black"
            ));
        }
        None
    }
}

/// Whether a light sends out any light at all.
fn emits(light: &Light) -> bool {
    let power = match *light {
        Light::Point { intensity, .. }
        | Light::Spot { intensity, .. }
        | Light::Line { intensity, .. }
        | Light::Volume { intensity, .. } => intensity,
        Light::Sphere { radiance, .. } | Light::Quad { radiance, .. } | Light::Triangle { radiance, .. } => radiance,
        Light::Distant { irradiance, .. } => irradiance,
        Light::Sky { radiance } => radiance,
    };
    power.max_element() > 0.0
}

#[cfg(test)]
mod tests {
    use crate::prelude::*;

    fn scene(f: impl FnOnce(SceneBuilder) -> SceneBuilder) -> Scene {
        f(SceneBuilder::new().material("m", Material::diffuse(Rgb::splat(0.5)))).build().unwrap()
    }

    #[test]
    fn scenes_that_can_only_be_black_are_named() {
        let sphere = |b: SceneBuilder| b.object(Shape::sphere(Vec3::ZERO, 1.0), "m");
        let lamp = Light::point(Vec3::Y * 3.0, Rgb::splat(10.0));
        let dark = scene(sphere).darkness(true).unwrap();
        assert!(dark.starts_with("the scene has no lights"), "{dark}");
        let off = scene(|b| sphere(b).light(Light::point(Vec3::Y, Rgb::ZERO))).darkness(true).unwrap();
        assert!(off.contains("emits nothing"), "{off}");
        let empty = scene(|b| b.light(lamp)).darkness(true).unwrap();
        assert!(empty.contains("no objects"), "{empty}");
        let fog = |b: SceneBuilder| b.light(lamp).medium(Medium::homogeneous(Rgb::ZERO, Rgb::splat(0.1), 0.0));
        assert_eq!(scene(fog).darkness(true), None);
        assert!(scene(fog).darkness(false).unwrap().contains("ignores the medium"));
        assert_eq!(scene(|b| sphere(b).light(lamp)).darkness(true), None);
        let quad = Light::quad(Vec3::ZERO, Vec3::X, Vec3::Z, Rgb::ONE);
        assert_eq!(scene(|b| b.light(quad)).darkness(false), None);
    }
}
