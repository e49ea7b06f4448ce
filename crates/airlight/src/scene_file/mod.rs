//! Reading a scene file: the scene, and the integrator its `[render]` table
//! asks for. The scene format is described in docs/scene-format.md.

mod camera;
mod check;
pub mod desc;
mod lights;
mod materials;
mod medium;
mod objects;
mod sdf;
mod tables;

pub(crate) use check::{build, parse};
pub use desc::SceneDesc;
pub use medium::medium_from_options;

use crate::assets::{AssetPath, read_text};
use crate::integrator::{INTEGRATOR_OPTIONS, IntegratorDesc, IntegratorKind};
use crate::scene::{RENDER_SETTINGS, Scene, SceneError};
use desc::RenderDesc;
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
            let model = || -> Result<SceneFile, SceneError> {
                let desc = parse(&text)?;
                let scene = check::build_as(&desc, &text, &assets, true)?;
                Ok(SceneFile { scene, integrator: integrator_options(&desc.render, false, &text)? })
            };
            return model().map_err(|e| SceneError { location: None, ..e }.in_file(path));
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
        let desc = parse(text)?;
        check_render_keys(&desc.render, text)?;
        let integrator = integrator_options(&desc.render, desc.medium.is_some(), text)?;
        let scene = build(&desc, text, assets)?;
        Ok(SceneFile { scene, integrator })
    }
}

/// Every key of `[render]` is a film setting or an integrator option;
/// any other is an error at the key, with the nearest known key if one
/// is a slip of the pen away.
fn check_render_keys(render: &RenderDesc, text: &str) -> Result<(), SceneError> {
    let known: Vec<&str> = SceneFile::render_keys().collect();
    for key in render.0.keys() {
        let name = key.get_ref().as_str();
        if known.contains(&name) {
            continue;
        }
        let hint = crate::options::nearest(name, &known).map(|k| format!("did you mean `{k}`? ")).unwrap_or_default();
        return Err(SceneError::at(
            text,
            key.span().start,
            format!("unknown field `{name}` in [render]; {hint}the keys of [render] are {}", known.join(", ")),
        ));
    }
    Ok(())
}

impl SceneFile {
    /// Every tag, type name and key of the typed tables (`[camera]`,
    /// `[medium]`, `[materials.NAME]`, `[[objects]]` with their SDF nodes,
    /// `[[lights]]`), each once, as their structs declare them.
    pub fn table_words() -> Vec<&'static str> {
        let mut words = Vec::new();
        tables::words::<desc::CameraDesc>(&mut words);
        tables::words::<desc::MediumDesc>(&mut words);
        tables::words::<desc::MaterialDesc>(&mut words);
        tables::words::<desc::ObjectDesc>(&mut words);
        tables::words::<desc::SdfNodeDesc>(&mut words);
        tables::words::<desc::LightDesc>(&mut words);
        words
    }

    /// The keys `[render]` takes: the film settings, then the integrators'
    /// options.
    pub fn render_keys() -> impl Iterator<Item = &'static str> {
        RENDER_SETTINGS.iter().map(|o| o.key).chain(INTEGRATOR_OPTIONS.iter().map(|o| o.spec.key))
    }
}

/// The integrator and options `[render]` names. Without an `integrator`
/// key: `raymarch` when the scene has a medium (show the fog), else
/// `direct`. Errors point at the value.
fn integrator_options(render: &RenderDesc, has_medium: bool, text: &str) -> Result<IntegratorDesc, SceneError> {
    let default_kind = if has_medium { IntegratorKind::Raymarch } else { IntegratorKind::Direct };
    let mut desc = IntegratorDesc::new(default_kind);
    for option in INTEGRATOR_OPTIONS {
        if let Some(v) = render.get(option.spec.key) {
            option
                .spec
                .apply(&mut desc, v.get_ref())
                .map_err(|e| SceneError::at(text, v.span().start, format!("render.{e}")))?;
        }
    }
    Ok(desc)
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
