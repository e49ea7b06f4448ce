//! `render()`'s keyword arguments: the film settings and the integrator
//! options by their scene-file names, each checked by the library's
//! declaration of it (`RENDER_SETTINGS`, `INTEGRATOR_OPTIONS`), so that the
//! keys, bounds and messages are the file's and the CLI's.

use crate::errors::integrator_error;
use airlight::integrator::{INTEGRATOR_KEY, IntegratorDesc, IntegratorKind};
use airlight::options::{OptionError, OptionValue, ValueKind};
use airlight::scene::{RENDER_SETTINGS, RenderSettings};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyInt, PyString};

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

fn number(key: &str, v: &Bound<'_, PyAny>) -> PyResult<f64> {
    if v.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!("{key} must be a number, got bool")));
    }
    v.extract::<f64>().map_err(|_| PyTypeError::new_err(format!("{key} must be a number, got {}", type_name(v))))
}

/// A keyword argument as an option value: None asks for the default.
/// A Python object of no kind an option takes is a `TypeError` in
/// Python's words.
fn value(kind: ValueKind, key: &str, v: &Bound<'_, PyAny>) -> PyResult<OptionValue> {
    let wrong = || {
        let expected = match kind {
            ValueKind::Bool => "True or False",
            ValueKind::Count { .. } => "an integer",
            ValueKind::Number(_) => "a number",
            ValueKind::Colour => "a number or a sequence of three numbers",
            ValueKind::Name(_) => "a string",
        };
        PyTypeError::new_err(format!("{key} must be {expected}, got {}", type_name(v)))
    };
    if v.is_none() {
        return Ok(OptionValue::Default);
    }
    Ok(match kind {
        ValueKind::Bool => OptionValue::Bool(boolean(key, v).map_err(|_| wrong())?),
        ValueKind::Count { .. } => OptionValue::Int(integer(key, v).map_err(|_| wrong())?),
        ValueKind::Number(_) => OptionValue::Float(number(key, v).map_err(|_| wrong())?),
        ValueKind::Name(_) => match v.cast::<PyString>() {
            Ok(s) => OptionValue::Text(s.to_cow()?.into_owned()),
            Err(_) => return Err(wrong()),
        },
        ValueKind::Colour => {
            if let Ok(x) = number(key, v) {
                OptionValue::Float(x)
            } else if let Ok(list) = v.extract::<Vec<f64>>() {
                OptionValue::List(list)
            } else {
                return Err(wrong());
            }
        }
    })
}

/// An option's refusal as Python's exception: a value of the wrong kind a
/// `TypeError`, an integrator option out of bounds an `IntegratorError`, a
/// film setting a `ValueError`.
fn refusal(e: OptionError, integrator_option: bool) -> PyErr {
    if e.wrong_type {
        PyTypeError::new_err(e.message)
    } else if integrator_option {
        integrator_error(e.message)
    } else {
        PyValueError::new_err(e.message)
    }
}

/// Every option `render()` takes by keyword, as the scene file's `[render]`
/// spells it, but the integrator (its own argument).
pub fn keywords() -> Vec<&'static str> {
    airlight::SceneFile::render_keys().filter(|k| *k != INTEGRATOR_KEY).collect()
}

/// The settings and integrator description `render()`'s arguments give:
/// `kind` names the integrator (None: the scene's), `options` maps keys of
/// `[render]` to values, each checked by its declaration.
pub fn apply(
    settings: &RenderSettings,
    integrator: IntegratorDesc,
    kind: Option<&Bound<'_, PyAny>>,
    options: &[(String, Bound<'_, PyAny>)],
) -> PyResult<(RenderSettings, IntegratorDesc)> {
    let (mut s, mut d) = (settings.clone(), integrator);
    if let Some(k) = kind.filter(|k| !k.is_none()) {
        let Ok(name) = k.cast::<PyString>() else {
            return Err(PyTypeError::new_err(format!("integrator must be a string, got {}", type_name(k))));
        };
        d.kind = name.to_cow()?.parse::<IntegratorKind>().map_err(integrator_error)?;
    }
    for (key, v) in options {
        if let Some(spec) = airlight::options::find(RENDER_SETTINGS, key) {
            spec.apply(&mut s, &value(spec.kind, key, v)?).map_err(|e| refusal(e, false))?;
        } else if let Some(o) = IntegratorDesc::option(key).filter(|o| o.spec.key != INTEGRATOR_KEY) {
            o.spec.apply(&mut d, &value(o.spec.kind, key, v)?).map_err(|e| refusal(e, true))?;
        } else {
            return Err(PyTypeError::new_err(format!(
                "render() got an unexpected keyword argument '{key}'; it takes {}",
                keywords().join(", ")
            )));
        }
    }
    s.validate().map_err(PyValueError::new_err)?;
    d.validate().map_err(|e| refusal(e, true))?;
    Ok((s, d))
}
