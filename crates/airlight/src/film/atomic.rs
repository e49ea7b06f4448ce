//! Writing a file whole or not at all (see [`super::write_atomically`]).
//!
//! The new file is created exclusively (`O_EXCL`, and `O_NOFOLLOW`), so a
//! symbolic link planted under its name is never followed: the open fails
//! and another name is drawn. Names carry a random part, so they cannot be
//! planted ahead. Data reach the disk (fsync) before the rename makes them
//! visible, and the folder is synced after it.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Seek, SeekFrom, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

pub fn write(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_with(path, |file| file.write_all(bytes))
}

/// As [`write`](fn@write), with the contents written by `fill` into the new file
/// (which it may seek in), so that they need not be held in memory whole.
pub fn write_with(path: &Path, fill: impl FnOnce(&mut File) -> io::Result<()>) -> io::Result<()> {
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, format!("`{}` names no file", path.display())))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // Linux: a file with no name until it is complete, then linked under a
    // temporary name (rename, unlike link, may replace `path`).
    let mut named = None;
    let mut fill = Some(fill);
    // Written but not linked: its contents are copied to a named file.
    let mut unlinked = None;
    if let Some(mut file) = anonymous(dir) {
        write_synced(&mut file, fill.take().expect("not yet used"))?;
        let tmp = temp_name(dir, name);
        if link(&file, &tmp).is_ok() {
            named = Some(tmp);
        } else {
            unlinked = Some(file);
        }
    }
    let tmp = match named {
        Some(tmp) => tmp,
        None => {
            let (tmp, mut file) = create_exclusive(dir, name)?;
            let written = match (fill, unlinked) {
                (Some(fill), _) => write_synced(&mut file, fill),
                (None, Some(mut unlinked)) => write_synced(&mut file, |file| copy_whole(&mut unlinked, file)),
                (None, None) => unreachable!("the contents are written to the anonymous file or still to write"),
            };
            if let Err(e) = written {
                let _ = fs::remove_file(&tmp);
                return Err(e);
            }
            tmp
        }
    };
    // Only a file this call created is ever removed.
    let result = rename(&tmp, path, dir);
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Copies all of `from`, from its start, to `to`.
fn copy_whole(from: &mut File, to: &mut File) -> io::Result<()> {
    from.seek(SeekFrom::Start(0))?;
    io::copy(from, to).map(drop)
}

fn write_synced(file: &mut File, fill: impl FnOnce(&mut File) -> io::Result<()>) -> io::Result<()> {
    fill(file)?;
    file.sync_all()
}

fn rename(tmp: &Path, path: &Path, dir: &Path) -> io::Result<()> {
    fs::rename(tmp, path)?;
    // The rename itself reaches the disk with the folder; a folder that
    // cannot be opened or synced (some file systems) is no failure.
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// `.NAME.tmp-PID-RANDOM` in `dir`.
fn temp_name(dir: &Path, name: &std::ffi::OsStr) -> PathBuf {
    use std::hash::{BuildHasher, Hasher};
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    // RandomState is seeded from the OS's random source.
    let mut h = std::hash::RandomState::new().build_hasher();
    h.write_u64(COUNTER.fetch_add(1, Ordering::Relaxed));
    h.write_u128(std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos()));
    let mut tmp = std::ffi::OsString::from(".");
    tmp.push(name);
    tmp.push(format!(".tmp-{}-{:016x}", std::process::id(), h.finish()));
    dir.join(tmp)
}

/// A new file under a fresh temporary name: never an existing file, never
/// through a link.
fn create_exclusive(dir: &Path, name: &std::ffi::OsStr) -> io::Result<(PathBuf, File)> {
    let mut last = None;
    for _ in 0..16 {
        let tmp = temp_name(dir, name);
        match OpenOptions::new()
            .write(true)
            .create_new(true)
            .custom_flags(libc::O_NOFOLLOW | libc::O_CLOEXEC)
            .mode(0o666)
            .open(&tmp)
        {
            Ok(file) => return Ok((tmp, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| io::Error::other("no free temporary name")))
}

/// An unnamed file in `dir` (Linux's `O_TMPFILE`); None where the system or
/// the file system has none.
#[cfg(target_os = "linux")]
fn anonymous(dir: &Path) -> Option<File> {
    OpenOptions::new().write(true).custom_flags(libc::O_TMPFILE | libc::O_CLOEXEC).mode(0o666).open(dir).ok()
}

#[cfg(not(target_os = "linux"))]
fn anonymous(_: &Path) -> Option<File> {
    None
}

/// Gives the unnamed `file` the name `to` (which must not exist: `linkat`
/// never replaces), through /proc/self/fd as unprivileged processes must.
#[cfg(target_os = "linux")]
fn link(file: &File, to: &Path) -> io::Result<()> {
    use std::ffi::CString;
    use std::os::fd::AsRawFd;
    use std::os::unix::ffi::OsStrExt;
    let from = CString::new(format!("/proc/self/fd/{}", file.as_raw_fd())).map_err(io::Error::other)?;
    let to = CString::new(to.as_os_str().as_bytes()).map_err(io::Error::other)?;
    // SAFETY: both are valid NUL-terminated strings that outlive the call.
    let r =
        unsafe { libc::linkat(libc::AT_FDCWD, from.as_ptr(), libc::AT_FDCWD, to.as_ptr(), libc::AT_SYMLINK_FOLLOW) };
    if r == 0 { Ok(()) } else { Err(io::Error::last_os_error()) }
}

#[cfg(not(target_os = "linux"))]
fn link(_: &File, _: &Path) -> io::Result<()> {
    Err(io::Error::new(io::ErrorKind::Unsupported, "no O_TMPFILE"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn a_link_in_place_of_the_output_is_replaced_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("precious");
        fs::write(&target, b"keep me").unwrap();
        let out = dir.path().join("out.bin");
        std::os::unix::fs::symlink(&target, &out).unwrap();
        write(&out, b"new").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"keep me");
        assert!(!fs::symlink_metadata(&out).unwrap().file_type().is_symlink());
        assert_eq!(fs::read(&out).unwrap(), b"new");
        assert_eq!(names(dir.path()), ["out.bin", "precious"]);
    }

    #[test]
    fn the_named_fallback_never_opens_a_planted_link() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("precious");
        fs::write(&target, b"keep me").unwrap();
        // The old name was predictable; a link planted there is ignored now.
        let planted = dir.path().join(format!(".out.bin.tmp-{}", std::process::id()));
        std::os::unix::fs::symlink(&target, &planted).unwrap();
        let (tmp, file) = create_exclusive(dir.path(), "out.bin".as_ref()).unwrap();
        drop(file);
        assert_ne!(tmp, planted);
        assert!(tmp.file_name().unwrap().to_string_lossy().starts_with(".out.bin.tmp-"));
        fs::remove_file(&tmp).unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"keep me");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn on_linux_the_file_has_no_name_until_it_is_complete() {
        let dir = tempfile::tempdir().unwrap();
        let Some(mut file) = anonymous(dir.path()) else {
            eprintln!("this file system has no O_TMPFILE: the named fallback is used");
            return;
        };
        write_synced(&mut file, |f| f.write_all(b"whole")).unwrap();
        assert!(names(dir.path()).is_empty(), "nothing to see, or to leave behind, while writing");
        link(&file, &dir.path().join("done")).unwrap();
        assert_eq!(fs::read(dir.path().join("done")).unwrap(), b"whole");
    }

    #[test]
    fn contents_may_be_written_with_seeks() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.bin");
        // As an EXR writer does: a placeholder, the data, then the
        // placeholder filled in.
        write_with(&out, |f| {
            f.write_all(b"????-data")?;
            f.seek(SeekFrom::Start(0))?;
            f.write_all(b"head")
        })
        .unwrap();
        assert_eq!(fs::read(&out).unwrap(), b"head-data");
        assert_eq!(names(dir.path()), ["out.bin"]);
    }

    #[test]
    fn a_file_written_without_a_name_is_copied_whole() {
        let dir = tempfile::tempdir().unwrap();
        let mut from = tempfile::tempfile().unwrap();
        from.write_all(b"all of it").unwrap();
        let (tmp, mut to) = create_exclusive(dir.path(), "out.bin".as_ref()).unwrap();
        copy_whole(&mut from, &mut to).unwrap();
        assert_eq!(fs::read(&tmp).unwrap(), b"all of it");
    }

    #[test]
    fn a_failed_fill_leaves_nothing_and_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.bin");
        fs::write(&out, b"old").unwrap();
        let e = write_with(&out, |f| {
            f.write_all(b"half")?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), "disk full");
        assert_eq!(fs::read(&out).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["out.bin"]);
    }

    #[test]
    fn failures_leave_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        // The target is a folder: the rename fails after the data are written.
        fs::create_dir(dir.path().join("a.exr")).unwrap();
        assert!(write(&dir.path().join("a.exr"), b"x").is_err());
        assert!(write(&dir.path().join("missing").join("a.exr"), b"x").is_err());
        assert!(write(Path::new("/"), b"x").is_err());
        assert_eq!(names(dir.path()), ["a.exr"]);
    }
}
