//! Helpers that read and check a spec table's keys, for registries and their entries'
//! constructors. Each error names the offending key.

use crate::{ParamSpec, RegistryError, SpecTable};
use serde_json::Value;

/// A real-valued key, required when `default` is `None`.
pub fn real(
    key: &str,
    meaning: &str,
    unit: &str,
    constraint: &str,
    default: Option<f64>,
) -> ParamSpec {
    let spec = ParamSpec::new(key, meaning, unit, constraint);
    match default {
        Some(v) => spec.with_default(v),
        None => spec,
    }
}

/// A whole-number key, required when `default` is `None`.
pub fn whole(key: &str, meaning: &str, constraint: &str, default: Option<f64>) -> ParamSpec {
    real(key, meaning, "", constraint, default).integer()
}

/// The string under `key`.
pub fn name_at<'a>(table: &'a SpecTable, key: &str) -> Result<&'a str, RegistryError> {
    match table.get(key) {
        Some(Value::String(s)) => Ok(s),
        Some(other) => Err(RegistryError::bad(
            key,
            format!("expected a name, got {other}"),
        )),
        None => Err(RegistryError::MissingKey {
            key: key.to_string(),
            entry: "the table".to_string(),
        }),
    }
}

/// Rejects keys of `table` that are neither `reserved` nor described by `specs`.
pub fn check_keys(
    table: &SpecTable,
    entry: &str,
    reserved: &[&str],
    specs: &[ParamSpec],
) -> Result<(), RegistryError> {
    for key in table.keys() {
        if !reserved.contains(&key.as_str()) && !specs.iter().any(|s| s.key == *key) {
            return Err(RegistryError::UnknownKey {
                key: key.clone(),
                entry: entry.to_string(),
                known: specs
                    .iter()
                    .map(|s| s.key.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
    }
    Ok(())
}

/// The number under `spec.key`, or its default.
pub fn number(table: &SpecTable, spec: &ParamSpec, entry: &str) -> Result<f64, RegistryError> {
    let key = spec.key.as_str();
    match table.get(key) {
        Some(v) => {
            let x = v
                .as_f64()
                .ok_or_else(|| RegistryError::bad(key, format!("expected a number, got {v}")))?;
            if spec.integer && x.fract() != 0.0 {
                return Err(RegistryError::bad(
                    key,
                    format!("expected a whole number, got {x}"),
                ));
            }
            Ok(x)
        }
        None => spec.default.ok_or_else(|| RegistryError::MissingKey {
            key: key.to_string(),
            entry: entry.to_string(),
        }),
    }
}

/// The whole number under `spec.key` (non-negative), or its default.
pub fn count(table: &SpecTable, spec: &ParamSpec, entry: &str) -> Result<u64, RegistryError> {
    let x = number(table, spec, entry)?;
    if !(x >= 0.0 && x <= u64::MAX as f64) {
        return Err(RegistryError::bad(
            &spec.key,
            format!("expected a whole number >= 0, got {x}"),
        ));
    }
    Ok(x as u64)
}

/// The list of numbers under `key` (empty when absent).
pub fn numbers(table: &SpecTable, key: &str) -> Result<Vec<f64>, RegistryError> {
    match table.get(key) {
        None => Ok(Vec::new()),
        Some(Value::Array(items)) => items
            .iter()
            .map(|v| {
                v.as_f64()
                    .ok_or_else(|| RegistryError::bad(key, format!("expected numbers, got {v}")))
            })
            .collect(),
        Some(other) => Err(RegistryError::bad(
            key,
            format!("expected a list of numbers, got {other}"),
        )),
    }
}

/// A registry's error for an unknown `name` under `key`.
pub fn unknown(key: &str, kind: &'static str, name: &str, known: &[&str]) -> RegistryError {
    RegistryError::UnknownName {
        key: key.to_string(),
        kind,
        name: name.to_string(),
        known: known.join(", "),
    }
}
