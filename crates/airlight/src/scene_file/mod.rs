//! Reading a scene file: the scene, and the integrator its `[render]` table
//! asks for. The scene format is described in docs/scene-format.md.

use crate::integrator::IntegratorDesc;
use crate::scene::assets::read_text;
use crate::scene::{self, AssetPath, Scene, SceneError};
use std::path::{Path, PathBuf};

/// A scene file, read and checked: the scene and the integrator it names,
/// with the options of every integrator its `[render]` table sets.
#[derive(Debug)]
pub struct SceneFile {
    pub scene: Scene,
    pub integrator: IntegratorDesc,
}

/// Largest scene file read.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

impl SceneFile {
    /// Reads the scene file at `path`; meshes are found in its folder (see
    /// [`AssetPath`]). Errors name the file, line and column.
    pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
        Self::load_with(path, &[])
    }

    /// [`SceneFile::load`], with meshes also looked for in `asset_dirs`,
    /// after the scene's folder ([`AssetPath::from_env`] reads them from
    /// `AIRLIGHT_ASSET_PATH`).
    /// A `.gltf` or `.glb` file is read as the scene of one `[[include]]`
    /// of it, with every other setting at its default.
    pub fn load_with(path: &Path, asset_dirs: &[PathBuf]) -> Result<SceneFile, SceneError> {
        let assets = AssetPath::new(path.parent(), asset_dirs);
        if let Some(gltf) = path.file_name().filter(|_| is_gltf(path)) {
            let text = format!("[[include]]\nfile = {}\n", toml::Value::from(gltf.to_string_lossy().into_owned()));
            // The error is the glTF file's, not of the text made here.
            return Self::from_toml_with(&text, &assets).map_err(|e| SceneError { location: None, ..e }.in_file(path));
        }
        let text = read_text(path, MAX_SCENE_BYTES, "scene file").map_err(|e| e.in_file(path))?;
        let mut file = Self::from_toml_with(&text, &assets).map_err(|e| e.in_file(path))?;
        let mut files = vec![path.canonicalize().unwrap_or_else(|_| path.to_path_buf())];
        files.append(&mut file.scene.files);
        file.scene.files = files;
        Ok(file)
    }

    /// Reads scene file text. `base_dir` is where mesh files are found
    /// (None: the current directory).
    pub fn from_toml_str(text: &str, base_dir: Option<&Path>) -> Result<SceneFile, SceneError> {
        Self::from_toml_with(text, &AssetPath::new(base_dir, &[]))
    }

    /// Reads scene file text, with mesh files found in `assets`.
    pub fn from_toml_with(text: &str, assets: &AssetPath) -> Result<SceneFile, SceneError> {
        let desc = scene::parse(text)?;
        let integrator = IntegratorDesc::from_render_desc(&desc.render, desc.medium.is_some())
            .map_err(|e| SceneError::at(text, e.span.start, e.message))?;
        let scene = scene::build(&desc, text, assets)?;
        Ok(SceneFile { scene, integrator })
    }
}

/// Whether `path` names a glTF file (`.gltf` or `.glb`, any case).
pub fn is_gltf(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// A fingerprint of a scene as resolved for a render (its file's values and
/// every command-line override) and of the integrator description: 16
/// hexadecimal digits of a 64-bit FNV-1a hash of their full debug
/// description (every shape, light, material, setting and option). Parts
/// of one render carry it so that `merge` refuses parts of another.
pub fn fingerprint(scene: &Scene, integrator: &IntegratorDesc) -> String {
    use std::fmt::Write;
    let mut hash = Fnv1a(0xcbf2_9ce4_8422_2325);
    // Writing into the hash cannot fail.
    let _ = write!(hash, "{scene:?}\n{integrator:?}");
    format!("{:016x}", hash.0)
}

/// FNV-1a, 64 bits (Fowler, Noll and Vo): a hash that is the same on every
/// machine and Rust version, fed by `write!`.
struct Fnv1a(u64);

impl std::fmt::Write for Fnv1a {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for &b in s.as_bytes() {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
