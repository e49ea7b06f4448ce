//! The files a scene names and their readers: OBJ meshes with their MTL
//! materials, glTF scenes, images, Mitsuba `.vol` density grids; and the
//! rules for where they may come from.
//!
//! A scene's files come from the scene file's folder, then the asset
//! folders the user names (`AIRLIGHT_ASSET_PATH` for the `airlight`
//! command), and nowhere else.
//!
//! A name must be a relative path without `..`; it is looked up in each
//! folder in turn, and the file found must lie inside that folder once
//! symbolic links are resolved, and be a regular file. Anything else gets
//! one message that depends only on the name and the folders, never on
//! what exists elsewhere on the machine: a scene author cannot probe the
//! rendering machine's files (`../../etc/passwd`, `/proc/self/environ`).

mod gltf;
mod images;
mod loader;
mod mesh;
pub mod mtl;
pub mod obj;
pub mod vol;

pub(crate) use gltf::{GltfInclude, Imported};
pub use loader::Loader;
pub(crate) use mesh::MeshPart;

use crate::scene::SceneError;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// The environment variable that lists asset folders (separated by `:`).
pub const ASSET_PATH_VAR: &str = "AIRLIGHT_ASSET_PATH";

/// Largest mesh file read.
pub const MAX_MESH_BYTES: u64 = 1 << 30;

/// Where the names of a scene's files are looked up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AssetPath {
    /// A scene file's names: inside these folders, in the order searched
    /// (see the module documentation).
    Folders(Vec<PathBuf>),
    /// A path typed on the command line (`--medium type="grid",file=…`):
    /// the user's own, so any regular file they can read, absolute or
    /// relative to the working directory. The limits above guard against
    /// scene authors, and the user who types the command is not one.
    CommandLine,
}

impl AssetPath {
    /// The scene's folder (None or empty: the current one), then `extra`.
    pub fn new(scene_dir: Option<&Path>, extra: &[PathBuf]) -> Self {
        let scene_dir = scene_dir.filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        AssetPath::Folders(std::iter::once(scene_dir.to_path_buf()).chain(extra.iter().cloned()).collect())
    }

    /// The folders listed in `AIRLIGHT_ASSET_PATH`, if set.
    pub fn from_env() -> Vec<PathBuf> {
        std::env::var_os(ASSET_PATH_VAR)
            .map(|v| std::env::split_paths(&v).filter(|p| !p.as_os_str().is_empty()).collect())
            .unwrap_or_default()
    }

    /// The folders searched (none for a command-line path).
    pub fn folders(&self) -> &[PathBuf] {
        match self {
            AssetPath::Folders(folders) => folders,
            AssetPath::CommandLine => &[],
        }
    }

    /// The file `name` stands for, with symbolic links resolved; or why
    /// not (see the module documentation).
    pub fn resolve(&self, name: &str) -> Result<PathBuf, String> {
        let folders = match self {
            AssetPath::Folders(folders) => folders,
            AssetPath::CommandLine => {
                return match Path::new(name).canonicalize() {
                    Ok(found) if found.is_file() => Ok(found),
                    Ok(_) => Err(format!("`{name}` is not a file")),
                    Err(e) => Err(format!("cannot open `{name}` (relative to the working directory): {e}")),
                };
            }
        };
        let relative = Path::new(name);
        let plain = !name.is_empty()
            && !name.contains('\0')
            && relative.components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
        if !plain {
            return Err(format!("`{name}` must be a relative path inside {}, without `..`", describe(folders)));
        }
        for folder in folders {
            let (Ok(root), Ok(found)) = (folder.canonicalize(), folder.join(relative).canonicalize()) else {
                continue;
            };
            if found.starts_with(&root) && found.metadata().is_ok_and(|m| m.is_file()) {
                return Ok(found);
            }
        }
        Err(format!("no file `{name}` in {} (more folders: {ASSET_PATH_VAR})", describe(folders)))
    }
}

/// "the scene's folder `d`" or "the scene's folder `d` or the asset folders
/// `a`, `b`", for `folders` as [`AssetPath::new`] makes them.
fn describe(folders: &[PathBuf]) -> String {
    let quoted = |p: &PathBuf| format!("`{}`", p.display());
    let Some((first, rest)) = folders.split_first() else {
        return "no folder".into();
    };
    let first = format!("the scene's folder {}", quoted(first));
    match rest {
        [] => first,
        rest => format!("{first} or the asset folders {}", rest.iter().map(quoted).collect::<Vec<_>>().join(", ")),
    }
}

/// The bytes of the file at `path`, refused beyond `limit` bytes (read at
/// most one past it, so `/dev/zero` or a pipe cannot run the reader out
/// of memory) and when it is a folder.
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    if file.metadata().is_ok_and(|m| m.is_dir()) {
        return Err("it is a folder".into());
    }
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(format!("it holds more than {} bytes, the most read", limit));
    }
    Ok(bytes)
}

/// [`read_limited`] as UTF-8 text; an error is placed at the first byte
/// that is not UTF-8 (the caller adds the file).
pub fn read_text(path: &Path, limit: u64, what: &str) -> Result<String, SceneError> {
    let bytes = read_limited(path, limit).map_err(|e| SceneError::new(format!("cannot read the {what}: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(&e.as_bytes()[..at]);
        SceneError::at(&text, at, "not UTF-8 text")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_files_inside_the_folders_are_found_and_the_message_does_not_tell_what_exists() {
        let root = tempfile::tempdir().unwrap();
        let scene_dir = root.path().join("scene");
        let assets = root.path().join("assets");
        std::fs::create_dir_all(scene_dir.join("meshes")).unwrap();
        std::fs::create_dir_all(&assets).unwrap();
        std::fs::write(scene_dir.join("meshes/a.obj"), "").unwrap();
        std::fs::write(assets.join("b.obj"), "").unwrap();
        std::fs::write(root.path().join("secret.obj"), "").unwrap();
        std::os::unix::fs::symlink(root.path().join("secret.obj"), scene_dir.join("out.obj")).unwrap();
        std::os::unix::fs::symlink(root.path().join("nothing.obj"), scene_dir.join("dangling.obj")).unwrap();
        let path = AssetPath::new(Some(&scene_dir), std::slice::from_ref(&assets));
        assert!(path.resolve("meshes/a.obj").unwrap().ends_with("scene/meshes/a.obj"));
        assert!(path.resolve("./b.obj").unwrap().ends_with("assets/b.obj"));
        // Outside, by name: refused before anything is opened.
        for name in ["../secret.obj", "../nothing.obj", "/etc/passwd", "/proc/self/environ", "", "a\0b"] {
            let e = path.resolve(name).unwrap_err();
            assert!(e.contains("must be a relative path inside the scene's folder"), "{name}: {e}");
        }
        // Outside through a link, whether its target exists or not, or not a
        // file: the same message as a file that is not there.
        let message = |name: &str| path.resolve(name).unwrap_err().replace(name, "NAME");
        let missing = message("missing.obj");
        assert!(missing.starts_with("no file `NAME` in the scene's folder"), "{missing}");
        assert_eq!(message("out.obj"), missing);
        assert_eq!(message("dangling.obj"), missing);
        assert_eq!(message("meshes"), missing);
    }

    #[test]
    fn a_command_line_path_may_be_absolute_or_relative_to_the_working_directory() {
        let root = tempfile::tempdir().unwrap();
        let file = root.path().join("cloud.vol");
        std::fs::write(&file, "").unwrap();
        let path = AssetPath::CommandLine;
        let name = file.to_str().unwrap();
        assert_eq!(path.resolve(name).unwrap(), file.canonicalize().unwrap());
        // Cargo runs a test in its package's folder.
        assert!(path.resolve("Cargo.toml").unwrap().ends_with("crates/airlight/Cargo.toml"));
        let e = path.resolve("missing.vol").unwrap_err();
        assert!(e.starts_with("cannot open `missing.vol` (relative to the working directory)"), "{e}");
        assert_eq!(
            path.resolve(root.path().to_str().unwrap()).unwrap_err(),
            format!("`{}` is not a file", root.path().display())
        );
    }

    #[test]
    fn reading_stops_past_the_limit() {
        let e = read_limited(Path::new("/dev/zero"), 1000).unwrap_err();
        assert_eq!(e, "it holds more than 1000 bytes, the most read");
        assert!(read_limited(Path::new("/"), 10).unwrap_err().contains("folder"));
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("t");
        std::fs::write(&f, b"ab\n\xffc").unwrap();
        assert_eq!(read_text(&f, 100, "file").unwrap_err().to_string(), "line 2, column 1: not UTF-8 text");
    }
}
