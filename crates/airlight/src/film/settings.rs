//! What the image is: its size, how a pixel gathers its samples, and how
//! it is shown (exposure and tone curve, for 8-bit output). Set from
//! `[render]`'s keys (their declarations are the scene's render settings).

use super::{MAX_PIXELS, Tonemap};

/// The image's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmSettings {
    pub width: u32,
    pub height: u32,
    /// Stops, for PNG output only.
    pub exposure: f32,
    pub tonemap: Tonemap,
    /// How a pixel gathers its samples.
    pub filter: PixelFilter,
}

impl Default for FilmSettings {
    fn default() -> Self {
        FilmSettings { width: 640, height: 480, exposure: 0.0, tonemap: Tonemap::Clamp, filter: PixelFilter::Box }
    }
}

impl FilmSettings {
    /// The number of pixels.
    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }

    /// Refuses an image of more than [`MAX_PIXELS`] pixels (each side's
    /// bound is its setting's).
    pub fn validate(&self) -> Result<(), String> {
        let (w, h) = (self.width, self.height);
        if self.pixels() > MAX_PIXELS {
            return Err(format!("the image may have at most {MAX_PIXELS} pixels (16384²), got {w}×{h}"));
        }
        Ok(())
    }
}

/// How the samples of a pixel are placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PixelFilter {
    /// The mean over the pixel's square: samples jittered across it (anti-aliasing).
    #[default]
    Box,
    /// Every sample through the pixel's centre: no anti-aliasing, but images
    /// whose integrators take different sample counts share their camera rays.
    Point,
}

impl PixelFilter {
    /// The name a scene file gives it.
    pub fn name(self) -> &'static str {
        match self {
            PixelFilter::Box => "box",
            PixelFilter::Point => "point",
        }
    }
}

impl std::str::FromStr for PixelFilter {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "box" => Ok(PixelFilter::Box),
            "point" => Ok(PixelFilter::Point),
            _ => Err(format!("unknown filter `{s}`; expected box or point")),
        }
    }
}
