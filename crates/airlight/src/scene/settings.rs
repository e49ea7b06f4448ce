//! The film and sampling settings of a scene (`[render]`'s keys that are
//! not an integrator's), each declared once in [`RENDER_SETTINGS`].

use crate::Rgb;
use crate::options::{NumberRange, OptionSpec, OptionValue, ValueKind, set_named};

/// The film and sampling settings of `[render]`: what every integrator
/// shares. Integrators' own options live in [`crate::integrator`].
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// The image: its size, how a pixel gathers its samples, and how it is
    /// shown.
    pub film: FilmSettings,
    /// Samples per pixel.
    pub spp: u32,
    pub seed: u64,
    /// How far a ray that hits nothing is followed, and how far along any
    /// camera ray the medium is integrated (a surface beyond it is still
    /// seen, attenuated by the medium all the way).
    pub max_distance: f32,
    /// Radiance of rays that escape.
    pub background: Rgb,
    /// Skip lights whose range ends before a point (finite-range falloffs).
    pub cull_lights: bool,
    /// Spread the samples over the pixels by their noise, `spp` a pixel on
    /// average (`render::adaptive`), rather than `spp` in every pixel.
    pub adaptive: bool,
}

use crate::film::FilmSettings;
/// The image's limits are the film's.
pub use crate::film::{MAX_IMAGE_SIDE, MAX_PIXELS};

/// Most samples per pixel.
pub const MAX_SPP: u32 = 1 << 24;

impl RenderSettings {
    /// Checks every setting by its declaration, and the image's pixel
    /// count; a message names the key and its bound.
    pub fn validate(&self) -> Result<(), String> {
        RENDER_SETTINGS.iter().try_for_each(|o| o.validate(self)).map_err(|e| e.message)?;
        self.film.validate()
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            film: FilmSettings::default(),
            spp: 16,
            seed: 0,
            max_distance: 100.0,
            background: Rgb::ZERO,
            cull_lights: true,
            adaptive: false,
        }
    }
}

/// A colour as an option value.
fn colour(c: Rgb) -> OptionValue {
    OptionValue::List(c.to_array().iter().map(|&x| x.to_string().parse().unwrap_or(x as f64)).collect())
}

/// Every film and sampling setting, in the order the docs list them.
pub const RENDER_SETTINGS: &[OptionSpec<RenderSettings>] = &[
    OptionSpec {
        key: "width",
        kind: ValueKind::Count { min: 1, max: MAX_IMAGE_SIDE as u64 },
        unit: "pixels",
        doc: "Image width.",
        default_doc: None,
        get: |s| OptionValue::Int(s.film.width as i128),
        set: |s, v| s.film.width = v.count() as u32,
    },
    OptionSpec {
        key: "height",
        kind: ValueKind::Count { min: 1, max: MAX_IMAGE_SIDE as u64 },
        unit: "pixels",
        doc: "Image height (an included glTF camera's aspect ratio sets it when neither size is given).",
        default_doc: None,
        get: |s| OptionValue::Int(s.film.height as i128),
        set: |s, v| s.film.height = v.count() as u32,
    },
    OptionSpec {
        key: "spp",
        kind: ValueKind::Count { min: 1, max: MAX_SPP as u64 },
        unit: "",
        doc: "Samples per pixel (on average, with adaptive sampling).",
        default_doc: None,
        get: |s| OptionValue::Int(s.spp as i128),
        set: |s, v| s.spp = v.count() as u32,
    },
    OptionSpec {
        key: "seed",
        kind: ValueKind::Count { min: 0, max: i64::MAX as u64 },
        unit: "",
        doc: "Seed of every random stream; the same seed gives the same image.",
        default_doc: None,
        get: |s| OptionValue::Int(s.seed as i128),
        set: |s, v| s.seed = v.count(),
    },
    OptionSpec {
        key: "max_distance",
        kind: ValueKind::Number(NumberRange::Positive),
        unit: "world units",
        doc: "How far a ray that hits nothing is followed, and how far the medium is integrated along it.",
        default_doc: None,
        get: |s| OptionValue::real(s.max_distance),
        set: |s, v| s.max_distance = v.number() as f32,
    },
    OptionSpec {
        key: "background",
        kind: ValueKind::Colour,
        unit: "W/(m² sr)",
        doc: "Radiance of rays that escape.",
        default_doc: None,
        get: |s| colour(s.background),
        set: |s, v| s.background = v.colour(),
    },
    OptionSpec {
        key: "exposure",
        kind: ValueKind::Number(NumberRange::Finite),
        unit: "stops",
        doc: "Scales the image by 2^exposure before the tone curve (PNG output only).",
        default_doc: None,
        get: |s| OptionValue::real(s.film.exposure),
        set: |s, v| s.film.exposure = v.number() as f32,
    },
    OptionSpec {
        key: "tonemap",
        kind: ValueKind::Name(&["clamp", "filmic"]),
        unit: "",
        doc: "Tone curve for PNG output: clip to [0, 1], or the ACES filmic fit (Narkowicz 2015).",
        default_doc: None,
        get: |s| OptionValue::Text(s.film.tonemap.name().into()),
        set: |s, v| set_named(&mut s.film.tonemap, v),
    },
    OptionSpec {
        key: "filter",
        kind: ValueKind::Name(&["box", "point"]),
        unit: "",
        doc: "Samples spread over each pixel's square (box), or all through its centre (point).",
        default_doc: None,
        get: |s| OptionValue::Text(s.film.filter.name().into()),
        set: |s, v| set_named(&mut s.film.filter, v),
    },
    OptionSpec {
        key: "cull_lights",
        kind: ValueKind::Bool,
        unit: "",
        doc: "Skip lights whose finite range ends before a point.",
        default_doc: None,
        get: |s| OptionValue::Bool(s.cull_lights),
        set: |s, v| s.cull_lights = v.bool(),
    },
    OptionSpec {
        key: "adaptive",
        kind: ValueKind::Bool,
        unit: "",
        doc: "Spread the samples over the pixels by their noise, spp a pixel on average.",
        default_doc: None,
        get: |s| OptionValue::Bool(s.adaptive),
        set: |s, v| s.adaptive = v.bool(),
    },
];

impl RenderSettings {
    /// Sets setting `key` to `value`, checked by its declaration; None when
    /// there is no such setting.
    pub fn set(&mut self, key: &str, value: &OptionValue) -> Option<Result<(), crate::options::OptionError>> {
        crate::options::find(RENDER_SETTINGS, key).map(|o| o.apply(self, value))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_setting_reads_back_what_it_was_set_to_and_knows_its_names() {
        crate::options::check_declarations(RENDER_SETTINGS);
    }
}
