//! `airlight.Scene`: a scene read from a file, text or dicts, rendered into
//! NumPy arrays.
//!
//! Scenes made from one another by `at_time` or `frame` share the Rust scene
//! and the integrator last built for it, as the CLI's animations do: the
//! integrator is built once for the lights as the file writes them, and a
//! render at another time only moves the lights and tells the integrator
//! (radiosity relights instead of recompiling). So two renders of such
//! scenes take turns.

use crate::errors::{Origin, guard, scene_error};
use crate::options;
use crate::render::{self, Job, Output, Progress};
use crate::shared::Shared;
use airlight::SceneFile;
use airlight::aov::Aov;
use airlight::assets::AssetPath;
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::render::{MAX_THREADS, RenderRequest};
use airlight::scene::RenderSettings;
use numpy::ndarray::{Array2, Array3};
use numpy::{PyArray2, PyArray3};
use pyo3::exceptions::{PyMemoryError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// A scene's text and where it came from, for `with_lights` and errors.
pub struct Source {
    pub text: String,
    /// Where mesh files are found.
    pub assets: AssetPath,
    pub origin: Origin,
    /// The file, for error messages.
    pub file: Option<PathBuf>,
}

impl Source {
    /// Text (`loads`, dicts): meshes are found in `base_dir` (None: the
    /// current folder), then in the folders of `AIRLIGHT_ASSET_PATH`, as
    /// the CLI finds a scene file's.
    pub fn text(text: String, base_dir: Option<&Path>, origin: Origin) -> Source {
        Source { text, assets: AssetPath::new(base_dir, &AssetPath::from_env()), origin, file: None }
    }
}

/// What a scene holds, read once.
struct Summary {
    animated: bool,
    lights: usize,
    medium: bool,
    /// Why every pixel will be black, if so: for integrators that ignore
    /// the medium (`direct`), and for the others.
    darkness: [Option<String>; 2],
}

/// A scene ready to render: read from a scene file (`airlight.load`), TOML
/// text (`airlight.loads`) or dicts with the file's keys (`airlight.Scene(d)`).
#[pyclass(name = "Scene", module = "airlight", frozen)]
pub struct PyScene {
    shared: Arc<Mutex<Shared>>,
    source: Arc<Source>,
    summary: Arc<Summary>,
    settings: RenderSettings,
    integrator: IntegratorDesc,
    time: Option<f32>,
}

/// Reads a scene from its text; the GIL is released meanwhile (meshes may
/// be large).
pub fn read(py: Python<'_>, source: Source) -> PyResult<PyScene> {
    let parsed = py.detach(|| SceneFile::from_toml_with(&source.text, &source.assets));
    let file = parsed.map_err(|e| scene_error(py, &e, &source.origin, &source.text))?;
    warn_notes(py, &file.scene)?;
    Ok(new_scene(file, source))
}

/// A UserWarning for each thing the scene asks for that Airlight does not
/// read (a glTF file's normal maps, say), as the CLI warns of them.
pub fn warn_notes(py: Python<'_>, scene: &airlight::Scene) -> PyResult<()> {
    for note in scene.notes() {
        let message = std::ffi::CString::new(note.as_str()).unwrap_or_default();
        PyErr::warn(py, &py.get_type::<PyUserWarning>(), &message, 1)?;
    }
    Ok(())
}

/// The Python scene of a scene file read from `source`.
pub fn new_scene(file: SceneFile, source: Source) -> PyScene {
    let SceneFile { scene, integrator } = file;
    let summary = Summary {
        animated: scene.is_animated(),
        lights: scene.lights().len(),
        medium: scene.medium().is_some(),
        darkness: [scene.darkness(false), scene.darkness(true)],
    };
    PyScene {
        settings: scene.settings().clone(),
        integrator,
        shared: Arc::new(Mutex::new(Shared::new(scene))),
        source: Arc::new(source),
        summary: Arc::new(summary),
        time: None,
    }
}

/// A scene from dicts: written as TOML and read as a file would be.
pub fn from_dict(py: Python<'_>, scene: &Bound<'_, PyAny>, base_dir: Option<PathBuf>) -> PyResult<PyScene> {
    let table = crate::dict::table(scene, "scene")?;
    let text =
        toml::to_string(&table).map_err(|e| PyValueError::new_err(format!("cannot write the scene as TOML: {e}")))?;
    read(py, Source::text(text, base_dir.as_deref(), Origin::Dict))
}

impl PyScene {
    fn at(&self, time: Option<f32>) -> PyScene {
        PyScene {
            shared: Arc::clone(&self.shared),
            source: Arc::clone(&self.source),
            summary: Arc::clone(&self.summary),
            settings: self.settings.clone(),
            integrator: self.integrator,
            time,
        }
    }
}

/// A buffer of H·W RGB triples as an (H, W, 3) array; NumPy takes the
/// buffer over, nothing is copied.
fn array(py: Python<'_>, pixels: Vec<f32>, w: u32, h: u32) -> PyResult<Bound<'_, PyArray3<f32>>> {
    let a = Array3::from_shape_vec((h as usize, w as usize, 3), pixels)
        .map_err(|e| crate::errors::internal_error(&format!("image buffer: {e}")))?;
    Ok(PyArray3::from_owned_array(py, a))
}

/// An image's pixels as an (H, W, 3) array.
fn image_array<'py>(py: Python<'py>, image: &airlight::Image) -> PyResult<Bound<'py, PyArray3<f32>>> {
    array(py, image.pixels.iter().flat_map(|p| p.to_array()).collect(), image.width, image.height)
}

/// The outputs `aovs=` asks for: True for all, or names (a list, or one
/// comma-separated string); the library's message for an unknown one.
fn aov_list(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Aov>> {
    let Some(arg) = arg.filter(|a| !a.is_none()) else { return Ok(Vec::new()) };
    if let Ok(flag) = arg.cast::<pyo3::types::PyBool>() {
        // All that Python computes (not `inscatter`, below).
        let all = Aov::ALL.into_iter().filter(|a| *a != Aov::Inscatter).collect();
        return Ok(if flag.is_true() { all } else { Vec::new() });
    }
    let list = if let Ok(s) = arg.cast::<pyo3::types::PyString>() {
        s.to_cow()?.into_owned()
    } else {
        let names: Vec<String> = arg.extract().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(
                "aovs must be True, False, a list of names or a comma-separated string of them \
                 (albedo, normal, depth, variance)",
            )
        })?;
        names.join(",")
    };
    let aovs = Aov::parse_list(&list).map_err(|e| PyValueError::new_err(format!("aovs: {e}")))?;
    if aovs.contains(&Aov::Inscatter) {
        return Err(PyValueError::new_err(
            "aovs: inscatter is not computed from Python yet; `airlight render --aov inscatter` writes it",
        ));
    }
    Ok(aovs)
}

#[pymethods]
impl PyScene {
    /// A scene from dicts with the scene file's keys (`render`, `camera`,
    /// `materials`, `objects`, `lights`, `medium`), checked as a file is;
    /// relative mesh paths start at `base_dir` (default: the current one).
    #[new]
    #[pyo3(signature = (scene, base_dir=None))]
    fn new(py: Python<'_>, scene: &Bound<'_, PyAny>, base_dir: Option<PathBuf>) -> PyResult<PyScene> {
        guard(|| from_dict(py, scene, base_dir))
    }

    /// Image width in pixels (the file's; `render(width=...)` overrides it).
    #[getter]
    fn width(&self) -> u32 {
        self.settings.film.width
    }

    /// Image height in pixels (the file's; `render(height=...)` overrides it).
    #[getter]
    fn height(&self) -> u32 {
        self.settings.film.height
    }

    /// Samples per pixel the file asks for.
    #[getter]
    fn spp(&self) -> u32 {
        self.settings.spp
    }

    /// The seed of the scene's random numbers; `render(seed=...)` overrides it.
    #[getter]
    fn seed(&self) -> u64 {
        self.settings.seed
    }

    /// The integrator the file names (or its default).
    #[getter]
    fn integrator(&self) -> &'static str {
        self.integrator.kind.name()
    }

    /// The animation time this scene's lights are at, or None for the
    /// lights as written.
    #[getter]
    fn time(&self) -> Option<f32> {
        self.time
    }

    /// Whether any light has keyframes.
    #[getter]
    fn is_animated(&self) -> bool {
        self.summary.animated
    }

    /// The scene as TOML text: the file read, or what a dict was written as.
    #[getter]
    fn toml(&self) -> &str {
        &self.source.text
    }

    /// The scene file read (`load`), else None.
    #[getter]
    fn path(&self) -> Option<&Path> {
        self.source.file.as_deref()
    }

    fn __repr__(&self) -> String {
        let s = &self.settings;
        let time = self.time.map(|t| format!(", time {t}")).unwrap_or_default();
        format!(
            "<airlight.Scene {}×{}, {} spp, {}, {} lights{}{time}>",
            s.film.width,
            s.film.height,
            s.spp,
            self.integrator.kind,
            self.summary.lights,
            if self.summary.medium { ", medium" } else { "" }
        )
    }

    /// The scene with its keyframed lights at `time` in [0, 1] (held at the
    /// end keys outside them); it shares this scene's integrator, so an
    /// animation compiles radiosity once.
    fn at_time(&self, time: f64) -> PyResult<PyScene> {
        if !time.is_finite() {
            return Err(PyValueError::new_err(format!("time must be a finite number, got {time}")));
        }
        Ok(self.at(Some(time as f32)))
    }

    /// Frame `k` of an `n`-frame animation, at time k/(n − 1) as
    /// `airlight render --frames n --frame k` renders it.
    fn frame(&self, k: u32, n: u32) -> PyResult<PyScene> {
        if k >= n {
            return Err(PyValueError::new_err(format!("frame {k}: the animation has frames 0 to {}", n as i64 - 1)));
        }
        Ok(self.at(Some(airlight::render::frame_time(k, n))))
    }

    /// The scene with other lights: a list of dicts as the file's
    /// `[[lights]]` tables (keyframes too). The scene is read again from its
    /// text with these lights, at the lights' written pose.
    fn with_lights(&self, py: Python<'_>, lights: &Bound<'_, PyAny>) -> PyResult<PyScene> {
        guard(|| {
            let mut table: toml::Table = self
                .source
                .text
                .parse()
                .map_err(|e| crate::errors::internal_error(&format!("the scene's own text: {e}")))?;
            table.insert("lights".into(), crate::dict::array(lights, "lights")?);
            let text = toml::to_string(&table)
                .map_err(|e| PyValueError::new_err(format!("cannot write the scene as TOML: {e}")))?;
            let assets = self.source.assets.clone();
            read(py, Source { text, assets, origin: Origin::Dict, file: None })
        })
    }

    /// Renders the scene; returns linear RGB as a float32 array (height,
    /// width, 3), the same pixels `airlight render` writes to an EXR.
    ///
    /// - `integrator`: direct, raymarch, analytic, stochastic, path or
    ///   radiosity (default: the scene's).
    /// - `threads`: worker threads (default: every core); the image does
    ///   not depend on it.
    /// - `shard=(k, n)`: only the k-th of n ranges of each pixel's samples
    ///   (`shard_samples`), as `airlight render --shard k/n`; the result is
    ///   their mean.
    /// - `progress`: a callable `f(done, total)` (pixel samples), a tqdm
    ///   bar, or True for a new tqdm bar; called on this thread at most
    ///   every 0.1 s. An exception it raises stops the render.
    /// - `aovs`: True for all, or names (a list, or a comma-separated
    ///   string): a dict of float32 arrays instead, `color` first, then
    ///   `albedo`, `normal` (H, W, 3) and `depth` (H, W) of the first hits
    ///   over the render's camera rays, and `variance` (of each pixel's
    ///   mean), as asked: the layers `airlight render --aov` writes. Not
    ///   with `shard`.
    /// - Every other keyword is a key of a scene file's `[render]` table
    ///   with the same meaning, overriding the scene's: the film settings
    ///   (`spp`, `seed`, `width`, `height`, `exposure`, `tonemap`, …) and
    ///   the integrator options (`steps`, `stratify`, `reuse`, …); None
    ///   gives the option's default. Each is checked by the declaration
    ///   the file and the CLI use: a value of the wrong kind raises
    ///   `TypeError`, an integrator option out of bounds `IntegratorError`,
    ///   a film setting out of bounds `ValueError`.
    ///
    /// The GIL is released while rendering; Ctrl-C (looked for every 50 ms)
    /// stops the render and raises KeyboardInterrupt. An image too large
    /// for the memory left raises MemoryError; a scene that can only be
    /// black gives a UserWarning, as the CLI warns.
    #[pyo3(signature = (
        integrator=None, *, threads=None, shard=None, progress=None, aovs=None, **options
    ))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        integrator: Option<&Bound<'py, PyAny>>,
        threads: Option<i64>,
        shard: Option<(i64, i64)>,
        progress: Option<&Bound<'py, PyAny>>,
        aovs: Option<&Bound<'py, PyAny>>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            airlight::memory::limit_var().map_err(PyValueError::new_err)?;
            let given: Vec<(String, Bound<'py, PyAny>)> = match options {
                Some(o) => o.iter().map(|(k, v)| Ok((k.extract::<String>()?, v))).collect::<PyResult<_>>()?,
                None => Vec::new(),
            };
            let (settings, desc) = options::apply(&self.settings, self.integrator, integrator, &given)?;
            // Python's integers as the job's: out of range, the job's own
            // message with the value as given.
            let threads = match threads {
                None => None,
                Some(n) => Some(u32::try_from(n).ok().filter(|&n| n >= 1).ok_or_else(|| {
                    PyValueError::new_err(format!("threads must be an integer from 1 to {MAX_THREADS}, got {n}"))
                })?),
            };
            let shard = match shard {
                None => None,
                Some((k, n)) if 0 <= k && k < n && n <= u32::MAX as i64 => Some((k as u32, n as u32)),
                Some((k, n)) => {
                    return Err(PyValueError::new_err(format!("shard (k, n) needs 0 ≤ k < n, got ({k}, {n})")));
                }
            };
            let aovs = aov_list(aovs)?;
            let request = RenderRequest { shard, aovs: aovs.clone(), threads, ..Default::default() };
            let job = request.check(&settings, desc.kind).map_err(PyValueError::new_err)?;
            let surface = aovs.iter().any(|a| matches!(a, Aov::Albedo | Aov::Normal | Aov::Depth));
            // As the CLI does before it renders: an image too large for
            // memory is refused, a scene that can only be black is warned of.
            job.mode
                .check_memory(&settings.film)
                .map_err(|e| PyMemoryError::new_err(format!("{e}: make the image smaller (width=, height=)")))?;
            let sees_medium = desc.kind != IntegratorKind::Direct;
            if let Some(why) = &self.summary.darkness[sees_medium as usize] {
                let message = std::ffi::CString::new(why.as_str()).unwrap_or_default();
                PyErr::warn(py, &py.get_type::<PyUserWarning>(), &message, 1)?;
            }
            let samples = &job.samples;
            let label = format!(
                "{} {}×{} {} spp",
                desc.kind,
                settings.film.width,
                settings.film.height,
                samples.end - samples.start
            );
            let progress = Progress::from_arg(py, progress, &label)?;
            let (w, h) = (settings.film.width, settings.film.height);
            // A scene without keyframes is the same at every time.
            let pose = self.time.filter(|_| self.summary.animated);
            let shared = Arc::clone(&self.shared);
            let job = Job { shared, settings, desc, pose, render: job, surface };
            let Output { color, mut variance, mut surface } = render::run(py, job, progress)?;
            let color = array(py, color, w, h)?;
            if aovs.is_empty() {
                return Ok(color.into_any());
            }
            let out = PyDict::new(py);
            out.set_item("color", color)?;
            for aov in aovs {
                let missing = || crate::errors::internal_error(&format!("{} was not rendered", aov.name()));
                let value = match aov {
                    Aov::Variance => array(py, variance.take().ok_or_else(missing)?, w, h)?.into_any(),
                    Aov::Albedo => image_array(py, &surface.as_ref().ok_or_else(missing)?.albedo)?.into_any(),
                    Aov::Normal => image_array(py, &surface.as_ref().ok_or_else(missing)?.normal)?.into_any(),
                    Aov::Depth => {
                        let depth = std::mem::take(&mut surface.as_mut().ok_or_else(missing)?.depth);
                        let depth = Array2::from_shape_vec((h as usize, w as usize), depth)
                            .map_err(|e| crate::errors::internal_error(&format!("depth buffer: {e}")))?;
                        PyArray2::from_owned_array(py, depth).into_any()
                    }
                    Aov::Inscatter => return Err(missing()),
                };
                out.set_item(aov.name(), value)?;
            }
            Ok(out.into_any())
        })
    }
}
