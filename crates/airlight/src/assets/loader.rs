//! [`Loader`]: the files one scene reads, found under its [`AssetPath`],
//! their memory counted together against the limit before each is
//! decoded, each image read once however many materials use it.

use super::AssetPath;
use crate::texture::Texture;
use std::cell::{Cell, RefCell};
use std::path::PathBuf;
use std::sync::Arc;

/// The files one scene reads, and what they cost so far.
pub struct Loader<'a> {
    folders: &'a AssetPath,
    /// The files read so far.
    files: RefCell<Vec<PathBuf>>,
    /// Memory the meshes and textures read so far will take.
    bytes: Cell<u64>,
    /// Image files read as textures, so that each is read once.
    pub(super) textures: RefCell<Vec<(PathBuf, Arc<Texture>)>>,
}

impl<'a> Loader<'a> {
    pub fn new(folders: &'a AssetPath) -> Self {
        Loader { folders, files: RefCell::default(), bytes: Cell::new(0), textures: RefCell::default() }
    }

    /// The file a scene's `name` stands for (see [`AssetPath::resolve`]).
    pub fn resolve(&self, name: &str) -> Result<PathBuf, String> {
        self.folders.resolve(name)
    }

    /// Notes that the scene was made from `path` (a viewer reloads the
    /// scene when one changes).
    pub fn record(&self, path: PathBuf) {
        self.files.borrow_mut().push(path);
    }

    /// Counts `more` bytes with those read so far against the memory limit
    /// (`what` names them in the message), before they are allocated.
    pub fn reserve(&self, more: u64, what: impl FnOnce() -> String) -> Result<(), String> {
        let needed = self.bytes.get().saturating_add(more);
        crate::memory::check(what(), needed).map_err(|e| e.to_string())?;
        self.bytes.set(needed);
        Ok(())
    }

    /// The files read, in the order read.
    pub fn into_files(self) -> Vec<PathBuf> {
        self.files.into_inner()
    }
}
