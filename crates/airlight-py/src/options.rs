//! `render()`'s keyword arguments: film settings (spp, seed, size) and the
//! integrator options by their scene-file names, checked by the library's
//! own checks so that the messages are the file's and the CLI's.

use crate::errors::integrator_error;
use airlight::integrator::analytic::LightQuadrature;
use airlight::integrator::{
    IntegratorDesc, IntegratorKind, MAX_BOUNCES, MAX_DEPTH, MAX_LIGHT_STEPS, MAX_STEPS, Sampling,
};
use airlight::scene::{MAX_IMAGE_SIDE, MAX_SPP, RenderSettings};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyInt, PyString};

/// The integrator options `render()` takes, as the scene file's `[render]`
/// table spells them.
pub const OPTIONS: [&str; 11] = [
    "steps",
    "jitter",
    "shadows",
    "light_steps",
    "light_quadrature",
    "sampling",
    "stratify",
    "max_depth",
    "bounces",
    "patch_size",
    "link_threshold",
];

/// A whole number within `min..=max`, else the library's message for a count
/// out of bounds ("steps must be an integer from 1 to 1048576, got 0"); here
/// because a Python int may not fit the u32 the library checks.
fn count(key: &str, v: &Bound<'_, PyAny>, min: u64, max: u64) -> PyResult<u64> {
    in_range(key, integer(key, v)?, min, max).map_err(PyValueError::new_err)
}

/// An integrator option's count: out of bounds, an `IntegratorError`.
fn option_count(key: &str, v: &Bound<'_, PyAny>, max: u32) -> PyResult<u32> {
    Ok(in_range(key, integer(key, v)?, 1, max as u64).map_err(integrator_error)? as u32)
}

fn in_range(key: &str, n: i128, min: u64, max: u64) -> Result<u64, String> {
    if (min as i128..=max as i128).contains(&n) {
        Ok(n as u64)
    } else {
        Err(format!("{key} must be an integer from {min} to {max}, got {n}"))
    }
}

fn integer(key: &str, v: &Bound<'_, PyAny>) -> PyResult<i128> {
    if v.is_instance_of::<PyBool>() || !v.is_instance_of::<PyInt>() && !v.hasattr("__index__")? {
        return Err(PyTypeError::new_err(format!("{key} must be an integer, got {}", type_name(v))));
    }
    v.call_method0("__index__")?.extract()
}

fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into())
}

fn boolean(key: &str, v: &Bound<'_, PyAny>) -> PyResult<bool> {
    // NumPy's bool (`bool_` before NumPy 2) is not a Python bool, but says
    // what it is through __bool__.
    if v.is_instance_of::<PyBool>() || is_numpy_bool(v) {
        return v.is_truthy();
    }
    Err(PyTypeError::new_err(format!("{key} must be True or False, got {}", type_name(v))))
}

fn is_numpy_bool(v: &Bound<'_, PyAny>) -> bool {
    let t = v.get_type();
    let module = t.module().map(|m| m.to_string()).unwrap_or_default();
    module == "numpy" && matches!(type_name(v).as_str(), "bool" | "bool_")
}

fn number(key: &str, v: &Bound<'_, PyAny>) -> PyResult<f32> {
    if v.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!("{key} must be a number, got bool")));
    }
    v.extract::<f64>()
        .map(|x| x as f32)
        .map_err(|_| PyTypeError::new_err(format!("{key} must be a number, got {}", type_name(v))))
}

fn name<T: std::str::FromStr<Err = String>>(key: &str, v: &Bound<'_, PyAny>) -> PyResult<T> {
    let Ok(s) = v.cast::<PyString>() else {
        return Err(PyTypeError::new_err(format!("{key} must be a string, got {}", type_name(v))));
    };
    s.to_cow()?.parse().map_err(|e: String| integrator_error(format!("{key}: {e}")))
}

/// The integrator `name` names (or the scene's), with `options` applied.
pub fn integrator(
    base: IntegratorDesc,
    kind: Option<&Bound<'_, PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<IntegratorDesc> {
    let mut d = base;
    if let Some(k) = kind.filter(|k| !k.is_none()) {
        let Ok(s) = k.cast::<PyString>() else {
            return Err(PyTypeError::new_err(format!("integrator must be a string, got {}", type_name(k))));
        };
        d.kind = s.to_cow()?.parse::<IntegratorKind>().map_err(integrator_error)?;
    }
    for (key, v) in options.into_iter().flat_map(|o| o.iter()) {
        let key: String = key.extract()?;
        let v = &v;
        match key.as_str() {
            "steps" => d.raymarch.steps = option_count("steps", v, MAX_STEPS)?,
            "jitter" => d.raymarch.jitter = boolean("jitter", v)?,
            "shadows" => d.analytic.shadows = boolean("shadows", v)?,
            "light_steps" => d.analytic.light_steps = option_count("light_steps", v, MAX_LIGHT_STEPS)?,
            "light_quadrature" => d.analytic.quadrature = name::<LightQuadrature>("light_quadrature", v)?,
            "sampling" => d.stochastic.sampling = name::<Sampling>("sampling", v)?,
            "stratify" => d.stochastic.stratify = boolean("stratify", v)?,
            "max_depth" => d.path.max_depth = option_count("max_depth", v, MAX_DEPTH)?,
            "bounces" => d.radiosity.bounces = option_count("bounces", v, MAX_BOUNCES)?,
            "patch_size" => d.radiosity.patch_size = if v.is_none() { None } else { Some(number("patch_size", v)?) },
            "link_threshold" => d.radiosity.link_threshold = number("link_threshold", v)?,
            other => {
                return Err(PyTypeError::new_err(format!(
                    "render() got an unexpected keyword argument '{other}'; the integrator options are {}",
                    OPTIONS.join(", ")
                )));
            }
        }
    }
    // The library's checks (the counts' bounds again, patch_size,
    // link_threshold), with its words.
    d.validate().map_err(|e| integrator_error(e.to_string()))?;
    Ok(d)
}

/// Film settings overridden by `render()`'s arguments, then checked.
pub struct Film<'a, 'py> {
    pub spp: Option<&'a Bound<'py, PyAny>>,
    pub seed: Option<&'a Bound<'py, PyAny>>,
    pub width: Option<&'a Bound<'py, PyAny>>,
    pub height: Option<&'a Bound<'py, PyAny>>,
}

impl Film<'_, '_> {
    pub fn apply(&self, base: &RenderSettings) -> PyResult<RenderSettings> {
        let mut s = base.clone();
        let side = MAX_IMAGE_SIDE as u64;
        if let Some(v) = self.width.filter(|v| !v.is_none()) {
            s.width = count("width", v, 1, side)? as u32;
        }
        if let Some(v) = self.height.filter(|v| !v.is_none()) {
            s.height = count("height", v, 1, side)? as u32;
        }
        if let Some(v) = self.spp.filter(|v| !v.is_none()) {
            s.spp = count("spp", v, 1, MAX_SPP as u64)? as u32;
        }
        if let Some(v) = self.seed.filter(|v| !v.is_none()) {
            s.seed = count("seed", v, 0, u64::MAX)?;
        }
        s.validate().map_err(PyValueError::new_err)?;
        Ok(s)
    }
}
