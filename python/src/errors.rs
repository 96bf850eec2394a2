//! Library errors as Python exceptions carrying the library's message, and spec tables from
//! the JSON text the Python side writes.

use pyo3::exceptions::PyValueError;
use pyo3::PyErr;
use serde_json::{Map, Value};
use std::fmt::Display;

/// A `ValueError` with the library's message.
pub fn value_error(e: impl Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A study-layer error as a `ValueError`, with the study layer's words for the command line's
/// options said as the Python arguments they are here: the study layer is the command line's
/// too, and a few of its messages name its flags (`--runs`, `--method bcls`, `--init auto`).
pub fn study_error(e: impl Display) -> PyErr {
    value_error(argument_words(&e.to_string()))
}

/// `message` with the command line's options named as the Python arguments.
fn argument_words(message: &str) -> String {
    [
        ("--init auto", "init=\"auto\""),
        ("--init experiment-only", "init=\"experiment-only\""),
        ("--time-limit", "time_limit"),
        ("--runs", "runs"),
        ("--threads", "threads"),
        ("--method ", "method "),
    ]
    .iter()
    .fold(message.to_string(), |m, (flag, argument)| {
        m.replace(flag, argument)
    })
}

/// The spec table in `json` (an object), as the registries take it.
pub fn spec_table(json: &str) -> Result<Map<String, Value>, PyErr> {
    match serde_json::from_str(json) {
        Ok(Value::Object(map)) => Ok(map),
        Ok(other) => Err(value_error(format!(
            "expected a table of keys and values, found {other}"
        ))),
        Err(e) => Err(value_error(format!("not a spec table: {e}"))),
    }
}

/// `value` as JSON text; serialising plain numbers, strings and tables cannot fail, so an
/// error is reported rather than unwrapped.
pub fn json_text(value: &impl serde::Serialize) -> Result<String, PyErr> {
    serde_json::to_string(value).map_err(|e| value_error(format!("JSON: {e}")))
}
