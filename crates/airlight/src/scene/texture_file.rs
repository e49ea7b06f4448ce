//! Image files that textures are read from: found under the asset rules
//! ([`super::assets`]), decoded ([`crate::texture::Texture::decode`]), their
//! memory counted with the meshes', and read once per scene however many
//! materials use them.

use super::assets::{MAX_MESH_BYTES, read_limited};
use super::build::Checker;
use crate::texture::Texture;
use std::sync::Arc;

/// Most texels a texture may have (16384²).
pub(super) const MAX_TEXTURE_PIXELS: u64 = 1 << 28;

impl Checker<'_> {
    /// The texture in the image file `name` (relative to the scene's
    /// folder or an asset folder), repeating in u and v; or why not.
    pub(super) fn texture_file(&self, name: &str) -> Result<Arc<Texture>, String> {
        let path = self.assets.resolve(name)?;
        if let Some((_, t)) = self.textures.borrow().iter().find(|(p, _)| *p == path) {
            return Ok(t.clone());
        }
        let bytes = read_limited(&path, MAX_MESH_BYTES).map_err(|why| format!("`{name}`: {why}"))?;
        let texture = Arc::new(self.texture_bytes(&bytes, name).map_err(|why| format!("`{name}`: {why}"))?);
        self.files.borrow_mut().push(path.clone());
        self.textures.borrow_mut().push((path, texture.clone()));
        Ok(texture)
    }

    /// A texture decoded from image bytes, its memory counted; `what`
    /// names it in the memory message (the caller places other errors).
    pub(super) fn texture_bytes(&self, bytes: &[u8], what: &str) -> Result<Texture, String> {
        let texture = Texture::decode(bytes, MAX_TEXTURE_PIXELS)?;
        let (w, h) = texture.size();
        let needed = self.mesh_bytes.get() + w as u64 * h as u64 * 3;
        crate::memory::check(format!("the scene's meshes and textures ({w}×{h} in {what})"), needed)
            .map_err(|e| e.to_string())?;
        self.mesh_bytes.set(needed);
        Ok(texture)
    }
}
