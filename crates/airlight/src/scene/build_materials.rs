//! The `[materials.NAME]` tables of a scene file, checked and built; and a
//! medium given as one line of `[medium]`'s keys (the command line's
//! `--medium`), checked as the table is (build_medium.rs).

use super::assets::AssetPath;
use super::build::{Checker, Result, parse};
use super::desc::{self, MaterialDesc, Triple};
use super::{SceneDesc, SceneError};
use crate::Rgb;
use crate::material::Material;
use crate::medium::Medium;
use glam::Vec3;
use std::cell::{Cell, RefCell};

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
    let document = toml::de::DeTable::parse(&text).map_err(|e| e.message().to_string())?.into_inner();
    let checker = Checker {
        text: &text,
        assets: &assets,
        document,
        files: RefCell::default(),
        mesh_bytes: Cell::new(0),
        notes: RefCell::default(),
        textures: RefCell::default(),
    };
    checker.medium().map_err(strip)
}

impl Checker<'_> {
    /// The material `[materials.NAME]` describes, read by its type.
    pub(super) fn material(&self, name: &str) -> Result<Material> {
        let label = format!("materials.{name}");
        let read = self.read_table::<MaterialDesc>(self.section_field("materials", name)?, &label)?;
        let span = read.table.span();
        let what = |field: &str| format!("{label}.{field}");
        let albedo = |t: Option<Triple>, field: &str, default: f32| -> Result<Rgb> {
            self.non_negative3(span.clone(), &what(field), t.map_or(Vec3::splat(default), |t| t.0))
        };
        Ok(match &read.kind {
            MaterialDesc::Diffuse(m) => Material::diffuse(albedo(m.albedo, "albedo", 0.8)?),
            MaterialDesc::Checker(m) => {
                let (a, a2) = (albedo(m.albedo, "albedo", 0.8)?, albedo(m.albedo2, "albedo2", 0.2)?);
                Material::checker(a, a2, self.positive(span, &what("scale"), m.scale.unwrap_or(1.0))?)
            }
            MaterialDesc::Phong(m) => {
                let specular = albedo(m.specular, "specular", 0.04)?;
                let exponent = self.non_negative(span.clone(), &what("exponent"), m.exponent.unwrap_or(32.0))?;
                Material::phong(albedo(m.albedo, "albedo", 0.8)?, specular, exponent)
            }
            MaterialDesc::Texture(m) => {
                let factor = albedo(m.albedo, "albedo", 1.0)?;
                let texture = self
                    .texture_file(m.file.get_ref())
                    .map_err(|why| self.err(m.file.span(), format!("{label}.file: cannot load the texture: {why}")))?;
                let texture = match &m.wrap {
                    Some(w) => {
                        let wrap = desc::parse_name(w, &what("wrap")).map_err(|e| self.err(e.span, e.message))?;
                        std::sync::Arc::new((*texture).clone().with_wrap(wrap, wrap))
                    }
                    None => texture,
                };
                Material::textured(factor, texture)
            }
        })
    }
}
