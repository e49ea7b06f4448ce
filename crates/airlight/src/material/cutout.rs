//! Cut-outs: surfaces with a coverage (glTF's alpha) that rays pass
//! through where it is low, as leaves cut out of a quad are. The geometry
//! tests a hit against its material's cut-out and goes on past it
//! ([`crate::geometry::Geometry`]), for camera rays, bounces and shadow
//! rays alike, so cut-outs cast the shadows of their shapes.

use super::TextureMap;
use glam::Vec2;

/// What a cut-out does with its coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// glTF's MASK: opaque where the coverage is at least `cutoff`, open
    /// elsewhere.
    Mask { cutoff: f32 },
    /// glTF's BLEND, as stochastic transparency: a ray passes with chance
    /// one minus the coverage (a number hashed from the ray's hit decides,
    /// so the same ray always does the same), which on average lets
    /// through the light a blended layer would.
    Blend,
}

/// A surface's coverage: `factor` (glTF's base colour alpha) times the
/// alpha of `map` (the base colour texture's) at the hit's texture
/// coordinates, and what the mode does with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Cutout {
    pub factor: f32,
    pub map: Option<TextureMap>,
    pub mode: AlphaMode,
}

impl Cutout {
    /// The coverage at texture coordinates `uv` (the factor alone where a
    /// surface has none).
    pub fn coverage(&self, uv: Option<Vec2>) -> f32 {
        match (&self.map, uv) {
            (Some(map), Some(uv)) => {
                let uv = map.transform.apply(uv);
                self.factor * map.texture.alpha(uv.x, uv.y)
            }
            _ => self.factor,
        }
    }

    /// Whether a ray passes through the surface at `uv`; `u` in [0, 1) is
    /// the ray's own number for [`AlphaMode::Blend`].
    pub fn passes(&self, uv: Option<Vec2>, u: f32) -> bool {
        let coverage = self.coverage(uv);
        match self.mode {
            AlphaMode::Mask { cutoff } => coverage < cutoff,
            AlphaMode::Blend => u >= coverage,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Texture;
    use std::sync::Arc;

    #[test]
    fn a_mask_opens_where_the_coverage_is_below_its_cutoff_and_a_blend_by_chance() {
        // Alpha 255 then 0 along u, repeating: the filtered coverage is 1 at
        // u = ¼, 0 at ¾, and ½ at u = 0 and ½.
        let texture = Texture::from_srgb8(2, 1, vec![[9; 3], [9; 3]]).unwrap().with_alpha(vec![255, 0]).unwrap();
        let map = TextureMap::new(Arc::new(texture));
        let mask = Cutout { factor: 1.0, map: Some(map.clone()), mode: AlphaMode::Mask { cutoff: 0.5 } };
        assert!(!mask.passes(Some(Vec2::new(0.25, 0.5)), 0.0));
        assert!(mask.passes(Some(Vec2::new(0.75, 0.5)), 0.0));
        // The open fraction along u is one half.
        let open = (0..1000).filter(|i| mask.passes(Some(Vec2::new((*i as f32 + 0.5) / 1000.0, 0.5)), 0.0)).count();
        assert_eq!(open, 500);
        // Half the factor halves the coverage: a blend passes where u ≥ ½
        // at the opaque texel.
        let blend = Cutout { factor: 0.5, map: Some(map), mode: AlphaMode::Blend };
        assert!(blend.passes(Some(Vec2::new(0.25, 0.5)), 0.6) && !blend.passes(Some(Vec2::new(0.25, 0.5)), 0.4));
        // Without texture coordinates, the factor.
        assert!((blend.coverage(None) - 0.5).abs() < 1e-7);
    }
}
