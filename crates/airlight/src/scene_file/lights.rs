//! The `[[lights]]` tables of a scene file, and their keyframes: each
//! value checked, placed at its line, before a light is made.

use super::check::{Checker, Result};
use super::desc::*;
use crate::light::environment::EnvironmentMap;
use crate::light::{Attenuation, Keyframes, Light, SpotProfile};
use crate::scene::limits;
use glam::Vec3;
use std::ops::Range;
use std::sync::Arc;

impl<'a> Checker<'a> {
    /// The `index`th `[[lights]]` table read by its type, and the light it
    /// makes, within [`limits::MAX_COORDINATE`] of the origin.
    pub(super) fn light(&self, index: usize) -> Result<(Light, LightMotion, Option<Arc<EnvironmentMap>>)> {
        let label = format!("lights[{index}]");
        let read = self.read_table::<LightDesc>(self.section_element("lights", index)?, &label)?;
        let label = format!("{label} ({})", read.name);
        let span = read.table.span();
        let light = self.light_values(span.clone(), &label, &read.kind)?;
        let extent = limits::light_extent(&light);
        if extent > limits::MAX_COORDINATE {
            return Err(self.err(span, limits::too_far(&label, extent)));
        }
        let map = match &read.kind {
            LightDesc::Sky(SkyLight { file: Some(file), .. }) => {
                Some(self.loader.environment_file(file.get_ref()).map_err(|why| {
                    self.err(file.span(), format!("{label}.file: cannot load the environment map: {why}"))
                })?)
            }
            _ => None,
        };
        Ok((light, read.shared, map))
    }

    fn light_values(&self, span: Range<usize>, label: &str, desc: &LightDesc) -> Result<Light> {
        let at = |name: &str| format!("{label}.{name}");
        let point = |p: Point, name: &str| self.finite3(span.clone(), &at(name), p.0);
        let power = |t: Triple, name: &str| self.non_negative3(span.clone(), &at(name), t.0);
        let (light, falloff) = match desc {
            LightDesc::Point(l) => {
                (Light::point(point(l.position, "position")?, power(l.intensity, "intensity")?), l.falloff())
            }
            LightDesc::Spot(l) => (self.spot(span.clone(), label, l)?, l.falloff()),
            LightDesc::Sky(l) => {
                return Ok(Light::sky(power(l.radiance.unwrap_or(Triple(Vec3::ONE)), "radiance")?));
            }
            LightDesc::Distant(l) => {
                let d = self.direction(span.clone(), &at("direction"), l.direction.0)?;
                return Ok(Light::distant(d, power(l.irradiance, "irradiance")?));
            }
            LightDesc::Sphere(l) if l.volume == Some(true) => {
                let falloff = l.falloff();
                let other = [
                    ("radiance", l.radiance.is_some()),
                    ("attenuation", falloff.model.is_some()),
                    ("cutoff", falloff.cutoff.is_some()),
                    ("range", falloff.range.is_some()),
                ];
                if let Some((key, _)) = other.iter().find(|(_, given)| *given) {
                    let why =
                        format!("{label}: a volume sphere (volume = true) glows with `intensity` and takes no `{key}`");
                    return Err(self.err_field(span, key, why));
                }
                let (Some(radius), Some(intensity)) = (l.radius, l.intensity) else {
                    let key = if l.radius.is_none() { "radius" } else { "intensity" };
                    return Err(self.err(span, format!("{label}: a volume sphere light needs `{key}`")));
                };
                let radius = self.positive(span.clone(), &at("radius"), radius)?;
                return Ok(Light::volume_sphere(point(l.center, "center")?, radius, power(intensity, "intensity")?));
            }
            LightDesc::Sphere(l) => {
                if l.intensity.is_some() {
                    let why =
                        format!("{label}: a sphere light's surface emits `radiance`; `intensity` is for volume = true");
                    return Err(self.err_field(span, "intensity", why));
                }
                let (Some(radius), Some(radiance)) = (l.radius, l.radiance) else {
                    let key = if l.radius.is_none() { "radius" } else { "radiance" };
                    return Err(self.err(span, format!("{label}: a sphere light needs `{key}`")));
                };
                let radius = self.positive(span.clone(), &at("radius"), radius)?;
                (Light::sphere(point(l.center, "center")?, radius, power(radiance, "radiance")?), l.falloff())
            }
            LightDesc::Quad(l) => {
                let (u, v) = (point(l.edge_u, "edge_u")?, point(l.edge_v, "edge_v")?);
                self.edges(span.clone(), label, u, v)?;
                return Ok(Light::quad(point(l.corner, "corner")?, u, v, power(l.radiance, "radiance")?));
            }
            LightDesc::Line(l) => {
                let (a, b) = (point(l.start, "start")?, point(l.end, "end")?);
                if a == b {
                    return Err(self.err_field(span, "end", format!("{label}: start and end must differ")));
                }
                return Ok(Light::line(a, b, power(l.intensity, "intensity")?));
            }
            LightDesc::Box(l) => {
                let (min, max) = (point(l.min, "min")?, point(l.max, "max")?);
                self.box_corners(span.clone(), label, min, max)?;
                return Ok(Light::volume_box(min, max, power(l.intensity, "intensity")?));
            }
        };
        // The falloff of a point, spot or sphere light.
        let radius = match falloff.radius {
            Some(r) => self.positive(span.clone(), &at("radius"), r)?,
            None => Attenuation::PHYSICAL.radius,
        };
        let cutoff = falloff.cutoff.map(|c| self.positive(span.clone(), &at("cutoff"), c)).transpose()?;
        let range = falloff.range.map(|r| self.positive(span.clone(), &at("range"), r)).transpose()?;
        let model = falloff.model.unwrap_or_default();
        // E₀, the irradiance at the light's surface, in its brightest channel.
        let e0 = light.intensity().max_element() / (radius * radius);
        let attenuation = Attenuation::new(model, radius, e0, cutoff, range)
            .map_err(|why| self.err_field(span.clone(), "attenuation", format!("{label}: {why}")))?;
        Ok(light.with_attenuation(attenuation))
    }

    /// A spot light, aimed by `direction` or `look_at`, its cone checked.
    fn spot(&self, span: Range<usize>, label: &str, l: &SpotLight) -> Result<Light> {
        let at = |name: &str| format!("{label}.{name}");
        let position = self.finite3(span.clone(), &at("position"), l.position.0)?;
        let direction = match (l.direction, l.look_at) {
            (Some(d), None) => self.direction(span.clone(), &at("direction"), d.0)?,
            (None, Some(t)) => self
                .direction(span.clone(), &at("look_at"), self.finite3(span.clone(), &at("look_at"), t.0)? - position)
                .map_err(|_| self.err(span.clone(), format!("{label}: look_at must differ from position")))?,
            (Some(_), Some(_)) => {
                return Err(self.err(span, format!("{label}: give direction or look_at, not both")));
            }
            (None, None) => {
                return Err(self.err(span, format!("{label}: a spot needs `direction` or `look_at`")));
            }
        };
        let cone = l.cone_angle.unwrap_or(30.0);
        if !(cone > 0.0 && cone <= 180.0) {
            return Err(self.err_field(
                span,
                "cone_angle",
                format!("{label}.cone_angle must be in (0, 180] degrees, got {cone}"),
            ));
        }
        let start = l.falloff_start.unwrap_or(cone);
        if !(start >= 0.0 && start <= cone) {
            return Err(self.err_field(
                span,
                "falloff_start",
                format!("{label}.falloff_start must be in [0, cone_angle = {cone}] degrees, got {start}"),
            ));
        }
        Ok(Light::Spot {
            position,
            direction,
            intensity: self.non_negative3(span, &at("intensity"), l.intensity.0)?,
            cone_angle: cone.to_radians(),
            falloff_start: start.to_radians(),
            profile: l.profile.map_or(SpotProfile::Smoothstep, Into::into),
            attenuation: Attenuation::PHYSICAL,
        })
    }

    /// A light's `keyframes`: times in [0, 1], strictly increasing, finite
    /// positions; not on a distant light or a sky.
    pub(super) fn keyframes(&self, index: usize, motion: &LightMotion, light: &Light) -> Result<Option<Keyframes>> {
        let Some(keys) = &motion.keyframes else {
            return Ok(None);
        };
        let label = format!("lights[{index}].keyframes");
        if light.position().is_none() {
            let what = if matches!(light, Light::Sky { .. }) { "sky" } else { "distant light" };
            return Err(self.err(keys.span(), format!("{label}: a {what} has no position to move")));
        }
        if keys.get_ref().is_empty() {
            return Err(self.err(keys.span(), format!("{label} needs at least one {{ time, position }} key")));
        }
        let mut out = Vec::with_capacity(keys.get_ref().len());
        for (k, key) in keys.get_ref().iter().enumerate() {
            let KeyframeDesc { time, position } = key.get_ref();
            if !(0.0..=1.0).contains(time) {
                return Err(self.err(key.span(), format!("{label}[{k}].time must lie in [0, 1], got {time}")));
            }
            let previous = out.last().map(|&(t, _): &(f32, Vec3)| t);
            if let Some(previous) = previous.filter(|&p| *time <= p) {
                return Err(self.err(
                    key.span(),
                    format!("{label}[{k}].time must be greater than the previous key's ({previous}), got {time}"),
                ));
            }
            if !position.0.is_finite() {
                return Err(self.err(key.span(), format!("{label}[{k}].position must be finite, got {}", position.0)));
            }
            let extent = limits::light_extent(&light.moved_to(position.0));
            if extent > limits::MAX_COORDINATE {
                return Err(self.err(key.span(), limits::too_far(&format!("{label}[{k}]"), extent)));
            }
            out.push((*time, position.0));
        }
        Ok(Keyframes::new(out))
    }
}
