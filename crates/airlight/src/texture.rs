//! Image textures: an sRGB-encoded 8-bit RGB image sampled with bilinear
//! filtering in linear RGB, addressed by texture coordinates (u, v) with
//! (0, 0) at the image's top-left corner and v growing downward (glTF's
//! convention; OBJ's `vt`, whose v grows upward, is flipped on reading).
//!
//! Texels stay 8-bit sRGB in memory (3 bytes each, a quarter of linear
//! f32) and are decoded through a 256-entry table when sampled; the four
//! texels of a bilinear lookup are decoded before they are blended, so the
//! filtering happens in linear light.

use crate::Rgb;

/// What happens to a coordinate outside [0, 1] (glTF's sampler wrap modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The edge texels extend outward.
    ClampToEdge,
    /// The image tiles the plane, every other copy mirrored.
    MirroredRepeat,
}

impl std::str::FromStr for Wrap {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "repeat" => Ok(Wrap::Repeat),
            "clamp" => Ok(Wrap::ClampToEdge),
            "mirror" => Ok(Wrap::MirroredRepeat),
            _ => Err(format!("unknown wrap `{s}`; expected repeat, clamp or mirror")),
        }
    }
}

impl Wrap {
    /// The texel index for index `i` of a row or column of `n` texels.
    #[inline]
    fn index(self, i: i64, n: u32) -> usize {
        let n = n as i64;
        let i = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let k = i.rem_euclid(2 * n);
                if k < n { k } else { 2 * n - 1 - k }
            }
        };
        i as usize
    }
}

/// Decodes one sRGB-encoded value in [0, 1] to linear (IEC 61966-2-1):
/// c/12.92 up to 0.04045, ((c + 0.055)/1.055)^2.4 above.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Each byte over 255, for textures that hold data.
fn data_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| i as f32 / 255.0))
}

/// The linear value of each 8-bit sRGB code.
fn decode_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

/// An RGB image texture (see the module documentation).
#[derive(Clone, PartialEq)]
pub struct Texture {
    width: u32,
    height: u32,
    /// sRGB-encoded, row by row from the top.
    texels: Vec<[u8; 3]>,
    wrap_u: Wrap,
    wrap_v: Wrap,
    /// Whether the bytes are data (glTF's metallic-roughness maps: the
    /// byte over 255) rather than sRGB-encoded colour.
    linear: bool,
    /// The mean linear colour, for surfaces without texture coordinates.
    mean: Rgb,
    /// Each texel's coverage (alpha over 255), row by row; empty for an
    /// image without alpha or whose alpha is everywhere opaque.
    alpha: Vec<u8>,
    /// A hash of the texels, computed once: the debug text (a render's
    /// fingerprint) names the texture by it, and a mesh's every emitting
    /// triangle names its texture.
    checksum: u64,
}

impl std::fmt::Debug for Texture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Texture")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("wrap", &(self.wrap_u, self.wrap_v))
            .field("linear", &self.linear)
            .field("mean", &self.mean)
            // The texels themselves, so that the debug text (a render's
            // fingerprint) changes with any of them, not only with the mean.
            .field("checksum", &format_args!("{:016x}", self.checksum))
            .finish()
    }
}

impl Texture {
    /// A hash of the texels' bytes, three to a word.
    fn texel_checksum(texels: &[[u8; 3]]) -> u64 {
        crate::geometry::checksum(texels.iter().map(|&[r, g, b]| u32::from_le_bytes([r, g, b, 0])))
    }

    /// A texture of `width × height` sRGB texels, row by row from the top;
    /// None if the sizes do not match or one is zero.
    pub fn from_srgb8(width: u32, height: u32, texels: Vec<[u8; 3]>) -> Option<Texture> {
        if width == 0 || height == 0 || texels.len() as u64 != width as u64 * height as u64 {
            return None;
        }
        let checksum = Texture::texel_checksum(&texels);
        let mut texture = Texture {
            width,
            height,
            texels,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            linear: false,
            mean: Rgb::ZERO,
            alpha: Vec::new(),
            checksum,
        };
        texture.mean = texture.texel_mean();
        Some(texture)
    }

    /// The same texture with a coverage for each texel (alpha over 255,
    /// row by row); None if there is not one per texel. An alpha that is
    /// opaque everywhere is not kept.
    pub fn with_alpha(mut self, alpha: Vec<u8>) -> Option<Texture> {
        if alpha.len() != self.texels.len() {
            return None;
        }
        if alpha.iter().any(|&a| a != 255) {
            self.checksum ^= crate::geometry::checksum(alpha.iter().map(|&a| a as u32)).rotate_left(1);
            self.alpha = alpha;
        }
        Some(self)
    }

    /// Whether some texel is not fully opaque.
    pub fn has_alpha(&self) -> bool {
        !self.alpha.is_empty()
    }

    /// The bilinearly filtered coverage at (u, v), as [`Texture::sample`]
    /// filters colour; 1 for an image without alpha.
    pub fn alpha(&self, u: f32, v: f32) -> f32 {
        if self.alpha.is_empty() {
            return 1.0;
        }
        if !(u.is_finite() && v.is_finite()) {
            return 1.0;
        }
        let (x0, y0, fx, fy) = self.footprint(u, v);
        let at = |x: i64, y: i64| {
            let (x, y) = (self.wrap_u.index(x, self.width), self.wrap_v.index(y, self.height));
            self.alpha[y * self.width as usize + x] as f32 / 255.0
        };
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
        let bottom = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The texel at the upper left of the four that (u, v) (finite) lies
    /// between, and its fractions of the way to the next along x and y.
    #[inline]
    fn footprint(&self, u: f32, v: f32) -> (i64, i64, f32, f32) {
        // f64: a coordinate of 1e6 still resolves a texel of a 16k image.
        let x = u as f64 * self.width as f64 - 0.5;
        let y = v as f64 * self.height as f64 - 0.5;
        // Beyond 2⁵² a float has no fraction left; held there, the texel
        // indices and their neighbours stay within i64 (u = 3e38 is a
        // texture coordinate a file may hold).
        const FAR: f64 = (1u64 << 52) as f64;
        let (x, y) = (x.clamp(-FAR, FAR), y.clamp(-FAR, FAR));
        let (x0, y0) = (x.floor(), y.floor());
        ((x0 as i64), (y0 as i64), (x - x0) as f32, (y - y0) as f32)
    }

    /// The same texels read as data, each byte over 255, not as sRGB
    /// colour: glTF's metallic-roughness maps hold numbers, not colours.
    pub fn as_data(mut self) -> Texture {
        self.linear = true;
        self.mean = self.texel_mean();
        self
    }

    fn table(&self) -> &'static [f32; 256] {
        if self.linear { data_table() } else { decode_table() }
    }

    fn texel_mean(&self) -> Rgb {
        let table = self.table();
        let sum = self.texels.iter().fold(glam::DVec3::ZERO, |s, t| {
            s + glam::DVec3::new(table[t[0] as usize] as f64, table[t[1] as usize] as f64, table[t[2] as usize] as f64)
        });
        (sum / self.texels.len() as f64).as_vec3()
    }

    /// Decodes a PNG or JPEG image; 16-bit channels are reduced to 8 bits,
    /// and an alpha channel is kept as the texels' coverage
    /// ([`Texture::alpha`]). `max_pixels` bounds the image's size.
    pub fn decode(bytes: &[u8], max_pixels: u64) -> Result<Texture, String> {
        let format = match image::guess_format(bytes) {
            Ok(f @ (image::ImageFormat::Png | image::ImageFormat::Jpeg)) => f,
            Ok(other) => return Err(format!("a {other:?} image; textures are PNG or JPEG")),
            Err(_) => return Err("not a PNG or JPEG image".to_string()),
        };
        let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(max_pixels.saturating_mul(8));
        reader.limits(limits);
        let (width, height) = reader.into_dimensions().map_err(|e| format!("cannot read the image: {e}"))?;
        if width as u64 * height as u64 > max_pixels {
            return Err(format!("{width}×{height} pixels is more than the {max_pixels} a texture may have"));
        }
        let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
        reader.limits(image::Limits::no_limits());
        // The decoded image (16-bit RGBA takes 8 bytes a pixel), its 8-bit
        // RGB(A) copy and the texels with their alpha, counted before the
        // decoder allocates.
        let decoder = reader.into_decoder().map_err(|e| format!("cannot read the image: {e}"))?;
        let decoded = image::ImageDecoder::total_bytes(&decoder);
        let needed = decoded.saturating_add(width as u64 * height as u64 * 8);
        crate::memory::check(format!("decoding a {width}×{height} texture"), needed).map_err(|e| e.to_string())?;
        let image = image::DynamicImage::from_decoder(decoder).map_err(|e| format!("cannot decode the image: {e}"))?;
        if image.color().has_alpha() {
            let rgba = image.into_rgba8();
            let texels = rgba.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect();
            let alpha = rgba.pixels().map(|p| p.0[3]).collect();
            let texture = Texture::from_srgb8(width, height, texels).ok_or_else(|| "the image is empty".to_string())?;
            return texture.with_alpha(alpha).ok_or_else(|| "the image is empty".to_string());
        }
        let rgb = image.into_rgb8();
        let texels = rgb.pixels().map(|p| p.0).collect();
        Texture::from_srgb8(width, height, texels).ok_or_else(|| "the image is empty".to_string())
    }

    /// The same texture with the given wrap modes along u and v.
    pub fn with_wrap(mut self, wrap_u: Wrap, wrap_v: Wrap) -> Texture {
        self.wrap_u = wrap_u;
        self.wrap_v = wrap_v;
        self
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The mean linear colour over the image.
    pub fn mean(&self) -> Rgb {
        self.mean
    }

    /// The linear colour of texel (x, y), wrapped.
    #[inline]
    fn texel(&self, x: i64, y: i64) -> Rgb {
        let (x, y) = (self.wrap_u.index(x, self.width), self.wrap_v.index(y, self.height));
        let t = self.texels[y * self.width as usize + x];
        let table = self.table();
        Rgb::new(table[t[0] as usize], table[t[1] as usize], table[t[2] as usize])
    }

    /// The bilinearly filtered linear colour at (u, v): texel centres sit
    /// at ((i + ½)/width, (j + ½)/height), and a point between four of them
    /// blends them by its distances to each.
    pub fn sample(&self, u: f32, v: f32) -> Rgb {
        if !(u.is_finite() && v.is_finite()) {
            return self.mean;
        }
        let (x0, y0, fx, fy) = self.footprint(u, v);
        let top = self.texel(x0, y0) * (1.0 - fx) + self.texel(x0 + 1, y0) * fx;
        let bottom = self.texel(x0, y0 + 1) * (1.0 - fx) + self.texel(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_at_the_ends_of_f32_sample_a_texel() {
        let t = Texture::from_srgb8(2, 1, vec![[255, 0, 0], [0, 0, 255]]).unwrap();
        for (u, v) in [(3.4e38, 0.5), (-3.4e38, 0.5), (0.5, 3.4e38), (1e20, -1e20)] {
            let c = t.sample(u, v);
            assert!(c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0, "({u}, {v}): {c}");
        }
    }

    #[test]
    fn srgb_decode_matches_the_standard_at_known_points() {
        // Values of the IEC 61966-2-1 curve worked out by hand.
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-7);
        // 0.5 → ((0.555/1.055)^2.4) = 0.214041…
        assert!((srgb_to_linear(0.5) - 0.214_041_14).abs() < 1e-6);
        // Code 128 → 0.215861 (the usual table value).
        assert!((decode_table()[128] - 0.215_860_5).abs() < 1e-6);
    }

    /// A 2×2 texture: red, green / blue, white (sRGB 255 and 0: linear 1 and 0).
    fn two_by_two() -> Texture {
        Texture::from_srgb8(2, 2, vec![[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]]).unwrap()
    }

    #[test]
    fn the_debug_text_changes_with_the_texels_not_only_their_mean() {
        // The same mean colour, the texels swapped: a different image.
        let swapped = Texture::from_srgb8(2, 2, vec![[0, 255, 0], [255, 0, 0], [0, 0, 255], [255, 255, 255]]).unwrap();
        assert_eq!(swapped.mean(), two_by_two().mean());
        assert_ne!(format!("{swapped:?}"), format!("{:?}", two_by_two()));
        assert_eq!(format!("{:?}", two_by_two()), format!("{:?}", two_by_two()));
    }

    #[test]
    fn bilinear_weights_between_texel_centres() {
        let t = two_by_two();
        // At texel centres: the texels themselves.
        assert_eq!(t.sample(0.25, 0.25), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(t.sample(0.75, 0.75), Rgb::ONE);
        // The image's centre: a quarter of each → (0.5, 0.5, 0.5).
        assert!((t.sample(0.5, 0.5) - Rgb::splat(0.5)).abs().max_element() < 1e-6);
        // u = 0.375 lies a quarter of the way from centre 0.25 to 0.75; v = 0.25 on the top row:
        // 0.75·red + 0.25·green.
        assert!((t.sample(0.375, 0.25) - Rgb::new(0.75, 0.25, 0.0)).abs().max_element() < 1e-6);
        // (0.375, 0.625): weights 0.75·0.25 red, 0.25·0.25 green, 0.75·0.75 blue, 0.25·0.75 white.
        let expected = Rgb::new(0.1875 + 0.1875, 0.0625 + 0.1875, 0.5625 + 0.1875);
        assert!((t.sample(0.375, 0.625) - expected).abs().max_element() < 1e-6);
        // The mean of the four texels.
        assert!((t.mean() - Rgb::new(0.5, 0.5, 0.5)).abs().max_element() < 1e-6);
    }

    #[test]
    fn wrap_modes_at_the_edges() {
        // At u = 0 the lookup falls halfway between texel −1 and texel 0.
        let repeat = two_by_two();
        // Repeat: texel −1 is texel 1 (green): half red, half green.
        assert!((repeat.sample(0.0, 0.25) - Rgb::new(0.5, 0.5, 0.0)).abs().max_element() < 1e-6);
        // Clamp: texel −1 is texel 0: red.
        let clamp = two_by_two().with_wrap(Wrap::ClampToEdge, Wrap::ClampToEdge);
        assert!((clamp.sample(0.0, 0.25) - Rgb::new(1.0, 0.0, 0.0)).abs().max_element() < 1e-6);
        // Mirror: u = 1.25 lies in the mirrored copy, at the centre of texel 1 reflected: texel 1 (green).
        let mirror = two_by_two().with_wrap(Wrap::MirroredRepeat, Wrap::MirroredRepeat);
        assert!((mirror.sample(1.25, 0.25) - Rgb::new(0.0, 1.0, 0.0)).abs().max_element() < 1e-6);
        // Repeat at u = 1.25: texel 0 again (red).
        assert!((repeat.sample(1.25, 0.25) - Rgb::new(1.0, 0.0, 0.0)).abs().max_element() < 1e-6);
        // Mid-grey sRGB 128 decodes by the formula, not as 128/255.
        let grey = Texture::from_srgb8(1, 1, vec![[128; 3]]).unwrap();
        assert!((grey.sample(0.3, 0.9).x - srgb_to_linear(128.0 / 255.0)).abs() < 1e-6);
    }

    #[test]
    fn bad_images_are_refused_with_a_reason() {
        assert_eq!(Texture::decode(b"not an image", 100).unwrap_err(), "not a PNG or JPEG image");
        let mut png = Vec::new();
        let encoder = image::codecs::png::PngEncoder::new(&mut png);
        image::ImageEncoder::write_image(encoder, &[0u8; 4 * 4 * 3], 4, 4, image::ExtendedColorType::Rgb8).unwrap();
        assert_eq!(Texture::decode(&png, 100).unwrap().size(), (4, 4));
        assert!(Texture::decode(&png, 15).unwrap_err().contains("more than the 15"));
        let truncated = &png[..png.len() - 20];
        assert!(Texture::decode(truncated, 100).unwrap_err().starts_with("cannot decode the image"));
    }
}
