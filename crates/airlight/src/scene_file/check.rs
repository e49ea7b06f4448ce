//! From a scene file to a [`Scene`]: parse, check every value, load meshes.
//! Each error names the place in the file and what was expected.

use super::desc::*;
use crate::assets::{AssetPath, Loader};
use crate::scene::{MAX_IMAGE_SIDE, RENDER_SETTINGS, RenderSettings, Scene, SceneBuilder, SceneError, limits};
use glam::Vec3;
use std::cell::RefCell;
use std::ops::Range;

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
/// scene. Mesh files are looked up in `assets` (see [`AssetPath`]); the
/// scene lists those it read ([`Scene::files`]). The `[render]` table's
/// integrator options are not read here (see [`crate::SceneFile`]).
pub fn build(desc: &SceneDesc, text: &str, assets: &AssetPath) -> Result<Scene, SceneError> {
    build_as(desc, text, assets, false)
}

/// [`build`], and when `model_alone` (a glTF file opened as the scene)
/// what a model needs to be seen: a sky when it brings no light, and a
/// camera that frames it when it brings none, each said in a note.
pub(super) fn build_as(
    desc: &SceneDesc,
    text: &str,
    assets: &AssetPath,
    model_alone: bool,
) -> Result<Scene, SceneError> {
    let mut checker = Checker::new(text, assets)?;
    checker.model_alone = model_alone;
    let mut scene = checker.scene(desc)?;
    scene.files = checker.loader.into_files();
    scene.notes = checker.notes.into_inner();
    Ok(scene)
}

/// The sky that lights a model opened alone without lights of its own.
const MODEL_SKY: f32 = 1.0;

/// The vertical field of view of the camera that frames a model.
const MODEL_FOV_DEGREES: f32 = 40.0;

/// A camera that frames the meshes and lights of `included`: it looks at
/// the centre of their bounds from the front (+z, glTF's front) and a
/// little above, far enough that the sphere around their bounding box,
/// seen as a disk, fits the narrower of the two fields of view. None when
/// they hold no mesh.
fn framing_camera(included: &[crate::assets::Imported], aspect: f32) -> Option<crate::camera::Camera> {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for imported in included {
        for (shape, _) in &imported.parts.objects {
            if let crate::geometry::Shape::Mesh { positions, .. } = shape {
                positions.iter().for_each(|p| (lo, hi) = (lo.min(*p), hi.max(*p)));
            }
        }
        for light in &imported.parts.lights {
            if let crate::light::Light::Triangle { a, edge_1, edge_2, .. } = *light {
                for p in [a, a + edge_1, a + edge_2] {
                    (lo, hi) = (lo.min(p), hi.max(p));
                }
            }
        }
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    let half = (0.5 * MODEL_FOV_DEGREES).to_radians();
    let narrower = if aspect < 1.0 { (half.tan() * aspect).atan() } else { half };
    let distance = radius / narrower.tan();
    let from = Vec3::new(0.0, 0.25, 1.0).normalize() * distance;
    Some(crate::camera::Camera::look_at(centre + from, centre, Vec3::Y, MODEL_FOV_DEGREES))
}

/// The checks and building of one scene file: its text, where each value
/// stands in it, and the files it reads.
pub(super) struct Checker<'a> {
    pub(super) text: &'a str,
    /// The text parsed to a spanned document: where each key and value
    /// stands, for errors found after deserializing, and the tables read
    /// by their types' structs ([`super::tables`]).
    pub(super) document: toml::de::DeTable<'a>,
    /// The files the scene names.
    pub(super) loader: Loader<'a>,
    /// What was asked for and is not done (see [`Scene::notes`]).
    pub(super) notes: RefCell<Vec<String>>,
    /// Whether the scene is a glTF file opened alone ([`build_as`]).
    model_alone: bool,
}

pub(super) type Result<T, E = SceneError> = std::result::Result<T, E>;

impl<'a> Checker<'a> {
    pub(super) fn new(text: &'a str, assets: &'a AssetPath) -> Result<Self> {
        let document = toml::de::DeTable::parse(text).map_err(|e| {
            let at = e.span().map_or(0, |s| s.start);
            SceneError::at(text, at, e.message().trim_end())
        })?;
        Ok(Checker {
            text,
            document: document.into_inner(),
            loader: Loader::new(assets),
            notes: RefCell::default(),
            model_alone: false,
        })
    }
}

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
        let mut settings = self.settings(desc)?;
        let mut included = Vec::new();
        for (i, include) in desc.include.iter().enumerate() {
            let mut imported = self.include(i, include, desc)?;
            self.notes.borrow_mut().append(&mut imported.notes);
            included.push(imported);
        }
        // An included camera serves when the file has none; its aspect
        // ratio sets the height when the file sets no size.
        let included_camera = included.iter_mut().find_map(|i| i.camera.take()).filter(|_| desc.camera.is_none());
        if let Some((_, Some(aspect))) = included_camera
            && desc.render.get("width").is_none()
            && desc.render.get("height").is_none()
            && aspect.is_finite()
            && aspect > 0.0
        {
            settings.film.height = ((settings.film.width as f32 / aspect).round() as u32).clamp(1, MAX_IMAGE_SIDE);
        }
        let aspect = settings.film.width as f32 / settings.film.height.max(1) as f32;
        let mut builder = SceneBuilder::new().settings(settings);
        let framed = included_camera.is_none() && desc.camera.is_none() && self.model_alone;
        if let Some((camera, _)) = included_camera {
            builder = builder.camera(camera);
        }
        if framed && let Some(camera) = framing_camera(&included, aspect) {
            self.notes.borrow_mut().push(format!(
                "the model has no camera: added one at {} looking at the centre of its bounds",
                camera.position
            ));
            builder = builder.camera(camera);
        }
        // Glowing surfaces (emissive materials) rarely light a model: a
        // model without lights of its own (KHR_lights_punctual) gets a sky.
        let glow = |l: &crate::light::Light| matches!(l, crate::light::Light::Triangle { .. });
        if self.model_alone && desc.lights.is_empty() && included.iter().all(|i| i.parts.lights.iter().all(glow)) {
            self.notes.borrow_mut().push(format!(
                "the model has no lights: added a uniform sky of radiance {MODEL_SKY} (a scene file that \
                 includes the model sets its own lights)"
            ));
            builder = builder.light(crate::light::Light::sky(crate::Rgb::splat(MODEL_SKY)));
        }
        if desc.camera.is_some() {
            builder = builder.camera(self.camera()?);
        }
        if desc.medium.is_some() {
            builder = builder.medium(self.medium()?);
        }
        for name in desc.materials.keys() {
            builder = builder.material(name, self.material(name)?);
        }
        for i in 0..desc.objects.len() {
            builder = builder.parts(self.object(i, desc)?);
        }
        for imported in included {
            builder = builder.parts(imported.parts);
        }
        let mut mapped_skies = 0;
        for i in 0..desc.lights.len() {
            let (light, motion, map) = self.light(i)?;
            builder = match (self.keyframes(i, &motion, &light)?, map, light) {
                (_, Some(map), crate::light::Light::Sky { radiance }) => {
                    mapped_skies += 1;
                    if mapped_skies > 1 {
                        let span = self.section_element("lights", i)?.span();
                        return Err(self.err(span, format!("lights[{i}]: a scene has at most one sky with a `file`")));
                    }
                    builder.environment(radiance, map)
                }
                (Some(path), _, light) => builder.moving_light(light, path),
                (None, _, light) => builder.light(light),
            };
        }
        builder.build()
    }

    /// The film settings `[render]` gives, each checked by its declaration
    /// (the integrators' options there are read by `SceneFile`).
    fn settings(&self, desc: &SceneDesc) -> Result<RenderSettings> {
        let r = &desc.render;
        let mut s = RenderSettings::default();
        for spec in RENDER_SETTINGS {
            if let Some(v) = r.get(spec.key) {
                spec.apply(&mut s, v.get_ref()).map_err(|e| self.err(v.span(), format!("render.{e}")))?;
            }
        }
        if let Err(message) = s.validate() {
            let span = r.get("height").or(r.get("width")).map_or(0..0, |v| v.span());
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

    pub(super) fn non_negative3(&self, span: Range<usize>, what: &str, v: Vec3) -> Result<Vec3> {
        if v.is_finite() && v.min_element() >= 0.0 {
            Ok(v)
        } else {
            Err(self.err_field(span, what, format!("{what} must be finite and ≥ 0, got {v}")))
        }
    }

    /// A direction: finite, not zero, returned at unit length (made so in
    /// f64, so that neither 1e20 nor 1e-30 on an axis is lost to f32).
    pub(super) fn direction(&self, span: Range<usize>, what: &str, v: Vec3) -> Result<Vec3> {
        let v = self.finite3(span.clone(), what, v)?;
        limits::unit(v).ok_or_else(|| self.err_field(span, what, format!("{what} must not be zero")))
    }

    /// A box's corners (a box object's, a box light's): `min` below `max`
    /// on every axis.
    pub(super) fn box_corners(&self, span: Range<usize>, label: &str, min: Vec3, max: Vec3) -> Result<()> {
        if min.cmplt(max).all() {
            return Ok(());
        }
        let message = format!("{label}: min must be less than max on every axis, got min {min} max {max}");
        Err(self.err_field(span, "max", message))
    }

    /// A quad's edges: not parallel (in f64), and making a normal in f32.
    pub(super) fn edges(&self, span: Range<usize>, label: &str, u: Vec3, v: Vec3) -> Result<()> {
        let reach = limits::reach_of(u).max(limits::reach_of(v));
        if reach > limits::MAX_COORDINATE {
            return Err(self.err_field(span, "edge_u", limits::too_far(&format!("{label}.edge_u or edge_v"), reach)));
        }
        let parallel = limits::unit(u).is_none() || limits::unit(v).is_none() || limits::sin_between(u, v) == 0.0;
        if parallel {
            return Err(self.err_field(
                span,
                "edge_v",
                format!("{label}: edge_u and edge_v must not be parallel or zero"),
            ));
        }
        // The quad's normal and area come from |u × v|² in f32.
        if !u.cross(v).length_squared().is_normal() {
            let exact = u.as_dvec3().cross(v.as_dvec3()).length();
            return Err(self.err_field(
                span,
                "edge_v",
                format!(
                    "{label}: the area |edge_u × edge_v| = {exact:.3e} is too small for 32-bit floats; \
                     it must be at least 1.1e-19"
                ),
            ));
        }
        Ok(())
    }
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
