//! The `airlight` Python module: scenes from files, text or dicts, rendered
//! into NumPy arrays, and the CLI's image comparison. Built with maturin
//! (pyproject.toml); the API is documented in docs/python.md and airlight.pyi.

mod dict;
mod errors;
mod options;
mod render;
mod scene;
mod shared;

use airlight::assets::AssetPath;
use errors::{Origin, guard};
use numpy::{AllowTypeChange, PyArray3, PyArrayLikeDyn};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use scene::{PyScene, Source};
use std::path::PathBuf;

/// Reads a scene file (or a `.gltf`/`.glb` file, as the scene of one
/// `[[include]]` of it) as `airlight render` does; errors are `SceneError`s
/// with the CLI's message (`file:line:col: message`). Meshes are found in
/// the file's folder, then in those of `AIRLIGHT_ASSET_PATH`.
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
    guard(|| {
        let extra = AssetPath::from_env();
        let file = py
            .detach(|| airlight::SceneFile::load_with(&path, &extra))
            .map_err(|e| errors::scene_error(py, &e, &Origin::File, ""))?;
        scene::warn_notes(py, &file.scene)?;
        // Kept for `Scene.toml` and `with_lights`: the file, which the
        // library has just read within its size limit, or for a glTF file
        // the scene file the library reads it as.
        let text = match path.file_name().filter(|_| is_gltf(&path)) {
            Some(name) => format!("[[include]]\nfile = {}\n", toml::Value::from(name.to_string_lossy().into_owned())),
            None => std::fs::read_to_string(&path)
                .map_err(|e| PyOSError::new_err(format!("cannot read `{}`: {e}", path.display())))?,
        };
        let assets = AssetPath::new(path.parent(), &extra);
        Ok(scene::new_scene(file, Source { text, assets, origin: Origin::File, file: Some(path) }))
    })
}

/// Reads a scene from TOML text; errors say `line L, column C: message`.
/// Meshes are found in `base_dir` (default: the current folder), then in
/// the folders of `AIRLIGHT_ASSET_PATH`.
#[pyfunction]
#[pyo3(signature = (text, base_dir=None))]
fn loads(py: Python<'_>, text: String, base_dir: Option<PathBuf>) -> PyResult<PyScene> {
    guard(|| scene::read(py, Source::text(text, base_dir.as_deref(), Origin::Text)))
}

/// A scene from dicts with the scene file's keys; the same as `Scene(d)`.
#[pyfunction]
#[pyo3(signature = (scene, base_dir=None))]
fn from_dict(py: Python<'_>, scene: &Bound<'_, PyAny>, base_dir: Option<PathBuf>) -> PyResult<PyScene> {
    guard(|| scene::from_dict(py, scene, base_dir))
}

/// The figures `airlight compare A.exr B.exr` prints, `image` against
/// `reference`, over all pixels and channels.
#[pyclass(module = "airlight", frozen, get_all)]
struct Comparison {
    /// √(mean (a − b)²)
    rmse: f64,
    /// mean (a − b)² / (b² + 0.01)
    rel_mse: f64,
    /// mean |a − b|
    mae: f64,
    /// max |a − b|
    max: f64,
    /// √(Σ(a − b)² / Σb²)
    rel_rmse: f64,
    /// The mean colour of `image`.
    mean_a: (f32, f32, f32),
    /// The mean colour of `reference`.
    mean_b: (f32, f32, f32),
}

#[pymethods]
impl Comparison {
    /// The figures as a dict.
    fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let d = pyo3::types::PyDict::new(py);
        d.set_item("rmse", self.rmse)?;
        d.set_item("rel_mse", self.rel_mse)?;
        d.set_item("mae", self.mae)?;
        d.set_item("max", self.max)?;
        d.set_item("rel_rmse", self.rel_rmse)?;
        d.set_item("mean_a", self.mean_a)?;
        d.set_item("mean_b", self.mean_b)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Comparison(rmse={}, rel_mse={}, mae={}, max={}, rel_rmse={})",
            self.rmse, self.rel_mse, self.mae, self.max, self.rel_rmse
        )
    }
}

/// An (H, W, 3) array as the library's image (a copy, as f32).
fn image(a: &PyArrayLikeDyn<'_, f32, AllowTypeChange>, what: &str) -> PyResult<airlight::Image> {
    let view = a.as_array();
    let shape = view.shape();
    if shape.len() != 3 || shape[2] != 3 {
        return Err(PyValueError::new_err(format!(
            "{what} must be an array of shape (height, width, 3), got shape {shape:?}"
        )));
    }
    let (h, w) = (shape[0], shape[1]);
    // Checked before the array is copied into a standard layout: a
    // zero-stride array claims any size in a few bytes.
    let side = airlight::film::MAX_IMAGE_SIDE as usize;
    if w > side || h > side || (w as u64) * (h as u64) > airlight::film::MAX_PIXELS {
        return Err(PyValueError::new_err(format!(
            "{what} is {w}×{h} pixels; an image has at most {side} on a side and {} in all",
            airlight::film::MAX_PIXELS
        )));
    }
    let bytes = (w * h) as u64 * (3 * 4 + size_of::<airlight::Rgb>() as u64);
    airlight::memory::check(format!("{what} ({w}×{h} pixels)"), bytes)
        .map_err(|e| pyo3::exceptions::PyMemoryError::new_err(e.to_string()))?;
    let pixels = view
        .as_standard_layout()
        .as_slice()
        .map(|s| s.chunks_exact(3).map(|c| airlight::Rgb::new(c[0], c[1], c[2])).collect())
        .unwrap_or_default();
    Ok(airlight::Image { width: w as u32, height: h as u32, pixels })
}

/// Whether the library reads `path` as a glTF file, not a scene file.
fn is_gltf(path: &std::path::Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// Refuses an image with pixels that are not finite numbers, as `airlight
/// compare` does: the measures over them would be NaN or infinite.
fn finite(image: &airlight::Image, what: &str) -> PyResult<()> {
    let mut broken = image.pixels.iter().enumerate().filter(|(_, p)| !p.is_finite());
    let Some((first, p)) = broken.next() else {
        return Ok(());
    };
    let count = 1 + broken.count();
    let w = image.width.max(1) as usize;
    Err(PyValueError::new_err(format!(
        "{what} has {count} pixel{} that {} not finite numbers (NaN or infinite), the first at (x {}, y {}): {} {} {}; \
         the measures would be meaningless",
        if count == 1 { "" } else { "s" },
        if count == 1 { "is" } else { "are" },
        first % w,
        first / w,
        p.x,
        p.y,
        p.z
    )))
}

/// Compares `image` against `reference` (arrays of shape (H, W, 3)) with
/// the figures `airlight compare` prints.
#[pyfunction]
fn compare(
    image: PyArrayLikeDyn<'_, f32, AllowTypeChange>,
    reference: PyArrayLikeDyn<'_, f32, AllowTypeChange>,
) -> PyResult<Comparison> {
    guard(|| {
        let (a, b) = (self::image(&image, "image")?, self::image(&reference, "reference")?);
        finite(&a, "image")?;
        finite(&b, "reference")?;
        let e = airlight::film::compare(&a, &b).ok_or_else(|| {
            PyValueError::new_err(format!(
                "the images differ in size: {}×{} and {}×{}",
                a.width, a.height, b.width, b.height
            ))
        })?;
        let (ma, mb) = (a.mean(), b.mean());
        Ok(Comparison {
            rmse: e.rmse,
            rel_mse: e.rel_mse,
            mae: e.mae,
            max: e.max,
            rel_rmse: e.rel_rmse,
            mean_a: (ma.x, ma.y, ma.z),
            mean_b: (mb.x, mb.y, mb.z),
        })
    })
}

/// Reads an EXR's RGB channels as a float32 array (H, W, 3).
#[pyfunction]
fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArray3<f32>>> {
    guard(|| {
        let img = py
            .detach(|| airlight::Image::read_exr(&path))
            .map_err(|e| PyOSError::new_err(format!("cannot read `{}`: {e}", path.display())))?;
        let flat: Vec<f32> = img.pixels.iter().flat_map(|p| p.to_array()).collect();
        let a = numpy::ndarray::Array3::from_shape_vec((img.height as usize, img.width as usize, 3), flat)
            .map_err(|e| errors::internal_error(&format!("image buffer: {e}")))?;
        Ok(PyArray3::from_owned_array(py, a))
    })
}

/// Writes an (H, W, 3) array as `.exr` (linear float) or `.png` (8-bit sRGB
/// after `exposure` stops and the tone curve, `clamp` or `filmic`), as
/// `airlight render -o` does.
#[pyfunction]
#[pyo3(signature = (path, image, exposure=0.0, tonemap="clamp"))]
fn save(
    py: Python<'_>,
    path: PathBuf,
    image: PyArrayLikeDyn<'_, f32, AllowTypeChange>,
    exposure: f32,
    tonemap: &str,
) -> PyResult<()> {
    guard(|| {
        let tonemap: airlight::film::Tonemap = tonemap.parse().map_err(PyValueError::new_err)?;
        let img = self::image(&image, "image")?;
        py.detach(|| img.save_with(&path, exposure, tonemap))
            .map_err(|e| PyOSError::new_err(format!("cannot write `{}`: {e}", path.display())))
    })
}

/// The range of sample numbers shard `k` of `n` renders of `spp` samples
/// per pixel, as (start, stop): `render(shard=(k, n))` returns the mean of
/// those samples, so shards combine as Σ (stop − start)·image / spp.
#[pyfunction]
fn shard_samples(spp: u64, k: u64, n: u64) -> PyResult<(u64, u64)> {
    if k >= n || n > spp {
        return Err(PyValueError::new_err(format!("shard ({k}, {n}) of {spp} samples needs 0 ≤ k < n ≤ spp")));
    }
    let r = airlight::film::partial::piece(spp, k, n);
    Ok((r.start, r.end))
}

/// Airlight, a CPU renderer for participating media: scenes in, NumPy
/// images out. See `help(airlight.Scene)` and the scene format
/// (docs/scene-format.md).
#[pymodule]
#[pyo3(name = "airlight")]
fn airlight_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyScene>()?;
    m.add_class::<Comparison>()?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("IntegratorError", py.get_type::<errors::IntegratorError>())?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(loads, m)?)?;
    m.add_function(wrap_pyfunction!(from_dict, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(save, m)?)?;
    m.add_function(wrap_pyfunction!(shard_samples, m)?)?;
    Ok(())
}
