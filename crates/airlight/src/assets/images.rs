//! Image files that textures are read from: found under the asset rules
//! ([`super::AssetPath`]), decoded ([`crate::texture::Texture::decode`]), their
//! memory counted with the meshes', and read once per scene however many
//! materials use them.

use super::{Loader, MAX_MESH_BYTES, read_limited};
use crate::texture::Texture;
use std::sync::Arc;

/// Most texels a texture may have (16384²).
pub(crate) const MAX_TEXTURE_PIXELS: u64 = 1 << 28;

impl Loader<'_> {
    /// The texture in the image file `name` (relative to the scene's
    /// folder or an asset folder), repeating in u and v; or why not.
    pub(crate) fn texture_file(&self, name: &str) -> Result<Arc<Texture>, String> {
        let path = self.resolve(name)?;
        if let Some((_, t)) = self.textures.borrow().iter().find(|(p, _)| *p == path) {
            return Ok(t.clone());
        }
        let bytes = read_limited(&path, MAX_MESH_BYTES).map_err(|why| format!("`{name}`: {why}"))?;
        let texture = Arc::new(self.texture_bytes(&bytes, name).map_err(|why| format!("`{name}`: {why}"))?);
        self.record(path.clone());
        self.textures.borrow_mut().push((path, texture.clone()));
        Ok(texture)
    }

    /// A texture decoded from image bytes, its memory counted; `what`
    /// names it in the memory message (the caller places other errors).
    pub(crate) fn texture_bytes(&self, bytes: &[u8], what: &str) -> Result<Texture, String> {
        let texture = Texture::decode(bytes, MAX_TEXTURE_PIXELS)?;
        let (w, h) = texture.size();
        let per_texel = if texture.has_alpha() { 4 } else { 3 };
        self.reserve(w as u64 * h as u64 * per_texel, || {
            format!("the scene's meshes and textures ({w}×{h} in {what})")
        })?;
        Ok(texture)
    }
}
