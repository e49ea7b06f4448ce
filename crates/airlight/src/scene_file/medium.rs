//! The `[medium]` table: homogeneous fog, height fog, or a density grid
//! read from a Mitsuba `.vol` file found under the scene's asset folders
//! ([`crate::assets`]); and a medium given as one line of its keys (the
//! command line's `--medium`), checked as the table is. Errors name the scene's line and, for a grid file,
//! what is wrong with it.

use super::check::{Checker, Result, parse};
use super::desc::{GridMedium, HomogeneousMedium, MediumDesc, NoiseMedium, SceneDesc};
use crate::assets::{AssetPath, vol};
use crate::medium::noise::MAX_OCTAVES;
use crate::medium::{DensityGrid, Medium, NoiseFog};
use crate::scene::{SceneError, limits};
use glam::Vec3;
use std::ops::Range;

/// A medium from the keys of a scene file's `[medium]` table written as
/// one line, `key = value` pairs separated by commas (`sigma_s = 0.05,
/// sigma_a = 0.01, g = 0.3`; colours as `[r, g, b]`; `type = "height"`),
/// checked by the same rules as the table. For command lines, which give
/// a medium without a scene file; a message without a line number. A
/// grid's `file` is any file the user can read, absolute or relative to
/// the working directory ([`AssetPath::CommandLine`]).
pub fn medium_from_options(options: &str) -> Result<Medium, String> {
    let text = format!("medium = {{ {options} }}");
    let strip = |e: SceneError| e.message;
    let desc: SceneDesc = parse(&text).map_err(strip)?;
    if desc.medium.is_none() {
        return Err("no medium".into());
    }
    let assets = AssetPath::CommandLine;
    Checker::new(&text, &assets).and_then(|checker| checker.medium()).map_err(strip)
}

impl Checker<'_> {
    /// The medium `[medium]` describes, read by its type.
    pub(super) fn medium(&self) -> Result<Medium> {
        let read = self.read_table::<MediumDesc>(self.section("medium")?, "medium")?;
        let span = read.table.span();
        let c = &read.shared;
        let sigma_a = self.non_negative3(span.clone(), "medium.sigma_a", c.sigma_a.map_or(Vec3::ZERO, |t| t.0))?;
        let sigma_s = self.non_negative3(span.clone(), "medium.sigma_s", c.sigma_s.map_or(Vec3::ZERO, |t| t.0))?;
        let g = c.g.unwrap_or(0.0);
        if !(g > -1.0 && g < 1.0) {
            return Err(self.err_field(span, "g", format!("medium.g must lie strictly between -1 and 1, got {g}")));
        }
        match &read.kind {
            MediumDesc::Homogeneous(HomogeneousMedium {}) => Ok(Medium::homogeneous(sigma_a, sigma_s, g)),
            MediumDesc::Height(m) => {
                let base = self.finite(span.clone(), "medium.base", m.base.unwrap_or(0.0))?;
                let falloff = self.non_negative(span, "medium.falloff", m.falloff.unwrap_or(0.5))?;
                Ok(Medium::height(sigma_a, sigma_s, g, base, falloff))
            }
            MediumDesc::Grid(m) => Ok(Medium::grid(sigma_a, sigma_s, g, self.density_grid(span, m)?)),
            MediumDesc::Noise(m) => Ok(Medium::noise(sigma_a, sigma_s, g, self.noise_fog(span, m)?)),
        }
    }

    /// The grid of a `type = "grid"` medium: its file read and checked,
    /// scaled by `density_scale` and placed by `translate`, `rotate`, `scale`.
    fn density_grid(&self, span: Range<usize>, m: &GridMedium) -> Result<DensityGrid> {
        let file = &m.file;
        let density_scale = self.non_negative(span.clone(), "medium.density_scale", m.density_scale.unwrap_or(1.0))?;
        let transform = self.transform_parts(span.clone(), "medium", m.translate, m.rotate, m.scale)?;
        let name = file.get_ref();
        let err = |why: String| self.err(file.span(), format!("medium.file: cannot load grid `{name}`: {why}"));
        if !name.to_ascii_lowercase().ends_with(".vol") {
            return Err(err("a grid file must be a Mitsuba volume ending in .vol".into()));
        }
        let path = self.loader.resolve(name).map_err(|why| self.err(file.span(), format!("medium.file: {why}")))?;
        let open = std::fs::File::open(&path).map_err(|e| err(e.to_string()))?;
        let length = open.metadata().map_err(|e| err(e.to_string()))?.len();
        let mut grid = vol::read(std::io::BufReader::new(open), length).map_err(err)?;
        if density_scale != 1.0 {
            for v in &mut grid.values {
                *v *= density_scale;
            }
            if let Some(big) = grid.values.iter().find(|v| !v.is_finite()) {
                return Err(err(format!("density_scale {density_scale} makes a density {big}")));
            }
        }
        let (min, max) = (grid.min, grid.max);
        let grid = DensityGrid::new(grid.resolution, grid.values, min, max, transform)
            .ok_or_else(|| err("its box, placed by the transform, is degenerate".into()))?;
        let reach = grid.corners().into_iter().map(limits::reach_of).fold(0.0, f32::max);
        if reach > limits::MAX_COORDINATE {
            return Err(err(limits::too_far("the grid's box", reach)));
        }
        self.loader.record(path);
        Ok(grid)
    }

    /// The fog of a `type = "noise"` medium, its parameters checked.
    fn noise_fog(&self, span: Range<usize>, m: &NoiseMedium) -> Result<NoiseFog> {
        let scale = m.scale.map_or(Vec3::ONE, |s| s.0);
        if !(scale.is_finite() && scale.min_element() > 0.0) {
            return Err(self.err_field(span, "scale", format!("medium.scale must be finite and > 0, got {scale}")));
        }
        let octaves = match &m.octaves {
            None => 4,
            Some(o) if (1..=MAX_OCTAVES as i64).contains(o.get_ref()) => *o.get_ref() as u32,
            Some(o) => {
                return Err(self.err(
                    o.span(),
                    format!("medium.octaves must be an integer from 1 to {MAX_OCTAVES}, got {}", o.get_ref()),
                ));
            }
        };
        let gain = m.gain.unwrap_or(0.5);
        if !(0.0..=1.0).contains(&gain) {
            return Err(self.err_field(span, "gain", format!("medium.gain must lie in [0, 1], got {gain}")));
        }
        let offset = self.finite(span.clone(), "medium.offset", m.offset.unwrap_or(0.0))?;
        let seed = match &m.seed {
            None => 0,
            Some(s) => u32::try_from(*s.get_ref()).map_err(|_| {
                self.err(
                    s.span(),
                    format!("medium.seed must be an integer from 0 to {}, got {}", u32::MAX, s.get_ref()),
                )
            })?,
        };
        let bounds = match (m.min, m.max) {
            (None, None) => None,
            (Some(lo), Some(hi)) => {
                let lo = self.finite3(span.clone(), "medium.min", lo.0)?;
                let hi = self.finite3(span.clone(), "medium.max", hi.0)?;
                if !hi.cmpgt(lo).all() {
                    return Err(self.err_field(
                        span,
                        "max",
                        format!("medium.max {hi} must exceed medium.min {lo} on every axis"),
                    ));
                }
                let reach = limits::reach_of(lo).max(limits::reach_of(hi));
                if reach > limits::MAX_COORDINATE {
                    return Err(self.err_field(span, "max", limits::too_far("the noise fog's box", reach)));
                }
                Some((lo, hi))
            }
            _ => {
                return Err(self.err_field(
                    span,
                    if m.min.is_some() { "min" } else { "max" },
                    "a noise fog's box needs both min and max",
                ));
            }
        };
        let height = match m.falloff {
            None if m.base.is_some() => {
                return Err(self.err_field(
                    span,
                    "base",
                    "medium.base needs a falloff: the height factor is exp(−falloff·(y − base))",
                ));
            }
            None => None,
            Some(falloff) => {
                let falloff = self.non_negative(span.clone(), "medium.falloff", falloff)?;
                Some((self.finite(span, "medium.base", m.base.unwrap_or(0.0))?, falloff))
            }
        };
        Ok(NoiseFog { scale, octaves, gain, offset, seed, bounds, height })
    }
}
