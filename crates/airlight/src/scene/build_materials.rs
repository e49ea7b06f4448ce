//! The `[materials.NAME]` tables of a scene file, checked and built; and a
//! medium given as one line of `[medium]`'s keys (the command line's
//! `--medium`), checked as the table is (build_medium.rs).

use super::assets::AssetPath;
use super::build::{Checker, Result, parse};
use super::desc::{self, MaterialDesc, MaterialType, Triple};
use super::{SceneDesc, SceneError};
use crate::Rgb;
use crate::material::Material;
use crate::medium::Medium;
use glam::Vec3;
use std::cell::{Cell, RefCell};
use toml::Spanned;

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
    let Some(medium) = &desc.medium else { return Err("no medium".into()) };
    let assets = AssetPath::CommandLine;
    let checker = Checker {
        text: &text,
        assets: &assets,
        document: Default::default(),
        files: RefCell::default(),
        mesh_bytes: Cell::new(0),
        notes: RefCell::default(),
        textures: RefCell::default(),
    };
    checker.medium(medium).map_err(strip)
}

impl Checker<'_> {
    pub(super) fn material(&self, name: &str, desc: &Spanned<MaterialDesc>) -> Result<Material> {
        let span = desc.span();
        let m = desc.get_ref();
        let what = |field: &str| format!("materials.{name}.{field}");
        let albedo = |t: Option<Triple>, field: &str, default: f32| -> Result<Rgb> {
            self.non_negative3(span.clone(), &what(field), t.map_or(Vec3::splat(default), |t| t.0))
        };
        let misplaced = |present: bool, field: &str, owner: &str| -> Result<()> {
            if present {
                Err(self.err_field(span.clone(), field, format!("{} belongs to a {owner} material", what(field))))
            } else {
                Ok(())
            }
        };
        if m.kind != MaterialType::Checker {
            misplaced(m.albedo2.is_some(), "albedo2", "checker")?;
            misplaced(m.scale.is_some(), "scale", "checker")?;
        }
        if m.kind != MaterialType::Phong {
            misplaced(m.specular.is_some(), "specular", "phong")?;
            misplaced(m.exponent.is_some(), "exponent", "phong")?;
        }
        if m.kind != MaterialType::Texture {
            misplaced(m.file.is_some(), "file", "texture")?;
            misplaced(m.wrap.is_some(), "wrap", "texture")?;
        }
        if m.kind == MaterialType::Texture {
            let Some(file) = &m.file else {
                return Err(self.err(span, format!("materials.{name}: a texture material needs a `file` (an image)")));
            };
            let factor = albedo(m.albedo, "albedo", 1.0)?;
            let texture = self.texture_file(file.get_ref()).map_err(|why| {
                self.err(file.span(), format!("materials.{name}.file: cannot load the texture: {why}"))
            })?;
            let texture = match &m.wrap {
                Some(w) => {
                    let wrap = desc::parse_name(w, &what("wrap")).map_err(|e| self.err(e.span, e.message))?;
                    std::sync::Arc::new((*texture).clone().with_wrap(wrap, wrap))
                }
                None => texture,
            };
            return Ok(Material::textured(factor, texture));
        }
        let a = albedo(m.albedo, "albedo", 0.8)?;
        Ok(match m.kind {
            MaterialType::Diffuse => Material::diffuse(a),
            MaterialType::Checker => {
                let a2 = albedo(m.albedo2, "albedo2", 0.2)?;
                let scale = self.positive(span, &what("scale"), m.scale.unwrap_or(1.0))?;
                Material::checker(a, a2, scale)
            }
            MaterialType::Phong => {
                let specular = albedo(m.specular, "specular", 0.04)?;
                let exponent = self.non_negative(span, &what("exponent"), m.exponent.unwrap_or(32.0))?;
                Material::phong(a, specular, exponent)
            }
            MaterialType::Texture => unreachable!("returned above"),
        })
    }
}
