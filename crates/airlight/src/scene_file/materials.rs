//! The `[materials.NAME]` tables of a scene file, checked and built.

use super::check::{Checker, Result};
use super::desc::{self, MaterialDesc, Triple};
use crate::Rgb;
use crate::material::{Material, MetallicRoughness, SurfaceMaps, TextureMap};
use crate::texture::Texture;
use glam::Vec3;
use std::sync::Arc;
use toml::Spanned;

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
                Material::textured(factor, self.image(&label, "file", &m.file, m.wrap.as_ref(), false)?)
            }
            MaterialDesc::MetallicRoughness(m) => {
                let base = albedo(m.base_colour, "base_colour", 0.8)?;
                let unit = |v: &Option<Spanned<f32>>, field: &str, default: f32| -> Result<f32> {
                    let Some(v) = v else { return Ok(default) };
                    if (0.0..=1.0).contains(v.get_ref()) {
                        Ok(*v.get_ref())
                    } else {
                        Err(self.err(
                            v.span(),
                            format!("{}: expected a number in [0, 1], got {}", what(field), v.get_ref()),
                        ))
                    }
                };
                let image = |file: &Option<Spanned<String>>, field: &str, data: bool| -> Result<Option<TextureMap>> {
                    file.as_ref()
                        .map(|f| self.image(&label, field, f, m.wrap.as_ref(), data).map(TextureMap::new))
                        .transpose()
                };
                let normal_scale = match &m.normal_scale {
                    Some(s) if !s.get_ref().is_finite() => {
                        return Err(self.err(s.span(), format!("{}: expected a finite number", what("normal_scale"))));
                    }
                    Some(s) => *s.get_ref(),
                    None => 1.0,
                };
                let maps = SurfaceMaps {
                    normal: image(&m.normal_file, "normal_file", true)?.map(|map| (map, normal_scale)),
                    base_colour: image(&m.base_colour_file, "base_colour_file", false)?,
                    metallic_roughness: image(&m.metallic_roughness_file, "metallic_roughness_file", true)?,
                };
                let has_maps = maps.base_colour.is_some() || maps.metallic_roughness.is_some() || maps.normal.is_some();
                Material::MetallicRoughness(MetallicRoughness {
                    base,
                    metallic: unit(&m.metallic, "metallic", 0.0)?,
                    roughness: unit(&m.roughness, "roughness", 0.5)?,
                    specular: unit(&m.specular, "specular", 1.0)?,
                    maps: has_maps.then(|| Arc::new(maps)),
                })
            }
        })
    }

    /// An image a material names in `field`, with its wrap mode; read as
    /// data rather than sRGB colour when `data`.
    fn image(
        &self,
        label: &str,
        field: &str,
        file: &Spanned<String>,
        wrap: Option<&Spanned<String>>,
        data: bool,
    ) -> Result<Arc<Texture>> {
        let texture = self
            .loader
            .texture_file(file.get_ref())
            .map_err(|why| self.err(file.span(), format!("{label}.{field}: cannot load the texture: {why}")))?;
        if wrap.is_none() && !data {
            return Ok(texture);
        }
        let mut texture = (*texture).clone();
        if let Some(w) = wrap {
            let wrap = desc::parse_name(w, &format!("{label}.wrap")).map_err(|e| self.err(e.span, e.message))?;
            texture = texture.with_wrap(wrap, wrap);
        }
        Ok(Arc::new(if data { texture.as_data() } else { texture }))
    }
}
