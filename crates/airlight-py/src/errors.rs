//! Python exceptions: scene errors with the CLI's messages, integrator
//! errors, and panics turned into `RuntimeError` so that none reaches Python
//! as a `PanicException`.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};

pyo3::create_exception!(
    airlight,
    SceneError,
    PyValueError,
    "A scene that cannot be read or built. `str(e)` is the message `airlight` prints \
     (file:line:col: message for a file); `file`, `line`, `column` and `message` hold its parts."
);

pyo3::create_exception!(
    airlight,
    IntegratorError,
    PyValueError,
    "An integrator option out of bounds, an unknown integrator, or an integrator that cannot \
     render the scene (the message says why and what to use instead)."
);

/// Where a scene's text came from, for its error messages.
#[derive(Clone, Debug)]
pub enum Origin {
    /// A file: errors are `file:line:col: message`, as the CLI prints them.
    File,
    /// Text given to `loads`: `line L, column C: message`.
    Text,
    /// A dict, written as TOML by us: the position in that text means little
    /// to the caller, so the message quotes the offending line instead.
    Dict,
}

/// A scene error as a Python `SceneError`, with its parts as attributes.
pub fn scene_error(py: Python<'_>, e: &airlight::scene::SceneError, origin: &Origin, text: &str) -> PyErr {
    let message = match (origin, e.location) {
        (Origin::Dict, Some((line, _))) => {
            let quoted = text.lines().nth(line - 1).unwrap_or("").trim();
            format!("{} (in the scene as TOML, line {line}: `{quoted}`)", e.message)
        }
        // The library's own form: the CLI's message without its `error: `.
        _ => e.to_string(),
    };
    let err = SceneError::new_err(message);
    let value = err.value(py);
    let file = e.file.as_ref().map(|f| f.display().to_string());
    let (line, column) = match e.location {
        Some((l, c)) => (Some(l), Some(c)),
        None => (None, None),
    };
    let toml = matches!(origin, Origin::Dict).then_some(text);
    // Setting attributes on a fresh exception instance cannot fail short of
    // memory exhaustion; the message is what matters, so ignore it then.
    let _ = value.setattr("file", file);
    let _ = value.setattr("line", line);
    let _ = value.setattr("column", column);
    let _ = value.setattr("message", &e.message);
    let _ = value.setattr("toml", toml);
    err
}

pub fn integrator_error(message: impl Into<String>) -> PyErr {
    IntegratorError::new_err(message.into())
}

/// The text of a panic's payload.
pub fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".into()
    }
}

/// A panic as the exception Python sees.
pub fn internal_error(message: &str) -> PyErr {
    PyRuntimeError::new_err(format!("internal error in airlight (a bug; please report it): {message}"))
}

/// Runs an entry point, turning a panic into `RuntimeError`: PyO3 would
/// raise `PanicException`, which derives from `BaseException` and so slips
/// past `except Exception`.
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| Err(internal_error(&panic_message(payload.as_ref()))))
}
