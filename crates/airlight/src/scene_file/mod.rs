//! Reading a scene file: the scene, and the integrator its `[render]` table
//! asks for. The scene format is described in docs/scene-format.md.

use crate::integrator::IntegratorDesc;
use crate::scene::{self, Scene, SceneError};
use std::path::Path;

/// A scene file, read and checked: the scene and the integrator it names,
/// with the options of every integrator its `[render]` table sets.
#[derive(Debug)]
pub struct SceneFile {
    pub scene: Scene,
    pub integrator: IntegratorDesc,
}

impl SceneFile {
    /// Reads the scene file at `path`; meshes are found relative to it.
    /// Errors name the file, line and column.
    pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::new(format!("cannot read the scene file: {e}")).in_file(path))?;
        Self::from_toml_str(&text, path.parent()).map_err(|e| e.in_file(path))
    }

    /// Reads scene file text. `base_dir` is where relative mesh paths start
    /// (None: the current directory).
    pub fn from_toml_str(text: &str, base_dir: Option<&Path>) -> Result<SceneFile, SceneError> {
        let desc = scene::parse(text)?;
        let integrator = IntegratorDesc::from_render_desc(&desc.render, desc.medium.is_some())
            .map_err(|e| SceneError::at(text, e.span.start, e.message))?;
        let scene = scene::build(&desc, text, base_dir)?;
        Ok(SceneFile { scene, integrator })
    }
}

#[cfg(test)]
mod tests;
