//! A mesh object's `file`: found under the scene's asset folders
//! ([`super::assets`]), its size and memory checked, read as OBJ
//! ([`super::obj`]). Errors name the scene's line and the mesh file's.

use super::assets::{MAX_MESH_BYTES, read_limited};
use super::build::{Checker, Result};
use super::obj;
use crate::geometry::Shape;
use toml::Spanned;

impl Checker<'_> {
    pub(super) fn mesh(&self, label: &str, file: &Spanned<String>) -> Result<Shape> {
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
        Ok(Shape::Mesh { positions: mesh.positions, triangles: mesh.triangles })
    }
}
