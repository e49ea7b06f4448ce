//! Objects of a scene file: each `[[objects]]` table's shape, its place
//! (transform), its material and, for emitting surfaces, its lights; and
//! each `[[include]]`d glTF file's meshes.

use super::check::{Checker, Result};
use super::desc::*;
use crate::Rgb;
use crate::assets::{GltfInclude, Imported, MeshPart};
use crate::geometry::Shape;
use crate::light::Light;
use crate::material::Material;
use crate::scene::{Parts, limits};
use glam::{Affine3A, Quat, Vec3};
use std::ops::Range;
use toml::Spanned;

impl Checker<'_> {
    /// The `index`th `[[objects]]` table read by its type, and what it
    /// builds.
    pub(super) fn object(&self, index: usize, scene: &SceneDesc) -> Result<Parts> {
        let label = format!("objects[{index}]");
        let read = self.read_table::<ObjectDesc>(self.section_element("objects", index)?, &label)?;
        let label = format!("{label} ({})", read.name);
        let span = read.table.span();
        let o = &read.shared;
        let transform = self.transform_parts(span.clone(), &label, o.translate, o.rotate, o.scale)?;
        if let ObjectDesc::Mesh(mesh) = &read.kind
            && o.material.is_none()
            && o.emission.is_none()
        {
            return self.mesh_with_materials(span, &label, &mesh.file, transform);
        }
        let get = |p: Point, name: &str| self.finite3(span.clone(), &format!("{label}.{name}"), p.0);
        let shape = match &read.kind {
            ObjectDesc::Sphere(s) => {
                let radius = self.positive(span.clone(), &format!("{label}.radius"), s.radius)?;
                Shape::sphere(get(s.center, "center")?, radius)
            }
            ObjectDesc::Plane(p) => {
                let normal = self.direction(span.clone(), &format!("{label}.normal"), p.normal.0)?;
                Shape::plane(get(p.point, "point")?, normal)
            }
            ObjectDesc::Quad(q) => {
                let (u, v) = (get(q.edge_u, "edge_u")?, get(q.edge_v, "edge_v")?);
                self.edges(span.clone(), &label, u, v)?;
                Shape::quad(get(q.corner, "corner")?, u, v)
            }
            ObjectDesc::Box(b) => {
                let (min, max) = (get(b.min, "min")?, get(b.max, "max")?);
                self.box_corners(span.clone(), &label, min, max)?;
                Shape::cuboid(min, max)
            }
            ObjectDesc::Mesh(mesh) => self.mesh(&label, &mesh.file)?,
            ObjectDesc::Sdf(SdfObject) => Shape::Sdf(self.sdf_object(&label, &read.table)?),
        };
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
            return Ok(Parts { lights, ..Parts::default() });
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
        Ok(Parts { objects, ..Parts::default() })
    }

    /// One `[[include]]`: a glTF file, or an OBJ file as a mesh object
    /// would take it.
    pub(super) fn include(&self, index: usize, desc: &Spanned<IncludeDesc>, scene: &SceneDesc) -> Result<Imported> {
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
                    Parts { objects: vec![(shape, name.to_string())], ..Parts::default() }
                }
                None => self.mesh_with_materials(span, &label, &d.file, transform)?,
            };
            return Ok(Imported { parts: built, notes: Vec::new(), camera: None });
        }
        if !(file.ends_with(".gltf") || file.ends_with(".glb")) {
            return Err(self.err(d.file.span(), format!("{label}: `file` must be a .gltf, .glb or .obj file")));
        }
        let include =
            GltfInclude { label: &label, file: d.file.get_ref(), scene: d.scene.as_deref(), transform, material };
        self.loader.gltf(&include).map_err(|why| self.err(d.file.span(), why))
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
    ) -> Result<Parts> {
        let parts = self.mesh_parts(label, file)?;
        let only_part = parts.len() == 1;
        let mut built = Parts::default();
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

    /// The mesh in the OBJ file `file`, all of it.
    fn mesh(&self, label: &str, file: &Spanned<String>) -> Result<Shape> {
        self.loader.mesh(file.get_ref()).map_err(|why| self.err(file.span(), format!("{label}: {why}")))
    }

    /// The mesh in the OBJ file `file`, one part per `.mtl` material.
    fn mesh_parts(&self, label: &str, file: &Spanned<String>) -> Result<Vec<MeshPart>> {
        self.loader.mesh_parts(file.get_ref()).map_err(|why| self.err(file.span(), format!("{label}: {why}")))
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

/// Names as a list for a message: `a`, `b`, `c`.
fn list(names: &[&str]) -> String {
    if names.is_empty() {
        return "(none)".into();
    }
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
