//! A mesh object's `file`: found under the scene's asset folders, its size
//! and memory checked, read as OBJ ([`super::obj`]), with its `.mtl`
//! materials when the scene gives the object none ([`super::mtl`]).
//! Errors name the mesh file's line; the caller adds the scene's.

use super::mtl::{self, MtlMaterial};
use super::obj::{self, Obj};
use super::{Loader, MAX_MESH_BYTES, read_limited};
use crate::geometry::Shape;
use crate::texture::Texture;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Largest `.mtl` file read.
const MAX_MTL_BYTES: u64 = 64 << 20;

/// The triangles of an OBJ mesh that share one `.mtl` material (None: the
/// faces before any `usemtl`).
pub(crate) struct MeshPart {
    pub shape: Shape,
    pub material: Option<MtlMaterial>,
    /// Its material's `map_Kd`, read.
    pub texture: Option<Arc<Texture>>,
}

impl Loader<'_> {
    /// The mesh, all of it, with its texture coordinates if every face
    /// has them; its materials unread.
    pub(crate) fn mesh(&self, name: &str) -> Result<Shape, String> {
        let obj = self.load_obj(name)?;
        if obj.triangle_texcoords.is_empty() {
            return Ok(Shape::Mesh {
                positions: obj.positions,
                triangles: obj.triangles,
                uvs: Vec::new(),
                normals: Vec::new(),
            });
        }
        Ok(compact(&obj, 0..obj.triangles.len(), true))
    }

    /// The mesh cut into one part per `.mtl` material its faces use, the
    /// libraries (`mtllib`) found beside the OBJ file, under the same
    /// rules as the OBJ itself.
    pub(crate) fn mesh_parts(&self, name: &str) -> Result<Vec<MeshPart>, String> {
        let obj = self.load_obj(name)?;
        let path = Path::new(name);
        let fail_at = |line: usize, why: String| format!("cannot load mesh {}:{line}: {why}", path.display());
        let mut library: Vec<MtlMaterial> = Vec::new();
        let mut library_of: HashMap<String, std::path::PathBuf> = HashMap::new();
        for (name, line) in &obj.libraries {
            let beside = path.parent().unwrap_or(Path::new("")).join(name);
            let mtl_path = self.resolve(&beside.to_string_lossy()).map_err(|why| fail_at(*line, why))?;
            let bytes =
                read_limited(&mtl_path, MAX_MTL_BYTES).map_err(|why| fail_at(*line, format!("{name}: {why}")))?;
            let text = String::from_utf8_lossy(&bytes);
            let mut materials = mtl::parse(&text).map_err(|e| {
                format!("cannot load material library {}:{}: {}", mtl_path.display(), e.line, e.message)
            })?;
            self.record(mtl_path.clone());
            // Texture maps are named relative to their library.
            for m in &mut materials {
                if let Some((map, _)) = &mut m.diffuse_map {
                    *map = beside.parent().unwrap_or(Path::new("")).join(&*map).to_string_lossy().into_owned();
                }
            }
            library_of.extend(materials.iter().map(|m| (m.name.clone(), mtl_path.clone())));
            library.extend(materials);
        }
        // Triangles grouped by material, in order of first use.
        let mut groups: Vec<(Option<MtlMaterial>, Vec<usize>)> = Vec::new();
        let mut group_of: HashMap<Option<String>, usize> = HashMap::new();
        let runs = &obj.material_runs;
        for (i, (start, used)) in runs.iter().enumerate() {
            let end = runs.get(i + 1).map_or(obj.triangles.len(), |next| next.0);
            let material = match used {
                None => None,
                Some((name, line)) => Some(library.iter().find(|m| &m.name == name).cloned().ok_or_else(|| {
                    let known: Vec<String> = library.iter().map(|m| format!("`{}`", m.name)).collect();
                    let known = if known.is_empty() { "none".to_string() } else { known.join(", ") };
                    fail_at(*line, format!("usemtl `{name}`: no such material in its libraries (they define {known})"))
                })?),
            };
            let key = material.as_ref().map(|m| m.name.clone());
            let index = *group_of.entry(key).or_insert_with(|| {
                groups.push((material, Vec::new()));
                groups.len() - 1
            });
            groups[index].1.extend(*start..end);
        }
        // Texture coordinates only where a texture will use them.
        let textured = |m: &Option<MtlMaterial>| {
            !obj.triangle_texcoords.is_empty() && m.as_ref().is_some_and(|m| m.diffuse_map.is_some())
        };
        let texture_of = |m: &Option<MtlMaterial>| -> Result<Option<Arc<Texture>>, String> {
            let Some((m, (map, line))) = m.as_ref().and_then(|m| Some(m).zip(m.diffuse_map.as_ref())) else {
                return Ok(None);
            };
            self.texture_file(map).map(Some).map_err(|why| {
                let mtl = library_of.get(&m.name).map_or(String::new(), |p| p.display().to_string());
                format!("cannot load material library {mtl}:{line}: map_Kd: {why}")
            })
        };
        if let [(material, _)] = &mut groups[..]
            && !textured(material)
        {
            // One material: the mesh as read.
            let texture = texture_of(material)?;
            let shape = Shape::Mesh {
                positions: obj.positions,
                triangles: obj.triangles,
                uvs: Vec::new(),
                normals: Vec::new(),
            };
            return Ok(vec![MeshPart { shape, material: material.take(), texture }]);
        }
        let mut parts = Vec::new();
        for (material, triangles) in groups {
            let shape = compact(&obj, triangles.into_iter(), textured(&material));
            parts.push(MeshPart { shape, texture: texture_of(&material)?, material });
        }
        Ok(parts)
    }

    fn load_obj(&self, name: &str) -> Result<Obj, String> {
        let path = self.resolve(name).map_err(|why| format!("cannot load mesh: {why}"))?;
        let fail = |why: String| format!("cannot load mesh `{}`: {why}", path.display());
        let bytes = read_limited(&path, MAX_MESH_BYTES).map_err(fail)?;
        let (vertices, triangles) = obj::count(&bytes);
        // Meshes add up: the scene's total is what must fit.
        let needed = vertices.saturating_mul(12).saturating_add(triangles.saturating_mul(obj::BYTES_PER_TRIANGLE));
        self.reserve(needed, || format!("the scene's meshes ({triangles} triangles in this one)")).map_err(fail)?;
        let mesh = obj::parse(&bytes, vertices, triangles).map_err(|e| match e.line {
            0 => fail(e.message),
            line => format!("cannot load mesh {}:{line}: {}", path.display(), e.message),
        })?;
        self.record(path);
        Ok(mesh)
    }
}

/// A mesh of the OBJ's triangles numbered `triangles`, holding only the
/// vertices they use; with texture coordinates, a vertex for each pair of
/// position and `vt` (OBJ indexes them apart, Airlight's meshes together).
fn compact(obj: &Obj, triangles: impl Iterator<Item = usize>, with_texcoords: bool) -> Shape {
    let mut index: HashMap<(u32, u32), u32> = HashMap::new();
    let (mut positions, mut uvs) = (Vec::new(), Vec::new());
    let triangles = triangles
        .map(|t| {
            let corners = obj.triangles[t];
            std::array::from_fn(|k| {
                let vt = if with_texcoords { obj.triangle_texcoords[t][k] } else { u32::MAX };
                *index.entry((corners[k], vt)).or_insert_with(|| {
                    positions.push(obj.positions[corners[k] as usize]);
                    if with_texcoords {
                        uvs.push(obj.texcoords[vt as usize]);
                    }
                    positions.len() as u32 - 1
                })
            })
        })
        .collect();
    Shape::Mesh { positions, triangles, uvs, normals: Vec::new() }
}
