//! From a scene file to a [`Scene`]: parse, check every value, load meshes.
//! Each error names the place in the file and what was expected.

use super::desc::*;
use super::{MAX_IMAGE_SIDE, MAX_SPP, RenderSettings, Scene, SceneBuilder, SceneError, default_camera, desc};
use crate::Rgb;
use crate::camera::{Camera, Projection};
use crate::geometry::Shape;
use crate::light::{Attenuation, Keyframes, Light, SpotProfile};
use crate::material::Material;
use crate::medium::Medium;
use glam::{Affine3A, Quat, Vec3};
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// Parses scene file text into its description; errors name the line and
/// column (unknown keys at the key).
pub fn parse(text: &str) -> Result<SceneDesc, SceneError> {
    toml::from_str(text).map_err(|e| {
        let message = e.message().trim_end().to_string();
        match e.span() {
            Some(span) => SceneError::at(text, span.start, message),
            None => SceneError::new(message),
        }
    })
}

/// Checks a parsed scene file (`text`, for error positions) and builds its
/// scene. `base_dir` is where relative mesh paths start (None: the current
/// directory). The `[render]` table's integrator options are not read here
/// (see [`crate::SceneFile`]).
pub fn build(desc: &SceneDesc, text: &str, base_dir: Option<&Path>) -> Result<Scene, SceneError> {
    // The same text parsed to a spanned document: where each key and value
    // stands, for errors found after deserializing.
    let document = toml::de::DeTable::parse(text).map(|d| d.into_inner()).unwrap_or_default();
    Checker { text, base_dir, document }.scene(desc)
}

pub(super) struct Checker<'a> {
    text: &'a str,
    base_dir: Option<&'a Path>,
    document: toml::de::DeTable<'a>,
}

pub(super) type Result<T, E = SceneError> = std::result::Result<T, E>;

impl Checker<'_> {
    pub(super) fn err(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError::at(self.text, span.start, message)
    }

    /// An error about `what` (a dotted path such as `objects[2] (sphere).radius`)
    /// in the table at `span`: placed at the field's value when the table
    /// spells the field out, else at the table.
    pub(super) fn err_field(&self, span: Range<usize>, what: &str, message: impl Into<String>) -> SceneError {
        let field = what.rsplit('.').next().unwrap_or(what);
        SceneError::at(self.text, self.locate(span.start, field), message)
    }

    /// The offset of `field`'s value in the table that starts at `start`,
    /// looked up in the parsed document; `start` when the table does not
    /// spell the field out.
    fn locate(&self, start: usize, field: &str) -> usize {
        find_table(&self.document, start)
            .and_then(|table| table.iter().find(|(key, _)| key.get_ref() == field))
            .map_or(start, |(_, value)| value.span().start)
    }

    fn scene(&self, desc: &SceneDesc) -> Result<Scene> {
        let settings = self.settings(desc)?;
        let mut builder = SceneBuilder::new().settings(settings);
        if let Some(camera) = &desc.camera {
            builder = builder.camera(self.camera(camera)?);
        }
        if let Some(medium) = &desc.medium {
            builder = builder.medium(self.medium(medium)?);
        }
        for (name, material) in &desc.materials {
            builder = builder.material(name, self.material(name, material)?);
        }
        for (i, object) in desc.objects.iter().enumerate() {
            let (shape, material) = self.object(i, object, desc)?;
            builder = builder.object(shape, &material);
        }
        for (i, light) in desc.lights.iter().enumerate() {
            let built = self.light(i, light)?;
            builder = match self.keyframes(i, light, &built)? {
                Some(path) => builder.moving_light(built, path),
                None => builder.light(built),
            };
        }
        builder.build()
    }

    fn settings(&self, desc: &SceneDesc) -> Result<RenderSettings> {
        let r = &desc.render;
        let mut s = RenderSettings::default();
        let located = |e: desc::FieldError| self.err(e.span, e.message);
        if let Some(v) = &r.width {
            s.width = desc::render_count(v, "width", 1, MAX_IMAGE_SIDE).map_err(located)?;
        }
        if let Some(v) = &r.height {
            s.height = desc::render_count(v, "height", 1, MAX_IMAGE_SIDE).map_err(located)?;
        }
        if let Some(v) = &r.spp {
            s.spp = desc::render_count(v, "spp", 1, MAX_SPP).map_err(located)?;
        }
        if let Some(seed) = &r.seed {
            s.seed = *seed.get_ref() as u64;
        }
        if let Some(d) = &r.max_distance {
            s.max_distance = self.positive(d.span(), "render.max_distance", *d.get_ref())?;
        }
        if let Some(b) = &r.background {
            s.background = self.non_negative3(b.span(), "render.background", b.get_ref().0)?;
        }
        if let Some(e) = &r.exposure {
            s.exposure = self.finite(e.span(), "render.exposure", *e.get_ref())?;
        }
        if let Some(t) = &r.tonemap {
            s.tonemap = desc::parse_name(t, "render.tonemap").map_err(located)?;
        }
        if let Some(c) = r.cull_lights {
            s.cull_lights = c;
        }
        if let Some(f) = &r.filter {
            s.filter = desc::parse_name(f, "render.filter").map_err(located)?;
        }
        if let Err(message) = s.validate() {
            let span = r.height.as_ref().or(r.width.as_ref()).map_or(0..0, |v| v.span());
            return Err(self.err(span, message));
        }
        Ok(s)
    }

    pub(super) fn finite(&self, span: Range<usize>, what: &str, v: f32) -> Result<f32> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err_field(span, what, format!("{what} must be a finite number, got {v}")))
        }
    }

    pub(super) fn positive(&self, span: Range<usize>, what: &str, v: f32) -> Result<f32> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.err_field(span, what, format!("{what} must be a positive finite number, got {v}")))
        }
    }

    pub(super) fn non_negative(&self, span: Range<usize>, what: &str, v: f32) -> Result<f32> {
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err_field(span, what, format!("{what} must be a finite number ≥ 0, got {v}")))
        }
    }

    pub(super) fn finite3(&self, span: Range<usize>, what: &str, v: Vec3) -> Result<Vec3> {
        if v.is_finite() { Ok(v) } else { Err(self.err_field(span, what, format!("{what} must be finite, got {v}"))) }
    }

    fn non_negative3(&self, span: Range<usize>, what: &str, v: Vec3) -> Result<Vec3> {
        if v.is_finite() && v.min_element() >= 0.0 {
            Ok(v)
        } else {
            Err(self.err_field(span, what, format!("{what} must be finite and ≥ 0, got {v}")))
        }
    }

    pub(super) fn nonzero3(&self, span: Range<usize>, what: &str, v: Vec3) -> Result<Vec3> {
        let v = self.finite3(span.clone(), what, v)?;
        if v.length_squared() > 0.0 {
            Ok(v)
        } else {
            Err(self.err_field(span, what, format!("{what} must not be zero")))
        }
    }

    fn camera(&self, desc: &Spanned<CameraDesc>) -> Result<Camera> {
        let span = desc.span();
        let c = desc.get_ref();
        let point = |v: Option<Point>, name: &str, default: Vec3| -> Result<Vec3> {
            self.finite3(span.clone(), &format!("camera.{name}"), v.map_or(default, |p| p.0))
        };
        let default = default_camera();
        let look_at = point(c.look_at, "look_at", Vec3::new(0.0, 1.0, 0.0))?;
        let up = self.nonzero3(span.clone(), "camera.up", c.up.map_or(Vec3::Y, |p| p.0))?;
        let position = match c.kind {
            CameraType::Isometric => {
                if c.position.is_some() {
                    return Err(self.err(span, "an isometric camera is placed by look_at and distance, not position"));
                }
                let distance = self.positive(span.clone(), "camera.distance", c.distance.unwrap_or(50.0))?;
                look_at - crate::camera::ISOMETRIC_VIEW * distance
            }
            _ => point(c.position, "position", default.position)?,
        };
        let forward = look_at - position;
        if forward.length_squared() == 0.0 {
            return Err(self.err_field(span, "look_at", "camera.position and camera.look_at must differ"));
        }
        if forward.normalize().cross(up.normalize()).length() < 1e-6 {
            return Err(self.err(span, "camera.up must not be parallel to the view direction"));
        }
        let projection = match c.kind {
            CameraType::Perspective => {
                if c.view_height.is_some() {
                    return Err(self.err_field(
                        span,
                        "view_height",
                        "view_height is for orthographic cameras; a perspective camera takes fov",
                    ));
                }
                let fov = c.fov.unwrap_or(40.0);
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(self.err_field(
                        span,
                        "fov",
                        format!("camera.fov must be between 0 and 180 degrees, got {fov}"),
                    ));
                }
                Projection::Perspective { fov_degrees: fov }
            }
            CameraType::Orthographic | CameraType::Isometric => {
                if c.fov.is_some() {
                    return Err(self.err_field(
                        span,
                        "fov",
                        "fov is for perspective cameras; an orthographic camera takes view_height",
                    ));
                }
                let h = self.positive(span.clone(), "camera.view_height", c.view_height.unwrap_or(10.0))?;
                Projection::Orthographic { view_height: h }
            }
        };
        let aperture = self.non_negative(span.clone(), "camera.aperture", c.aperture.unwrap_or(0.0))?;
        let focus = c.focus_distance.unwrap_or(forward.length());
        let focus = self.positive(span, "camera.focus_distance", focus)?;
        Ok(Camera::oriented(position, look_at, up, projection).with_lens(aperture, focus))
    }

    fn medium(&self, desc: &Spanned<MediumDesc>) -> Result<Medium> {
        let span = desc.span();
        let m = desc.get_ref();
        let sigma_a = self.non_negative3(span.clone(), "medium.sigma_a", m.sigma_a.map_or(Vec3::ZERO, |t| t.0))?;
        let sigma_s = self.non_negative3(span.clone(), "medium.sigma_s", m.sigma_s.map_or(Vec3::ZERO, |t| t.0))?;
        let g = m.g.unwrap_or(0.0);
        if !(g > -1.0 && g < 1.0) {
            return Err(self.err_field(span, "g", format!("medium.g must lie strictly between -1 and 1, got {g}")));
        }
        match m.kind {
            MediumType::Homogeneous => {
                if m.base.is_some() || m.falloff.is_some() {
                    return Err(self.err_field(
                        span,
                        if m.base.is_some() { "base" } else { "falloff" },
                        "base and falloff belong to a `height` medium, not a homogeneous one",
                    ));
                }
                Ok(Medium::homogeneous(sigma_a, sigma_s, g))
            }
            MediumType::Height => {
                let base = self.finite(span.clone(), "medium.base", m.base.unwrap_or(0.0))?;
                let falloff = self.non_negative(span, "medium.falloff", m.falloff.unwrap_or(0.5))?;
                Ok(Medium::height(sigma_a, sigma_s, g, base, falloff))
            }
        }
    }

    fn material(&self, name: &str, desc: &Spanned<MaterialDesc>) -> Result<Material> {
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
        })
    }

    fn object(&self, index: usize, desc: &Spanned<ObjectDesc>, scene: &SceneDesc) -> Result<(Shape, String)> {
        let span = desc.span();
        let o = desc.get_ref();
        let kind = format!("{:?}", o.kind).to_lowercase();
        let label = format!("objects[{index}] ({kind})");
        let fields: [(&str, bool); 18] = [
            ("shape", o.shape.is_some()),
            ("children", o.children.is_some()),
            ("blend", o.blend.is_some()),
            ("a", o.a.is_some()),
            ("b", o.b.is_some()),
            ("major_radius", o.major_radius.is_some()),
            ("minor_radius", o.minor_radius.is_some()),
            ("rounding", o.rounding.is_some()),
            ("center", o.center.is_some()),
            ("radius", o.radius.is_some()),
            ("point", o.point.is_some()),
            ("normal", o.normal.is_some()),
            ("corner", o.corner.is_some()),
            ("edge_u", o.edge_u.is_some()),
            ("edge_v", o.edge_v.is_some()),
            ("min", o.min.is_some()),
            ("max", o.max.is_some()),
            ("file", o.file.is_some()),
        ];
        let takes: &[&str] = match o.kind {
            ObjectType::Sphere => &["center", "radius"],
            ObjectType::Plane => &["point", "normal"],
            ObjectType::Quad => &["corner", "edge_u", "edge_v"],
            ObjectType::Box => &["min", "max"],
            ObjectType::Mesh => &["file"],
            // The node's own shape decides (sdf.rs); other types' fields are not for it.
            ObjectType::Sdf => {
                let sdf_fields = fields.iter().filter(|(n, _)| !matches!(*n, "corner" | "edge_u" | "edge_v" | "file"));
                let names: Vec<&str> = sdf_fields.map(|(n, _)| *n).collect();
                self.check_fields(span.clone(), &label, &kind, &fields, &[], &names)?;
                &[]
            }
        };
        if o.kind != ObjectType::Sdf {
            self.check_fields(span.clone(), &label, &kind, &fields, takes, &[])?;
        }
        let get = |p: Option<Point>, name: &str| self.finite3(span.clone(), &format!("{label}.{name}"), p.unwrap().0);
        let shape = match o.kind {
            ObjectType::Sphere => {
                let radius = self.positive(span.clone(), &format!("{label}.radius"), o.radius.unwrap())?;
                Shape::sphere(get(o.center, "center")?, radius)
            }
            ObjectType::Plane => {
                let normal = self.nonzero3(span.clone(), &format!("{label}.normal"), o.normal.unwrap().0)?;
                Shape::plane(get(o.point, "point")?, normal)
            }
            ObjectType::Quad => {
                let (u, v) = (get(o.edge_u, "edge_u")?, get(o.edge_v, "edge_v")?);
                if u.cross(v).length_squared() == 0.0 {
                    return Err(self.err_field(
                        span,
                        "edge_v",
                        format!("{label}: edge_u and edge_v must not be parallel or zero"),
                    ));
                }
                Shape::quad(get(o.corner, "corner")?, u, v)
            }
            ObjectType::Box => {
                let (min, max) = (get(o.min, "min")?, get(o.max, "max")?);
                if !min.cmplt(max).all() {
                    return Err(self.err_field(
                        span,
                        "max",
                        format!("{label}: min must be less than max on every axis, got min {min} max {max}"),
                    ));
                }
                Shape::cuboid(min, max)
            }
            ObjectType::Mesh => self.mesh(&label, o.file.as_ref().unwrap())?,
            ObjectType::Sdf => Shape::Sdf(self.sdf_object(span.clone(), &label, o)?),
        };
        let transform = self.transform(span.clone(), &label, o)?;
        let material = match &o.material {
            Some(name) => {
                if !scene.materials.contains_key(name.get_ref()) {
                    let known: Vec<&str> = scene.materials.keys().map(String::as_str).collect();
                    return Err(self.err(
                        name.span(),
                        format!("{label}: unknown material `{}`; the scene defines: {}", name.get_ref(), list(&known)),
                    ));
                }
                name.get_ref().clone()
            }
            None => {
                return Err(self.err(span, format!("{label} needs a `material` (a name from [materials])")));
            }
        };
        Ok((shape.transformed(transform), material))
    }

    /// Checks that an object or light has every field its type needs and
    /// none that belongs to another type.
    pub(super) fn check_fields(
        &self,
        span: Range<usize>,
        label: &str,
        kind: &str,
        fields: &[(&str, bool)],
        required: &[&str],
        optional: &[&str],
    ) -> Result<()> {
        for (name, present) in fields {
            if *present && !required.contains(name) && !optional.contains(name) {
                let takes = [required, optional].concat();
                return Err(self.err_field(
                    span,
                    name,
                    format!("{label}: `{name}` does not belong to a {kind}, which takes {}", list(&takes)),
                ));
            }
        }
        for name in required {
            if !fields.iter().any(|(n, present)| n == name && *present) {
                return Err(self.err(span, format!("{label}: a {kind} needs `{name}`")));
            }
        }
        Ok(())
    }

    /// T·Rz·Ry·Rx·S: scale, then rotate about X, Y, Z (degrees), then translate.
    fn transform(&self, span: Range<usize>, label: &str, o: &ObjectDesc) -> Result<Affine3A> {
        self.transform_parts(span, label, o.translate, o.rotate, o.scale)
    }

    /// The transform of `translate`, `rotate` (degrees) and `scale`, each optional.
    pub(super) fn transform_parts(
        &self,
        span: Range<usize>,
        label: &str,
        translate: Option<Point>,
        rotate: Option<Point>,
        scale: Option<Triple>,
    ) -> Result<Affine3A> {
        let translate =
            self.finite3(span.clone(), &format!("{label}.translate"), translate.map_or(Vec3::ZERO, |p| p.0))?;
        let rotate = self.finite3(span.clone(), &format!("{label}.rotate"), rotate.map_or(Vec3::ZERO, |p| p.0))?;
        let scale = self.finite3(span.clone(), &format!("{label}.scale"), scale.map_or(Vec3::ONE, |p| p.0))?;
        if scale.cmpeq(Vec3::ZERO).any() {
            return Err(self.err_field(
                span,
                "scale",
                format!("{label}.scale must not be zero on any axis, got {scale}"),
            ));
        }
        let r = rotate * (std::f32::consts::PI / 180.0);
        let rotation = Quat::from_rotation_z(r.z) * Quat::from_rotation_y(r.y) * Quat::from_rotation_x(r.x);
        Ok(Affine3A::from_scale_rotation_translation(scale, rotation, translate))
    }

    fn mesh(&self, label: &str, file: &Spanned<String>) -> Result<Shape> {
        let path = match self.base_dir {
            Some(dir) => dir.join(file.get_ref()),
            None => file.get_ref().into(),
        };
        let fail =
            |why: String| self.err(file.span(), format!("{label}: cannot load mesh `{}`: {why}", path.display()));
        let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
        let (models, _) = tobj::load_obj(&path, &options).map_err(|e| fail(e.to_string()))?;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for model in &models {
            let m = &model.mesh;
            let base = positions.len() as u32;
            for p in m.positions.chunks_exact(3) {
                let v = Vec3::new(p[0], p[1], p[2]);
                if !v.is_finite() {
                    return Err(fail(format!("vertex {} is not finite", positions.len())));
                }
                positions.push(v);
            }
            let count = m.positions.len() / 3;
            for t in m.indices.chunks_exact(3) {
                if t.iter().any(|&i| i as usize >= count) {
                    return Err(fail(format!("a face refers to vertex {} of {count}", t.iter().max().unwrap() + 1)));
                }
                triangles.push([base + t[0], base + t[1], base + t[2]]);
            }
        }
        if triangles.is_empty() {
            return Err(fail("it holds no faces".into()));
        }
        Ok(Shape::Mesh { positions, triangles })
    }

    fn light(&self, index: usize, desc: &Spanned<LightDesc>) -> Result<Light> {
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
                    (Some(d), None) => self.nonzero3(span.clone(), &at("direction"), d.0)?,
                    (None, Some(t)) => self
                        .nonzero3(span.clone(), &at("look_at"), t.0 - position)
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
                    direction: direction.normalize(),
                    intensity: power(l.intensity, "intensity")?,
                    cone_angle: cone.to_radians(),
                    falloff_start: start.to_radians(),
                    profile: l.profile.map_or(SpotProfile::Smoothstep, Into::into),
                    attenuation: Attenuation::PHYSICAL,
                }
            }
            LightType::Distant => {
                check(&["direction", "irradiance"], &[])?;
                let d = self.nonzero3(span.clone(), &at("direction"), l.direction.unwrap().0)?;
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
                if u.cross(v).length_squared() == 0.0 {
                    return Err(self.err_field(
                        span,
                        "edge_v",
                        format!("{label}: edge_u and edge_v must not be parallel or zero"),
                    ));
                }
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
}

impl Checker<'_> {
    /// A light's `keyframes`: times in [0, 1], strictly increasing, finite
    /// positions; not on a distant light.
    fn keyframes(&self, index: usize, desc: &Spanned<LightDesc>, light: &Light) -> Result<Option<Keyframes>> {
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
            out.push((*time, position.0));
        }
        Ok(Keyframes::new(out))
    }
}

fn list(names: &[&str]) -> String {
    if names.is_empty() {
        return "(none)".into();
    }
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}

/// The table (at any depth: nested, in arrays of tables, inline) whose span
/// starts at `start`.
fn find_table<'d, 'i>(table: &'d toml::de::DeTable<'i>, start: usize) -> Option<&'d toml::de::DeTable<'i>> {
    use toml::de::DeValue;
    fn in_value<'d, 'i>(value: &'d toml::Spanned<DeValue<'i>>, start: usize) -> Option<&'d toml::de::DeTable<'i>> {
        match value.get_ref() {
            DeValue::Table(t) if value.span().start == start => Some(t),
            DeValue::Table(t) => find_table(t, start),
            DeValue::Array(items) => items.iter().find_map(|item| in_value(item, start)),
            _ => None,
        }
    }
    table.values().find_map(|value| in_value(value, start))
}
