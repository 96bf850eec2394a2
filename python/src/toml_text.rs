//! Experiment text from a table of sections (JSON), so that a fit described by keyword
//! arguments goes through the command line's own experiment reader, checks and messages.

use crate::errors::value_error;
use pyo3::PyResult;
use serde_json::{Map, Value};
use std::fmt::Write;

/// TOML text of `sections`: plain keys first, then one `[section]` per table.
pub fn experiment_text(sections: &Map<String, Value>) -> PyResult<String> {
    let mut out = String::new();
    for (key, value) in sections.iter().filter(|(_, v)| !v.is_object()) {
        writeln!(out, "{} = {}", key_text(key), value_text(key, value)?).ok();
    }
    for (name, table) in sections {
        let Value::Object(table) = table else {
            continue;
        };
        writeln!(out, "\n[{}]", key_text(name)).ok();
        for (key, value) in table {
            writeln!(out, "{} = {}", key_text(key), value_text(key, value)?).ok();
        }
    }
    Ok(out)
}

/// A bare key when it can be one, else a quoted key.
fn key_text(key: &str) -> String {
    let bare = !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare {
        key.to_string()
    } else {
        Value::from(key).to_string()
    }
}

/// A TOML value: JSON's strings, numbers, booleans and arrays are TOML's; objects become inline
/// tables. `key` names the value in the message for `null`.
fn value_text(key: &str, value: &Value) -> PyResult<String> {
    Ok(match value {
        Value::Null => {
            return Err(value_error(format!(
                "`{key}`: expected a value, found None"
            )))
        }
        // JSON escapes are valid in TOML basic strings; floats print in their shortest
        // round-trip form, which TOML reads back exactly.
        Value::Bool(_) | Value::String(_) | Value::Number(_) => value.to_string(),
        Value::Array(items) => {
            let parts = items
                .iter()
                .map(|v| value_text(key, v))
                .collect::<PyResult<Vec<_>>>()?;
            format!("[{}]", parts.join(", "))
        }
        Value::Object(map) => {
            let parts = map
                .iter()
                .map(|(k, v)| Ok(format!("{} = {}", key_text(k), value_text(k, v)?)))
                .collect::<PyResult<Vec<_>>>()?;
            format!("{{ {} }}", parts.join(", "))
        }
    })
}
