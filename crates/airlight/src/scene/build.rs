//! From a scene file to a [`Scene`]: parse, check every value, load meshes.
//! Each error names the place in the file and what was expected.

use super::assets::AssetPath;
use super::desc::*;
use super::gltf;
use super::limits;
use super::{MAX_IMAGE_SIDE, MAX_SPP, RenderSettings, Scene, SceneBuilder, SceneError, desc};
use crate::Rgb;
use crate::geometry::Shape;
use crate::light::Light;
use crate::material::Material;
use glam::{Affine3A, Quat, Vec3};
use std::cell::{Cell, RefCell};
use std::ops::Range;
use std::path::PathBuf;
use toml::Spanned;

/// What one `[[objects]]` table builds: surfaces with the names of their
/// materials, the materials it brings (an OBJ's `.mtl`), and the lights
/// of emitting surfaces.
#[derive(Default)]
pub(super) struct Built {
    pub materials: Vec<(String, Material)>,
    pub objects: Vec<(Shape, String)>,
    pub lights: Vec<Light>,
}

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
    // The same text parsed to a spanned document: where each key and value
    // stands, for errors found after deserializing.
    let document = toml::de::DeTable::parse(text).map(|d| d.into_inner()).unwrap_or_default();
    let checker = Checker {
        text,
        assets,
        document,
        files: RefCell::default(),
        mesh_bytes: Cell::new(0),
        notes: RefCell::default(),
        textures: RefCell::default(),
    };
    let mut scene = checker.scene(desc)?;
    scene.files = checker.files.into_inner();
    scene.notes = checker.notes.into_inner();
    Ok(scene)
}

pub(super) struct Checker<'a> {
    pub(super) text: &'a str,
    pub(super) assets: &'a AssetPath,
    pub(super) document: toml::de::DeTable<'a>,
    /// The files read so far (meshes).
    pub(super) files: RefCell<Vec<PathBuf>>,
    /// Memory the meshes read so far will take.
    pub(super) mesh_bytes: Cell<u64>,
    /// What was asked for and is not done (see [`Scene::notes`]).
    pub(super) notes: RefCell<Vec<String>>,
    /// Image files read as textures, so that each is read once.
    pub(super) textures: RefCell<Vec<(PathBuf, std::sync::Arc<crate::texture::Texture>)>>,
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
        let mut settings = self.settings(desc)?;
        let mut included = Vec::new();
        for (i, include) in desc.include.iter().enumerate() {
            included.push(self.include(i, include, desc)?);
        }
        // An included camera serves when the file has none; its aspect
        // ratio sets the height when the file sets no size.
        let included_camera = included.iter_mut().find_map(|i| i.camera.take()).filter(|_| desc.camera.is_none());
        if let Some((_, Some(aspect))) = included_camera
            && desc.render.width.is_none()
            && desc.render.height.is_none()
            && aspect.is_finite()
            && aspect > 0.0
        {
            settings.height = ((settings.width as f32 / aspect).round() as u32).clamp(1, MAX_IMAGE_SIDE);
        }
        let mut builder = SceneBuilder::new().settings(settings);
        if let Some((camera, _)) = included_camera {
            builder = builder.camera(camera);
        }
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
            let built = self.object(i, object, desc)?;
            builder = built.materials.into_iter().fold(builder, |b, (name, m)| b.material(&name, m));
            builder = built.objects.into_iter().fold(builder, |b, (shape, name)| b.object(shape, &name));
            builder = built.lights.into_iter().fold(builder, SceneBuilder::light);
        }
        for imported in included {
            let built = imported.built;
            builder = built.materials.into_iter().fold(builder, |b, (name, m)| b.material(&name, m));
            builder = built.objects.into_iter().fold(builder, |b, (shape, name)| b.object(shape, &name));
            builder = built.lights.into_iter().fold(builder, SceneBuilder::light);
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
        if let Some(a) = r.adaptive {
            s.adaptive = a;
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

    fn object(&self, index: usize, desc: &Spanned<ObjectDesc>, scene: &SceneDesc) -> Result<Built> {
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
        if o.kind == ObjectType::Mesh && o.material.is_none() && o.emission.is_none() {
            let transform = self.transform(span.clone(), &label, o)?;
            return self.mesh_with_materials(span, &label, o.file.as_ref().unwrap(), transform);
        }
        let get = |p: Option<Point>, name: &str| self.finite3(span.clone(), &format!("{label}.{name}"), p.unwrap().0);
        let shape = match o.kind {
            ObjectType::Sphere => {
                let radius = self.positive(span.clone(), &format!("{label}.radius"), o.radius.unwrap())?;
                Shape::sphere(get(o.center, "center")?, radius)
            }
            ObjectType::Plane => {
                let normal = self.direction(span.clone(), &format!("{label}.normal"), o.normal.unwrap().0)?;
                Shape::plane(get(o.point, "point")?, normal)
            }
            ObjectType::Quad => {
                let (u, v) = (get(o.edge_u, "edge_u")?, get(o.edge_v, "edge_v")?);
                self.edges(span.clone(), &label, u, v)?;
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
        if let Some(emission) = o.emission {
            let radiance = self.non_negative3(span.clone(), &format!("{label}.emission"), emission.0)?;
            if let Some(material) = &o.material {
                return Err(self.err(
                    material.span(),
                    format!("{label}: an emitting object's surface is black and reflects nothing; drop its `material`"),
                ));
            }
            let placed = self.placed(span.clone(), &label, shape.transformed(transform))?;
            let lights = self.emitter(span, &label, placed, radiance)?;
            return Ok(Built { lights, ..Built::default() });
        }
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
        let objects = vec![(self.placed(span, &label, shape.transformed(transform))?, material)];
        Ok(Built { objects, ..Built::default() })
    }

    /// One `[[include]]`: a glTF file, or an OBJ file as a mesh object
    /// would take it.
    fn include(&self, index: usize, desc: &Spanned<IncludeDesc>, scene: &SceneDesc) -> Result<gltf::Imported> {
        let span = desc.span();
        let d = desc.get_ref();
        let label = format!("include[{index}]");
        let transform = self.transform_parts(span.clone(), &label, d.translate, d.rotate, d.scale)?;
        if let Some(name) = &d.material
            && !scene.materials.contains_key(name.get_ref())
        {
            let known: Vec<&str> = scene.materials.keys().map(String::as_str).collect();
            return Err(self.err(
                name.span(),
                format!("{label}: unknown material `{}`; the scene defines: {}", name.get_ref(), list(&known)),
            ));
        }
        let material = d.material.as_ref().map(|m| m.get_ref().as_str());
        let file = d.file.get_ref().to_ascii_lowercase();
        if file.ends_with(".obj") {
            if d.scene.is_some() {
                return Err(self.err_field(span, "scene", format!("{label}: `scene` is for glTF files")));
            }
            let built = match material {
                Some(name) => {
                    let shape = self.placed(span, &label, self.mesh(&label, &d.file)?.transformed(transform))?;
                    Built { objects: vec![(shape, name.to_string())], ..Built::default() }
                }
                None => self.mesh_with_materials(span, &label, &d.file, transform)?,
            };
            return Ok(gltf::Imported { built, camera: None });
        }
        if !(file.ends_with(".gltf") || file.ends_with(".glb")) {
            return Err(self.err(d.file.span(), format!("{label}: `file` must be a .gltf, .glb or .obj file")));
        }
        self.gltf(&gltf::Include { label: &label, file: &d.file, scene: d.scene.as_deref(), transform, material })
    }

    /// A mesh object without a `material`: its faces take the `.mtl`
    /// materials their `usemtl` names, `Kd` as a diffuse albedo (0.8 when
    /// absent), and faces whose material has a `Ke` emit it.
    fn mesh_with_materials(
        &self,
        span: Range<usize>,
        label: &str,
        file: &Spanned<String>,
        transform: Affine3A,
    ) -> Result<Built> {
        let parts = self.mesh_parts(label, file)?;
        let only_part = parts.len() == 1;
        let mut built = Built::default();
        for part in parts {
            let texture = part.texture;
            let Some(m) = part.material else {
                let why = if only_part {
                    "(a name from [materials]), or faces with `usemtl` materials from an `mtllib`"
                } else {
                    "for its faces before the first `usemtl`"
                };
                return Err(self.err(span, format!("{label} needs a `material` {why}")));
            };
            let placed = self.placed(span.clone(), label, part.shape.transformed(transform))?;
            match m.emission {
                Some(radiance) if radiance.max_element() > 0.0 => {
                    built.lights.extend(self.emitter(span.clone(), label, placed, radiance)?)
                }
                _ => {
                    let name = format!("{}:{}", file.get_ref(), m.name);
                    let material = match texture {
                        // The MTL convention: the map scaled by Kd (1 when absent).
                        Some(t) => Material::textured(m.diffuse.unwrap_or(Vec3::ONE), t),
                        None => Material::diffuse(m.diffuse.unwrap_or(Vec3::splat(0.8))),
                    };
                    built.materials.push((name.clone(), material));
                    built.objects.push((placed, name));
                }
            }
        }
        Ok(built)
    }

    /// The lights an emitting object becomes: a sphere light, a quad light,
    /// or a triangle light per triangle of a mesh (degenerate triangles,
    /// which emit nothing, are left out).
    fn emitter(&self, span: Range<usize>, label: &str, shape: Shape, radiance: Rgb) -> Result<Vec<Light>> {
        match shape {
            Shape::Sphere { center, radius } => Ok(vec![Light::sphere(center, radius, radiance)]),
            Shape::Quad { corner, edge_u, edge_v } => Ok(vec![Light::quad(corner, edge_u, edge_v, radiance)]),
            // The mesh's memory was checked when it was read.
            Shape::Mesh { positions, triangles, .. } => Ok(Light::triangles_of(&positions, &triangles, radiance)),
            _ => Err(self.err_field(
                span,
                "emission",
                format!(
                    "{label}: only sphere, quad and mesh objects can emit (a sphere stretched by `scale` \
                     cannot either)"
                ),
            )),
        }
    }

    /// A shape in world space, checked for what its transform may have
    /// pushed out of f32's range: too far, edges or a normal lost.
    fn placed(&self, span: Range<usize>, label: &str, shape: Shape) -> Result<Shape> {
        let extent = limits::shape_extent(&shape);
        // Never NaN: a shape with a non-finite point reaches infinity.
        if extent > limits::MAX_COORDINATE {
            return Err(self.err(span, limits::too_far(label, extent)));
        }
        match &shape {
            Shape::Quad { edge_u, edge_v, .. } => self.edges(span, label, *edge_u, *edge_v)?,
            Shape::Plane { normal, .. } if !normal.is_normalized() => {
                return Err(self.err_field(span, "scale", format!("{label}: its scale leaves the plane no normal")));
            }
            Shape::Transformed { world_from_local, .. } if !world_from_local.inverse().is_finite() => {
                return Err(self.err_field(span, "scale", format!("{label}: its scale is too small to invert")));
            }
            _ => {}
        }
        Ok(shape)
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
