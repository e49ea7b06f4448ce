//! A mesh object's `file`: found under the scene's asset folders
//! ([`super::assets`]), its size and memory checked, read as OBJ
//! ([`super::obj`]), with its `.mtl` materials when the scene gives the
//! object none ([`super::mtl`]). Errors name the scene's line and the mesh
//! file's.

use super::assets::{MAX_MESH_BYTES, read_limited};
use super::build::{Checker, Result};
use super::mtl::{self, MtlMaterial};
use super::obj::{self, Obj};
use crate::geometry::Shape;
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;
use toml::Spanned;

/// Largest `.mtl` file read.
const MAX_MTL_BYTES: u64 = 64 << 20;

/// The triangles of an OBJ mesh that share one `.mtl` material (None: the
/// faces before any `usemtl`).
pub(super) struct MeshPart {
    pub shape: Shape,
    pub material: Option<MtlMaterial>,
}

impl Checker<'_> {
    /// The mesh, all of it, its materials unread.
    pub(super) fn mesh(&self, label: &str, file: &Spanned<String>) -> Result<Shape> {
        let obj = self.load_obj(label, file)?;
        Ok(Shape::Mesh { positions: obj.positions, triangles: obj.triangles })
    }

    /// The mesh cut into one part per `.mtl` material its faces use, the
    /// libraries (`mtllib`) found beside the OBJ file, under the same
    /// rules as the OBJ itself.
    pub(super) fn mesh_parts(&self, label: &str, file: &Spanned<String>) -> Result<Vec<MeshPart>> {
        let obj = self.load_obj(label, file)?;
        let path = Path::new(file.get_ref());
        let fail_at = |line: usize, why: String| {
            self.err(file.span(), format!("{label}: cannot load mesh {}:{line}: {why}", path.display()))
        };
        let mut library: Vec<MtlMaterial> = Vec::new();
        for (name, line) in &obj.libraries {
            let beside = path.parent().unwrap_or(Path::new("")).join(name);
            let mtl_path = self.assets.resolve(&beside.to_string_lossy()).map_err(|why| fail_at(*line, why))?;
            let bytes =
                read_limited(&mtl_path, MAX_MTL_BYTES).map_err(|why| fail_at(*line, format!("{name}: {why}")))?;
            let text = String::from_utf8_lossy(&bytes);
            let materials = mtl::parse(&text).map_err(|e| {
                self.err(
                    file.span(),
                    format!("{label}: cannot load material library {}:{}: {}", mtl_path.display(), e.line, e.message),
                )
            })?;
            self.files.borrow_mut().push(mtl_path);
            library.extend(materials);
        }
        // Triangles grouped by material, in order of first use.
        let mut groups: Vec<(Option<MtlMaterial>, Vec<[u32; 3]>)> = Vec::new();
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
            groups[index].1.extend_from_slice(&obj.triangles[*start..end]);
        }
        if let [(material, _)] = &mut groups[..] {
            // One material: the mesh as read.
            let shape = Shape::Mesh { positions: obj.positions, triangles: obj.triangles };
            return Ok(vec![MeshPart { shape, material: material.take() }]);
        }
        Ok(groups
            .into_iter()
            .map(|(material, triangles)| MeshPart { shape: compact(&obj.positions, triangles), material })
            .collect())
    }

    fn load_obj(&self, label: &str, file: &Spanned<String>) -> Result<Obj> {
        let name = file.get_ref();
        let path = self
            .assets
            .resolve(name)
            .map_err(|why| self.err(file.span(), format!("{label}: cannot load mesh: {why}")))?;
        let fail =
            |why: String| self.err(file.span(), format!("{label}: cannot load mesh `{}`: {why}", path.display()));
        let bytes = read_limited(&path, MAX_MESH_BYTES).map_err(fail)?;
        let (vertices, triangles) = obj::count(&bytes);
        // Meshes add up: the scene's total is what must fit.
        let bytes_needed =
            self.mesh_bytes.get() + vertices.saturating_mul(12) + triangles.saturating_mul(obj::BYTES_PER_TRIANGLE);
        crate::memory::check(format!("the scene's meshes ({triangles} triangles in this one)"), bytes_needed)
            .map_err(|e| fail(e.to_string()))?;
        self.mesh_bytes.set(bytes_needed);
        let mesh = obj::parse(&bytes, vertices, triangles).map_err(|e| match e.line {
            0 => fail(e.message),
            line => {
                self.err(file.span(), format!("{label}: cannot load mesh {}:{line}: {}", path.display(), e.message))
            }
        })?;
        self.files.borrow_mut().push(path);
        Ok(mesh)
    }
}

/// A mesh of `triangles` holding only the vertices they use.
fn compact(positions: &[Vec3], triangles: Vec<[u32; 3]>) -> Shape {
    let mut index: HashMap<u32, u32> = HashMap::new();
    let mut kept = Vec::new();
    let triangles = triangles
        .into_iter()
        .map(|t| {
            t.map(|i| {
                *index.entry(i).or_insert_with(|| {
                    kept.push(positions[i as usize]);
                    kept.len() as u32 - 1
                })
            })
        })
        .collect();
    Shape::Mesh { positions: kept, triangles }
}
