//! Helpers that read and check a spec table's keys, for registries and their entries'
//! constructors. Each error names the offending key.
//!
//! [`SpecReader`] is the typed reader an entry's constructor gets: a table already checked
//! against the entry's keys, read key by key with errors in the registry's own error type
//! ([`SpecError`]). The free functions read a bare table with [`RegistryError`]s.

use crate::{ParamSpec, RegistryError, SpecError, SpecTable};
use serde_json::Value;
use std::fmt;
use std::marker::PhantomData;

/// A spec table with the keys of the entry it builds: typed reads of its keys, each error (in
/// the registry's error type `E`) naming the entry and the key. A registry hands one, checked
/// against the entry's keys, to the entry's constructor.
pub struct SpecReader<'a, E = RegistryError> {
    entry: &'a str,
    params: &'a [ParamSpec],
    table: &'a SpecTable,
    error: PhantomData<fn() -> E>,
}

impl<E> Clone for SpecReader<'_, E> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<E> Copy for SpecReader<'_, E> {}

impl<E> fmt::Debug for SpecReader<'_, E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SpecReader")
            .field("entry", &self.entry)
            .field("table", &self.table)
            .finish_non_exhaustive()
    }
}

impl<'a, E> SpecReader<'a, E> {
    /// `table` read as a table of the entry `entry` whose keys are `params` (unchecked: a
    /// registry checks the table's keys before it builds; see `Entry::reader`).
    pub fn new(entry: &'a str, params: &'a [ParamSpec], table: &'a SpecTable) -> Self {
        SpecReader {
            entry,
            params,
            table,
            error: PhantomData,
        }
    }

    /// The entry's name.
    pub fn entry(&self) -> &'a str {
        self.entry
    }

    /// The entry's keys.
    pub fn params(&self) -> &'a [ParamSpec] {
        self.params
    }

    /// The raw table.
    pub fn table(&self) -> &'a SpecTable {
        self.table
    }

    /// Whether the table has `key`.
    pub fn has(&self, key: &str) -> bool {
        self.table.contains_key(key)
    }

    /// The raw value at `key`.
    pub fn get(&self, key: &str) -> Option<&'a Value> {
        self.table.get(key)
    }

    /// The default of `key` ([`ParamSpec::default`]), if it is one of the entry's keys and has
    /// one.
    pub fn default_of(&self, key: &str) -> Option<f64> {
        self.params
            .iter()
            .find(|p| p.key == key)
            .and_then(|p| p.default)
    }
}

impl<E: SpecError> SpecReader<'_, E> {
    /// The error for `key`, with the message of `error`.
    pub fn invalid(&self, key: &str, error: impl fmt::Display) -> E {
        E::bad_value(self.entry, key, error.to_string())
    }

    /// The error for a missing `key`.
    pub fn missing(&self, key: &str) -> E {
        E::missing_key(self.entry, key)
    }

    /// The number at `key`, if present (not its default).
    pub fn opt_f64(&self, key: &str) -> Result<Option<f64>, E> {
        match self.table.get(key) {
            None => Ok(None),
            Some(Value::Number(n)) => match n.as_f64() {
                Some(x) if x.is_finite() => Ok(Some(x)),
                _ => Err(self.invalid(key, format!("expected a finite number, found {n}"))),
            },
            Some(other) => Err(self.invalid(key, format!("expected a number, found {other}"))),
        }
    }

    /// The number at `key`, or its default; a missing-key error if neither.
    pub fn f64(&self, key: &str) -> Result<f64, E> {
        match self.opt_f64(key)?.or_else(|| self.default_of(key)) {
            Some(x) => Ok(x),
            None => Err(self.missing(key)),
        }
    }

    /// The whole number in `0..=max` at `key`, or its default.
    pub fn u32(&self, key: &str, max: u32) -> Result<u32, E> {
        let x = self.f64(key)?;
        if x.fract() == 0.0 && x >= 0.0 && x <= f64::from(max) {
            // Exact: a whole number in [0, max] with max < 2^32.
            Ok(x as u32)
        } else {
            Err(self.invalid(
                key,
                format!("expected a whole number in [0, {max}], found {x}"),
            ))
        }
    }

    /// The boolean at `key`, or `default` when absent.
    pub fn bool_or(&self, key: &str, default: bool) -> Result<bool, E> {
        match self.table.get(key) {
            None => Ok(default),
            Some(Value::Bool(b)) => Ok(*b),
            Some(other) => Err(self.invalid(key, format!("expected true or false, found {other}"))),
        }
    }
}

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
    name_in(table, key)
}

/// The string under `key`, with the errors of `E`.
pub(crate) fn name_in<'a, E: SpecError>(table: &'a SpecTable, key: &str) -> Result<&'a str, E> {
    match table.get(key) {
        Some(Value::String(s)) => Ok(s),
        Some(other) => Err(E::not_a_name(key, other)),
        None => Err(E::missing_name(key)),
    }
}

/// Rejects keys of `table` that are neither `reserved` nor described by `specs`.
pub fn check_keys(
    table: &SpecTable,
    entry: &str,
    reserved: &[&str],
    specs: &[ParamSpec],
) -> Result<(), RegistryError> {
    let mut allowed = reserved.to_vec();
    allowed.extend(specs.iter().map(|s| s.key.as_str()));
    check_table(table, entry, specs, &allowed)
}

/// Rejects keys of `table` outside `allowed` with `E::unknown_key`.
pub(crate) fn check_table<E: SpecError>(
    table: &SpecTable,
    entry: &str,
    params: &[ParamSpec],
    allowed: &[&str],
) -> Result<(), E> {
    match table.keys().find(|k| !allowed.contains(&k.as_str())) {
        Some(key) => Err(E::unknown_key(entry, key, params, allowed)),
        None => Ok(()),
    }
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
    RegistryError::unknown_name(key, kind, name, known)
}
