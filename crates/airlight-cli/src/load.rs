//! Where a command's scene comes from: a scene file (TOML or glTF), or the
//! built-in demo scene.

use airlight::SceneFile;
use std::path::Path;

/// The built-in demo scene: spheres on a checker floor under a spot light in fog.
const DEMO_SCENE: &str = include_str!("../../../scenes/demo.toml");

/// The scene file at `path`, or the built-in demo scene.
pub fn load(path: Option<&Path>) -> Result<SceneFile, String> {
    match path {
        Some(path) => SceneFile::load_with(path, &airlight::assets::AssetPath::from_env()).map_err(|e| e.to_string()),
        None => SceneFile::from_toml_str(DEMO_SCENE, None).map_err(|e| format!("built-in demo scene: {e}")),
    }
}
