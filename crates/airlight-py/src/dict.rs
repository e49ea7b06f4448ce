//! Python values as TOML: a scene given as dicts is written as the scene file
//! it stands for and read by the same reader, so its keys, defaults and error
//! messages are the file's.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml::Value;

/// A mapping as a TOML table; `what` names it in errors ("scene", "lights").
pub fn table(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<toml::Table> {
    match value(obj, "", 0)? {
        Value::Table(t) => Ok(t),
        _ => Err(PyTypeError::new_err(format!(
            "{what} must be a dict (the tables of a scene file), got {}",
            type_name(obj)
        ))),
    }
}

/// A list of mappings (`[[lights]]`) as a TOML array.
pub fn array(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Value> {
    match value(obj, what, 0)? {
        v @ Value::Array(_) => Ok(v),
        _ => Err(PyTypeError::new_err(format!("{what} must be a list of dicts, got {}", type_name(obj)))),
    }
}

/// How deep dicts and lists may nest: far deeper than any scene (signed
/// distance fields nest at most 64 deep), far shallower than what would
/// overflow the stack.
const MAX_DEPTH: usize = 256;

/// One value; `path` is where it sits, as the scene format names keys
/// (`objects[0].radius`), for errors; `depth` how deep it is nested.
fn value(obj: &Bound<'_, PyAny>, path: &str, depth: usize) -> PyResult<Value> {
    if depth > MAX_DEPTH {
        return Err(crate::errors::SceneError::new_err(format!(
            "{}: dicts and lists nested more than {MAX_DEPTH} deep, which no scene is",
            label(path)
        )));
    }
    // bool before int: Python's bool is an int.
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Boolean(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        let i: i64 = obj
            .extract()
            .map_err(|_| PyValueError::new_err(format!("{}: {obj} does not fit a 64-bit integer", label(path))))?;
        return Ok(Value::Integer(i));
    }
    if let Ok(f) = obj.cast::<PyFloat>() {
        return Ok(Value::Float(f.value()));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, v) in d.iter() {
            let Ok(key) = k.cast::<PyString>() else {
                return Err(PyTypeError::new_err(format!(
                    "{}: keys must be strings, got {}",
                    label(path),
                    type_name(&k)
                )));
            };
            let key = key.to_cow()?.into_owned();
            let inner = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
            if v.is_none() {
                return Err(PyValueError::new_err(format!(
                    "{inner} is None, which a scene file cannot hold; leave the key out for its default"
                )));
            }
            t.insert(key, value(&v, &inner, depth + 1)?);
        }
        return Ok(Value::Table(t));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, v) in obj.try_iter()?.enumerate() {
            items.push(value(&v?, &format!("{path}[{i}]"), depth + 1)?);
        }
        return Ok(Value::Array(items));
    }
    // NumPy arrays and scalars (float32, int64, bool_) become Python values.
    if obj.hasattr("tolist")? {
        return value(&obj.call_method0("tolist")?, path, depth + 1);
    }
    // pathlib.Path and other path-like objects: a mesh `file`.
    if obj.hasattr("__fspath__")? {
        return value(&obj.call_method0("__fspath__")?, path, depth + 1);
    }
    // Other mappings and sequences (e.g. a MappingProxy, a range).
    if obj.hasattr("keys")? {
        let dict = PyDict::new(obj.py());
        for key in obj.call_method0("keys")?.try_iter()? {
            let key = key?;
            dict.set_item(&key, obj.get_item(&key)?)?;
        }
        return value(dict.as_any(), path, depth + 1);
    }
    if obj.hasattr("__iter__")? {
        let list = PyList::empty(obj.py());
        for v in obj.try_iter()? {
            list.append(v?)?;
        }
        return value(list.as_any(), path, depth + 1);
    }
    Err(PyTypeError::new_err(format!(
        "{}: a value of type {} cannot be written in a scene file (numbers, strings, booleans, lists and dicts can)",
        label(path),
        type_name(obj)
    )))
}

/// The key path in a message; the scene itself at the top.
fn label(path: &str) -> &str {
    if path.is_empty() { "the scene" } else { path }
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into())
}
