//! Emitting triangles whose radiance varies over them: glTF's emissive
//! textures. The triangle light itself carries the texture's mean over the
//! triangle (what its power, and so its chance among its mesh's triangles,
//! is reckoned from: `Emitters`); the radiance a ray meets or a sample
//! draws at a point is the factor times the texture there.

use crate::Rgb;
use crate::light::Light;
use crate::material::TextureMap;
use glam::{Vec2, Vec3};

/// The emission of one triangle light: `factor` × the texture at the
/// point's texture coordinates, interpolated from its corners' `uvs` (in
/// the order of the light's corners a, a + edge_1, a + edge_2).
#[derive(Clone, Debug, PartialEq)]
pub struct TexturedEmission {
    pub map: TextureMap,
    pub factor: Rgb,
    pub uvs: [Vec2; 3],
}

impl TexturedEmission {
    /// The radiance at point `x` of `light` (a triangle light; others
    /// give their own uniform radiance).
    pub fn radiance_at(&self, light: &Light, x: Vec3) -> Rgb {
        let Light::Triangle { a, edge_1, edge_2, .. } = *light else { return light.emitted(Vec3::ZERO, Vec3::ZERO) };
        let [b1, b2] = crate::geometry::barycentric_coordinates(x - a, edge_1, edge_2);
        let [t0, t1, t2] = self.uvs;
        self.factor * self.map.sample(t0 + (t1 - t0) * b1 + (t2 - t0) * b2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Texture, Wrap};
    use std::sync::Arc;

    #[test]
    fn the_radiance_follows_the_texture_across_the_triangle() {
        // A 2×1 texture, white then black, clamped; the triangle's corners
        // at u = 0, 1, 0: the radiance at each corner is the texel there.
        let texture = Texture::from_srgb8(2, 1, vec![[255; 3], [0; 3]]).unwrap();
        let map = TextureMap::new(Arc::new(texture.with_wrap(Wrap::ClampToEdge, Wrap::ClampToEdge)));
        let light = Light::triangle(Vec3::ZERO, Vec3::X, Vec3::Z, Rgb::splat(1.0));
        let e = TexturedEmission {
            map,
            factor: Rgb::new(2.0, 1.0, 0.5),
            uvs: [Vec2::new(0.0, 0.5), Vec2::new(1.0, 0.5), Vec2::new(0.0, 0.5)],
        };
        assert_eq!(e.radiance_at(&light, Vec3::ZERO), Rgb::new(2.0, 1.0, 0.5));
        assert_eq!(e.radiance_at(&light, Vec3::X), Rgb::ZERO);
        // Half way along edge_1 (u = ½): between the texel centres, half each.
        let half = e.radiance_at(&light, Vec3::new(0.5, 0.0, 0.0));
        assert!((half - Rgb::new(1.0, 0.5, 0.25)).abs().max_element() < 1e-6, "{half}");
    }
}
