//! Where a command will write, checked before it does any work: every
//! output's folder exists and is writable, no output is a folder, no two
//! outputs are the same file, and no output would replace one of the
//! command's inputs (the scene file, a mesh, an image being compared).
//! Paths are compared after resolving their folders' symbolic links, so
//! `-o ./a.png -o sub/../a.png` are the same file.

use std::path::{Path, PathBuf};

/// One file a command will write: the option that names it (`-o`,
/// `--variance`, …) and its path.
pub struct Output<'a> {
    pub option: &'static str,
    pub path: &'a Path,
}

/// The file `path` names: its folder resolved, its own name kept (a link
/// there is replaced by the output, never followed).
fn identity(path: &Path) -> Result<PathBuf, String> {
    let name = path.file_name().ok_or_else(|| format!("`{}` names no file", path.display()))?;
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let resolved = folder.canonicalize().map_err(|e| format!("the folder `{}`: {e}", folder.display()))?;
    if !resolved.is_dir() {
        return Err(format!("`{}` is not a folder", folder.display()));
    }
    Ok(resolved.join(name))
}

/// Whether `a` and `b` name the same file, their folders resolved.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (identity(a), identity(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// Whether this process may create files in `folder`.
fn writable(folder: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(c) = std::ffi::CString::new(folder.as_os_str().as_bytes()) else {
        return false;
    };
    // SAFETY: `c` is a valid NUL-terminated string that outlives the call.
    unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) == 0 }
}

/// Checks `outputs` against each other and against `inputs` (see the
/// module documentation). Inputs are compared both as given and resolved.
pub fn check(outputs: &[Output], inputs: &[&Path]) -> Result<(), String> {
    let mut input_ids = Vec::new();
    for input in inputs {
        input_ids.extend(identity(input).ok());
        input_ids.extend(input.canonicalize().ok());
    }
    let mut seen: Vec<(PathBuf, &Output)> = Vec::new();
    for out in outputs {
        let shown = out.path.display();
        let id = identity(out.path).map_err(|e| format!("cannot write {} `{shown}`: {e}", out.option))?;
        let folder = id.parent().unwrap_or(Path::new("/"));
        if !writable(folder) {
            return Err(format!(
                "cannot write {} `{shown}`: the folder `{}` is not writable",
                out.option,
                folder.display()
            ));
        }
        if id.is_dir() {
            return Err(format!("cannot write {} `{shown}`: it is a folder", out.option));
        }
        if input_ids.contains(&id) {
            return Err(format!(
                "{} `{shown}` would replace an input of this command: choose another name",
                out.option
            ));
        }
        if let Some((_, first)) = seen.iter().find(|(other, _)| *other == id) {
            return Err(format!(
                "{} `{}` and {} `{shown}` are the same file: each output needs its own",
                first.option,
                first.path.display(),
                out.option
            ));
        }
        seen.push((id, out));
    }
    Ok(())
}

/// The checks of `airlight render`: its images (`-o`) and variance
/// against each other, the scene file as named and every file the scene
/// was read from. With `frames`, the outputs are numbered (`NAME_0007.png`):
/// an input that one of those names would be is refused too.
pub fn check_render(
    scene: Option<&Path>,
    files: &[PathBuf],
    images: &[PathBuf],
    variance: Option<&Path>,
    frames: Option<u32>,
) -> Result<(), String> {
    let inputs: Vec<&Path> = scene.into_iter().chain(files.iter().map(PathBuf::as_path)).collect();
    let given = images.iter().map(|p| ("-o", p.as_path())).chain(variance.map(|p| ("--variance", p)));
    let mut numbered = Vec::new();
    let mut outputs = Vec::new();
    for (option, path) in given {
        outputs.push(Output { option, path });
        if let Some(n) = frames {
            numbered.extend(inputs.iter().filter_map(|input| frame_name(path, input, n)).map(|p| (option, p)));
        }
    }
    outputs.extend(numbered.iter().map(|(option, path)| Output { option, path }));
    check(&outputs, &inputs)
}

/// `base` numbered for the frame that `input`'s name gives, when that frame
/// is one of `frames` (so the numbered output and `input` share a name).
fn frame_name(base: &Path, input: &Path, frames: u32) -> Option<PathBuf> {
    let stem = base.file_stem()?.to_str()?;
    let name = input.file_name()?.to_str()?;
    let rest = name.strip_prefix(stem)?.strip_prefix('_')?;
    let digits = match base.extension() {
        Some(ext) => rest.strip_suffix(ext.to_str()?)?.strip_suffix('.')?,
        None => rest,
    };
    let frame: u32 = digits.parse().ok().filter(|&k| k < frames && format!("{k:04}") == digits)?;
    let numbered = match base.extension() {
        Some(ext) => format!("{stem}_{frame:04}.{}", ext.to_str()?),
        None => format!("{stem}_{frame:04}"),
    };
    Some(base.with_file_name(numbered))
}

/// Checks a folder a command will create files in (creating it, as the
/// command would, when missing).
pub fn check_folder(option: &str, folder: &Path) -> Result<(), String> {
    std::fs::create_dir_all(folder).map_err(|e| format!("cannot create {option} `{}`: {e}", folder.display()))?;
    if !writable(folder) {
        return Err(format!("{option} `{}` is not writable", folder.display()));
    }
    Ok(())
}

/// Checks a folder a command will write the files `names` into (frames):
/// the folder as [`check_folder`] checks it, and no file it writes may
/// replace one of the command's `inputs` (a scene or texture named
/// `frame_0000.png` there).
pub fn check_in_folder(
    option: &str,
    folder: &Path,
    names: impl Iterator<Item = String>,
    inputs: &[&Path],
) -> Result<(), String> {
    check_folder(option, folder)?;
    let resolved = folder.canonicalize().map_err(|e| format!("{option} `{}`: {e}", folder.display()))?;
    let mut input_ids = std::collections::HashSet::new();
    for input in inputs {
        input_ids.extend(identity(input).ok());
        input_ids.extend(input.canonicalize().ok());
    }
    for name in names {
        if input_ids.contains(&resolved.join(&name)) {
            return Err(format!(
                "{option} `{}`: its `{name}` would replace an input of this command: choose another folder",
                folder.display()
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn out<'a>(option: &'static str, path: &'a Path) -> Output<'a> {
        Output { option, path }
    }

    #[test]
    fn outputs_may_not_meet_inputs_each_other_or_missing_folders() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("scene.exr"), "").unwrap();
        std::fs::create_dir(d.join("sub")).unwrap();
        let scene = d.join("scene.exr");
        let (a, also_a) = (d.join("a.png"), d.join("sub/../a.png"));
        assert_eq!(check(&[out("-o", &a), out("--variance", &d.join("v.exr"))], &[&scene]), Ok(()));
        let e = check(&[out("-o", &scene)], &[&scene]).unwrap_err();
        assert!(e.contains("would replace an input"), "{e}");
        let e = check(&[out("-o", &a), out("--variance", &also_a)], &[]).unwrap_err();
        assert!(e.contains("are the same file"), "{e}");
        let e = check(&[out("-o", &d.join("missing/a.png"))], &[]).unwrap_err();
        assert!(e.contains("missing"), "{e}");
        let e = check(&[out("-o", &d.join("sub"))], &[]).unwrap_err();
        assert!(e.contains("it is a folder"), "{e}");
        // Frame 7 of `-o scene.exr --frames 8` would be scene_0007.exr.
        std::fs::write(d.join("scene_0007.exr"), "").unwrap();
        let numbered = d.join("scene_0007.exr");
        let base = [d.join("scene.exr")];
        assert!(check_render(None, std::slice::from_ref(&numbered), &base, None, Some(8)).is_err());
        assert!(check_render(None, std::slice::from_ref(&numbered), &base, None, Some(7)).is_ok());
        assert!(check_render(None, std::slice::from_ref(&numbered), &base, None, None).is_ok());
    }
}
