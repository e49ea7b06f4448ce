//! The `[materials.NAME]` tables of a scene file, checked and built.

use super::check::{Checker, Result};
use super::desc::{self, MaterialDesc, Triple};
use crate::Rgb;
use crate::material::Material;
use glam::Vec3;

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
                    .loader
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
