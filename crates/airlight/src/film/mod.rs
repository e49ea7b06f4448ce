//! Images: linear f32 RGB, written as EXR (linear) or PNG (sRGB after
//! exposure and a tone curve), always whole or not at all; the accumulator
//! that every render adds its samples into; and the error measures that
//! `airlight compare` prints.

mod accumulator;
mod atomic;
mod compare;
pub mod partial;
mod settings;

pub use accumulator::{ACCUMULATOR_BYTES_PER_PIXEL, Accumulator, PixelSum, SQUARE_FRACTION_BITS, SUM_FRACTION_BITS};
pub(crate) use accumulator::{AddSample, PixelTotal};
pub use compare::{ImageError, compare, error_map};
pub use partial::{Partial, PartialHeader};
pub use settings::{FilmSettings, PixelFilter};

use crate::Rgb;
use std::io;
use std::path::Path;

/// Largest image side.
pub const MAX_IMAGE_SIDE: u32 = 1 << 16;
/// Most pixels in an image (16384²).
pub const MAX_PIXELS: u64 = 1 << 28;

/// Largest EXR file read (a 16384² RGB float image uncompressed is 3 GiB).
pub const MAX_EXR_BYTES: u64 = 4 << 30;

/// How the image is turned into 8-bit PNG values (EXR output is always linear).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tonemap {
    /// Clip to [0, 1].
    #[default]
    Clamp,
    /// The ACES filmic curve as fitted by Narkowicz (2015).
    Filmic,
}

impl Tonemap {
    pub const ALL: [Tonemap; 2] = [Tonemap::Clamp, Tonemap::Filmic];

    /// The name a scene file gives it.
    pub fn name(self) -> &'static str {
        match self {
            Tonemap::Clamp => "clamp",
            Tonemap::Filmic => "filmic",
        }
    }
}

impl std::str::FromStr for Tonemap {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Tonemap::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| format!("unknown tone curve `{s}`; expected clamp or filmic"))
    }
}

/// A linear RGB image, row-major, pixel (0, 0) at the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Rgb>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Image { width, height, pixels: vec![Rgb::ZERO; width as usize * height as usize] }
    }

    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> Rgb {
        self.pixels[(y * self.width + x) as usize]
    }

    /// The mean of all pixels.
    pub fn mean(&self) -> Rgb {
        let sum: glam::DVec3 = self.pixels.iter().map(|p| p.as_dvec3()).sum();
        (sum / self.pixels.len().max(1) as f64).as_vec3()
    }

    /// Writes `.exr` (linear f32) or `.png` (8-bit sRGB, clipped to [0, 1]),
    /// chosen by the extension, whole or not at all (see [`Image::save_with`]).
    pub fn save(&self, path: impl AsRef<Path>) -> io::Result<()> {
        self.save_with(path.as_ref(), 0.0, Tonemap::Clamp)
    }

    /// Writes `.exr` (linear f32) or `.png` (8-bit sRGB after `exposure`
    /// stops and the tone curve), chosen by the extension. The file is
    /// written beside the target under a temporary name and renamed, so a
    /// failure never leaves a partial image.
    pub fn save_with(&self, path: &Path, exposure: f32, tonemap: Tonemap) -> io::Result<()> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let bytes = match ext.as_deref() {
            Some("exr") => self.encode_exr()?,
            Some("png") => self.encode_png(exposure, tonemap)?,
            _ => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("cannot tell the image format of `{}`: use .exr or .png", path.display()),
                ));
            }
        };
        write_atomically(path, &bytes)
    }

    /// Writes the image as an EXR with more channels beside R, G, B (each
    /// named, e.g. `albedo.R`, `N.X`, `Z`: layers of a multi-layer EXR, as
    /// compositors read them), whole or not at all.
    pub fn save_exr_with_channels(&self, path: &Path, extra: &[(&str, Vec<f32>)]) -> io::Result<()> {
        use exr::prelude::*;
        let count = self.pixels.len();
        if let Some((name, _)) = extra.iter().find(|(_, values)| values.len() != count) {
            return Err(io::Error::other(format!("channel {name} does not have one value per pixel")));
        }
        let mut list: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(c, name)| AnyChannel::new(*name, FlatSamples::F32(self.pixels.iter().map(|p| p[c]).collect())))
            .collect();
        for (name, values) in extra {
            list.push(AnyChannel::new(*name, FlatSamples::F32(values.clone())));
        }
        let encoding =
            Encoding { compression: Compression::ZIP16, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
        let size = (self.width as usize, self.height as usize);
        let layer = Layer::new(size, LayerAttributes::default(), encoding, AnyChannels::sort(list.into()));
        let mut out = io::Cursor::new(Vec::new());
        exr::prelude::Image::from_layer(layer).write().to_buffered(&mut out).map_err(io::Error::other)?;
        write_atomically(path, &out.into_inner())
    }

    fn encode_exr(&self) -> io::Result<Vec<u8>> {
        use exr::prelude::*;
        let (w, h) = (self.width as usize, self.height as usize);
        let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
            let p = self.pixels[pos.y() * w + pos.x()];
            (p.x, p.y, p.z)
        });
        // Lines in increasing order: the default lets parallel compression
        // write blocks as they finish, so the bytes would vary run to run.
        let encoding =
            Encoding { compression: Compression::ZIP16, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
        let layer = Layer::new((w, h), LayerAttributes::default(), encoding, channels);
        let image = exr::prelude::Image::from_layer(layer);
        let mut out = io::Cursor::new(Vec::new());
        image.write().to_buffered(&mut out).map_err(io::Error::other)?;
        Ok(out.into_inner())
    }

    fn encode_png(&self, exposure: f32, tonemap: Tonemap) -> io::Result<Vec<u8>> {
        let scale = exposure.exp2();
        let mut rgb = Vec::with_capacity(self.pixels.len() * 3);
        for p in &self.pixels {
            for c in p.to_array() {
                rgb.push(to_srgb8(tone(c * scale, tonemap)));
            }
        }
        let mut out = io::Cursor::new(Vec::new());
        image::ImageEncoder::write_image(
            image::codecs::png::PngEncoder::new(&mut out),
            &rgb,
            self.width,
            self.height,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(io::Error::other)?;
        Ok(out.into_inner())
    }

    /// Reads an EXR's RGB channels. The header is read first and an image
    /// larger than [`MAX_IMAGE_SIDE`] on a side, [`MAX_PIXELS`] in all, or
    /// than the memory a run may take ([`crate::memory`]) is refused before
    /// any pixel is allocated; so is anything but a regular file of at most
    /// [`MAX_EXR_BYTES`]. Errors name the file.
    pub fn read_exr(path: &Path) -> io::Result<Image> {
        use exr::prelude::*;
        let invalid = |why: String| io::Error::new(io::ErrorKind::InvalidData, format!("{}: {why}", path.display()));
        let meta = std::fs::metadata(path).map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        if !meta.is_file() {
            return Err(invalid("not a regular file".into()));
        }
        if meta.len() > MAX_EXR_BYTES {
            return Err(invalid(format!("{} bytes; an EXR may have at most {MAX_EXR_BYTES}", meta.len())));
        }
        let headers = exr::meta::MetaData::read_from_file(path, false).map_err(|e| invalid(e.to_string()))?;
        for header in headers.headers.iter() {
            let (w, h) = (header.layer_size.width() as u64, header.layer_size.height() as u64);
            if w > MAX_IMAGE_SIDE as u64 || h > MAX_IMAGE_SIDE as u64 || w * h > MAX_PIXELS {
                return Err(invalid(format!(
                    "its header declares {w}×{h} pixels; at most {MAX_IMAGE_SIDE} on a side and {MAX_PIXELS} in all \
                     are read"
                )));
            }
            // The pixels, and the decoder's copy of a block of them.
            crate::memory::check(format!("reading {w}×{h} pixels"), 2 * w * h * size_of::<Rgb>() as u64)
                .map_err(|e| invalid(e.to_string()))?;
        }
        let image = read_first_rgba_layer_from_file(
            path,
            |res, _| (res.width(), vec![Rgb::ZERO; res.width() * res.height()]),
            |(stride, pixels), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                if let Some(p) = pixels.get_mut(pos.y() * *stride + pos.x()) {
                    *p = Rgb::new(r, g, b)
                }
            },
        )
        .map_err(|e| invalid(e.to_string()))?;
        let size = image.layer_data.size;
        let (_, pixels) = image.layer_data.channel_data.pixels;
        Ok(Self { width: size.x() as u32, height: size.y() as u32, pixels })
    }
}

/// A tone curve applied to a linear value.
pub fn tone(x: f32, tonemap: Tonemap) -> f32 {
    let x = x.max(0.0);
    match tonemap {
        Tonemap::Clamp => x.min(1.0),
        // Narkowicz, "ACES Filmic Tone Mapping Curve" (2015).
        Tonemap::Filmic => ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0),
    }
}

/// The sRGB transfer function (IEC 61966-2-1) to 8 bits.
pub fn to_srgb8(linear: f32) -> u8 {
    let v = linear.clamp(0.0, 1.0);
    let s = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

/// Writes `bytes` to `path` whole or not at all: into a new file in the
/// same folder (never one that exists, never through a symbolic link),
/// flushed to disk, then renamed over `path`, so readers see the old file
/// or the whole new one. On Linux the file has no name until it is
/// complete (`O_TMPFILE`), so even a kill leaves nothing behind; elsewhere
/// it is `.NAME.tmp-PID-RANDOM`, removed on every failure this function
/// sees.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    atomic::write(path, bytes)
}

/// As [`write_atomically`], with the contents written by `fill` into the
/// new file (which it may seek in) rather than held in memory whole.
pub fn write_atomically_with(path: &Path, fill: impl FnOnce(&mut std::fs::File) -> io::Result<()>) -> io::Result<()> {
    atomic::write_with(path, fill)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trips_exactly() {
        let mut img = Image::new(5, 3);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = Rgb::new(i as f32 * 0.25, 1.0 / (i as f32 + 1.0), 1e-3 * i as f32);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        img.save(&path).unwrap();
        assert_eq!(Image::read_exr(&path).unwrap(), img);
        // Nothing temporary is left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing-dir").join("a.png");
        assert!(Image::new(2, 2).save(&path).is_err());
        assert!(!path.exists());
        assert!(Image::new(2, 2).save(dir.path().join("a.tiff")).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn srgb_curve_hits_known_values() {
        assert_eq!(to_srgb8(0.0), 0);
        assert_eq!(to_srgb8(1.0), 255);
        // 0.5 linear is 0.7354 in sRGB: 187.5 → 188.
        assert_eq!(to_srgb8(0.5), 188);
        assert!(tone(1e6, Tonemap::Filmic) <= 1.0);
    }
}
