//! The `[[lights]]` tables of a scene file, and their keyframes: each
//! value checked, placed at its line, before a light is made.

use super::build::{Checker, Result};
use super::desc::*;
use super::limits;
use crate::light::{Attenuation, Keyframes, Light, SpotProfile};
use glam::Vec3;
use toml::Spanned;

impl Checker<'_> {
    /// A light, checked, within [`limits::MAX_COORDINATE`] of the origin.
    pub(super) fn light(&self, index: usize, desc: &Spanned<LightDesc>) -> Result<Light> {
        let light = self.light_values(index, desc)?;
        let kind = format!("{:?}", desc.get_ref().kind).to_lowercase();
        let extent = limits::light_extent(&light);
        if extent > limits::MAX_COORDINATE {
            return Err(self.err(desc.span(), limits::too_far(&format!("lights[{index}] ({kind})"), extent)));
        }
        Ok(light)
    }

    fn light_values(&self, index: usize, desc: &Spanned<LightDesc>) -> Result<Light> {
        let span = desc.span();
        let l = desc.get_ref();
        let kind = format!("{:?}", l.kind).to_lowercase();
        let label = format!("lights[{index}] ({kind})");
        let fields: [(&str, bool); 22] = [
            ("min", l.min.is_some()),
            ("max", l.max.is_some()),
            ("volume", l.volume.is_some()),
            ("position", l.position.is_some()),
            ("intensity", l.intensity.is_some()),
            ("direction", l.direction.is_some()),
            ("look_at", l.look_at.is_some()),
            ("cone_angle", l.cone_angle.is_some()),
            ("falloff_start", l.falloff_start.is_some()),
            ("profile", l.profile.is_some()),
            ("irradiance", l.irradiance.is_some()),
            ("center", l.center.is_some()),
            ("radius", l.radius.is_some()),
            ("radiance", l.radiance.is_some()),
            ("corner", l.corner.is_some()),
            ("edge_u", l.edge_u.is_some()),
            ("edge_v", l.edge_v.is_some()),
            ("attenuation", l.attenuation.is_some()),
            ("cutoff", l.cutoff.is_some()),
            ("range", l.range.is_some()),
            ("start", l.start.is_some()),
            ("end", l.end.is_some()),
        ];
        let at = |name: &str| format!("{label}.{name}");
        let point = |p: Option<Point>, name: &str| self.finite3(span.clone(), &at(name), p.unwrap().0);
        let power = |t: Option<Triple>, name: &str| self.non_negative3(span.clone(), &at(name), t.unwrap().0);
        let check = |required: &[&str], optional: &[&str]| {
            self.check_fields(span.clone(), &label, &kind, &fields, required, optional)
        };
        const FALLOFF: [&str; 3] = ["attenuation", "cutoff", "range"];
        let light = match l.kind {
            LightType::Point => {
                check(&["position", "intensity"], &[&FALLOFF[..], &["radius"]].concat())?;
                Light::point(point(l.position, "position")?, power(l.intensity, "intensity")?)
            }
            LightType::Spot => {
                let optional = ["cone_angle", "falloff_start", "profile", "direction", "look_at", "radius"];
                check(&["position", "intensity"], &[&FALLOFF[..], &optional].concat())?;
                let position = point(l.position, "position")?;
                let direction = match (l.direction, l.look_at) {
                    (Some(d), None) => self.direction(span.clone(), &at("direction"), d.0)?,
                    (None, Some(t)) => self
                        .direction(
                            span.clone(),
                            &at("look_at"),
                            self.finite3(span.clone(), &at("look_at"), t.0)? - position,
                        )
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
                Light::Spot {
                    position,
                    direction,
                    intensity: power(l.intensity, "intensity")?,
                    cone_angle: cone.to_radians(),
                    falloff_start: start.to_radians(),
                    profile: l.profile.map_or(SpotProfile::Smoothstep, Into::into),
                    attenuation: Attenuation::PHYSICAL,
                }
            }
            LightType::Distant => {
                check(&["direction", "irradiance"], &[])?;
                let d = self.direction(span.clone(), &at("direction"), l.direction.unwrap().0)?;
                return Ok(Light::distant(d, power(l.irradiance, "irradiance")?));
            }
            LightType::Sphere if l.volume == Some(true) => {
                check(&["center", "radius", "intensity"], &["volume"])?;
                let radius = self.positive(span.clone(), &at("radius"), l.radius.unwrap())?;
                return Ok(Light::volume_sphere(point(l.center, "center")?, radius, power(l.intensity, "intensity")?));
            }
            LightType::Box => {
                check(&["min", "max", "intensity"], &[])?;
                let (min, max) = (point(l.min, "min")?, point(l.max, "max")?);
                if !min.cmplt(max).all() {
                    return Err(self.err_field(
                        span,
                        "max",
                        format!("{label}: min must be less than max on every axis, got min {min} max {max}"),
                    ));
                }
                return Ok(Light::volume_box(min, max, power(l.intensity, "intensity")?));
            }
            LightType::Sphere => {
                check(&["center", "radius", "radiance"], &[&FALLOFF[..], &["volume"]].concat())?;
                let radius = self.positive(span.clone(), &at("radius"), l.radius.unwrap())?;
                Light::sphere(point(l.center, "center")?, radius, power(l.radiance, "radiance")?)
            }
            LightType::Quad => {
                check(&["corner", "edge_u", "edge_v", "radiance"], &[])?;
                let (u, v) = (point(l.edge_u, "edge_u")?, point(l.edge_v, "edge_v")?);
                self.edges(span.clone(), &label, u, v)?;
                return Ok(Light::quad(point(l.corner, "corner")?, u, v, power(l.radiance, "radiance")?));
            }
            LightType::Line => {
                check(&["start", "end", "intensity"], &[])?;
                let (a, b) = (point(l.start, "start")?, point(l.end, "end")?);
                if a == b {
                    return Err(self.err_field(span, "end", format!("{label}: start and end must differ")));
                }
                return Ok(Light::line(a, b, power(l.intensity, "intensity")?));
            }
        };
        // The falloff of a point, spot or sphere light.
        let radius = match l.radius {
            Some(r) => self.positive(span.clone(), &at("radius"), r)?,
            None => Attenuation::PHYSICAL.radius,
        };
        let cutoff = l.cutoff.map(|c| self.positive(span.clone(), &at("cutoff"), c)).transpose()?;
        let range = l.range.map(|r| self.positive(span.clone(), &at("range"), r)).transpose()?;
        let model = l.attenuation.unwrap_or_default();
        // E₀, the irradiance at the light's surface, in its brightest channel.
        let e0 = light.intensity().max_element() / (radius * radius);
        let attenuation = Attenuation::new(model, radius, e0, cutoff, range)
            .map_err(|why| self.err_field(span.clone(), "attenuation", format!("{label}: {why}")))?;
        Ok(light.with_attenuation(attenuation))
    }

    /// A light's `keyframes`: times in [0, 1], strictly increasing, finite
    /// positions; not on a distant light.
    pub(super) fn keyframes(
        &self,
        index: usize,
        desc: &Spanned<LightDesc>,
        light: &Light,
    ) -> Result<Option<Keyframes>> {
        let Some(keys) = &desc.get_ref().keyframes else {
            return Ok(None);
        };
        let label = format!("lights[{index}].keyframes");
        if light.position().is_none() {
            return Err(self.err(keys.span(), format!("{label}: a distant light has no position to move")));
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
