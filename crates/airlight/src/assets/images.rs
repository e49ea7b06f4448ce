//! Image files that textures are read from: found under the asset rules
//! ([`super::AssetPath`]), decoded ([`crate::texture::Texture::decode`]), their
//! memory counted with the meshes', and read once per scene however many
//! materials use them.

use super::{Loader, MAX_MESH_BYTES, read_limited};
use crate::light::environment::{EnvironmentMap, environment_bytes};
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

/// Most texels an environment map may have (8192 × 4096: 640 MiB with its
/// sampling tables).
const MAX_ENVIRONMENT_PIXELS: u64 = 1 << 25;

impl Loader<'_> {
    /// The environment map in the image file `name` (found as a texture
    /// is): a Radiance HDR (`.hdr`) or OpenEXR (`.exr`) image of linear
    /// radiance, equirectangular ([`EnvironmentMap`]); or why not.
    pub(crate) fn environment_file(&self, name: &str) -> Result<Arc<EnvironmentMap>, String> {
        let path = self.resolve(name)?;
        let fail = |why: String| format!("`{name}`: {why}");
        let bytes = read_limited(&path, MAX_MESH_BYTES).map_err(fail)?;
        let format = match image::guess_format(&bytes) {
            Ok(f @ (image::ImageFormat::Hdr | image::ImageFormat::OpenExr)) => f,
            Ok(other) => return Err(fail(format!("a {other:?} image; environment maps are Radiance HDR or OpenEXR"))),
            Err(_) => return Err(fail("not a Radiance HDR or OpenEXR image".into())),
        };
        let reader = image::ImageReader::with_format(std::io::Cursor::new(&bytes), format);
        let (width, height) = reader.into_dimensions().map_err(|e| fail(format!("cannot read the image: {e}")))?;
        let texels = width as u64 * height as u64;
        if texels > MAX_ENVIRONMENT_PIXELS {
            return Err(fail(format!(
                "{width}×{height} texels is more than the {MAX_ENVIRONMENT_PIXELS} an environment map may have"
            )));
        }
        // The map with its tables, and the decoder's own image (up to
        // 16 bytes a texel, RGBA in f32) while it is converted.
        let needed = environment_bytes(width, height).saturating_add(texels.saturating_mul(16));
        crate::memory::check(format!("decoding a {width}×{height} environment map"), needed)
            .map_err(|e| fail(e.to_string()))?;
        let mut reader = image::ImageReader::with_format(std::io::Cursor::new(&bytes), format);
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(texels.saturating_mul(32).max(1 << 20));
        reader.limits(limits);
        let image = reader.decode().map_err(|e| fail(format!("cannot decode the image: {e}")))?;
        let rgb = image.into_rgb32f();
        let radiance = rgb.pixels().map(|p| glam::Vec3::from_array(p.0)).collect();
        let map = EnvironmentMap::new(width, height, radiance)
            .ok_or_else(|| fail("a texel is negative or not a number".into()))?;
        self.reserve(environment_bytes(width, height), || format!("the environment map ({width}×{height})"))
            .map_err(fail)?;
        self.record(path);
        Ok(Arc::new(map))
    }
}
