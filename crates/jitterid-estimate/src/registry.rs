//! The crate's run-time registries (noise models, criteria, solvers) share one shape: a
//! [`Registry`] of [`Entry`]s, each describing its keys with [`ParamSpec`], built from a spec
//! table (`serde_json::Map`), with errors ([`RegistryError`]) that name the offending key.
//!
//! Front ends (the command line's TOML tables, Python keyword arguments) convert their input to
//! a spec table and build from it; every value goes through the constructor of the type it
//! builds, so a registry accepts exactly what the library accepts.

use serde_json::{Map, Value};
use std::fmt;
use std::sync::Arc;
use thiserror::Error;

/// A spec table: key/value construction input.
pub type SpecTable = Map<String, Value>;

pub use jitterid_jitter::registry::ParamSpec;

/// A real-valued key, required when `default` is `None`.
pub(crate) fn real(
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
pub(crate) fn whole(key: &str, meaning: &str, constraint: &str, default: Option<f64>) -> ParamSpec {
    real(key, meaning, "", constraint, default).integer()
}

/// Why a registry could not build from a spec table. Each variant names the offending key.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RegistryError {
    /// The name under `key` is not registered.
    #[error("`{key}`: unknown {kind} `{name}` (known: {known})")]
    UnknownName {
        /// The key holding the name (`"noise"`, `"criterion"`, `"solver"`).
        key: String,
        /// What kind of thing was asked for.
        kind: &'static str,
        /// The name given.
        name: String,
        /// The registered names, comma-separated.
        known: String,
    },
    /// A key the entry does not take.
    #[error("`{key}`: not a key of {entry} (keys: {known})")]
    UnknownKey {
        /// The key given.
        key: String,
        /// The entry's name.
        entry: String,
        /// The keys it takes, comma-separated.
        known: String,
    },
    /// A required key is absent.
    #[error("`{key}`: required by {entry}")]
    MissingKey {
        /// The key.
        key: String,
        /// The entry's name.
        entry: String,
    },
    /// A value of the wrong type or outside its domain.
    #[error("`{key}`: {message}")]
    BadValue {
        /// The key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A name registered twice.
    #[error("`{name}` is already registered")]
    Duplicate {
        /// The name.
        name: String,
    },
}

impl RegistryError {
    /// The key this error points at, for front ends that locate it in their input.
    pub fn key(&self) -> Option<&str> {
        match self {
            RegistryError::UnknownName { key, .. }
            | RegistryError::UnknownKey { key, .. }
            | RegistryError::MissingKey { key, .. }
            | RegistryError::BadValue { key, .. } => Some(key),
            RegistryError::Duplicate { .. } => None,
        }
    }

    /// A value error at `key`.
    pub fn bad(key: &str, message: impl std::fmt::Display) -> Self {
        RegistryError::BadValue {
            key: key.to_string(),
            message: message.to_string(),
        }
    }
}

type Build<T> = dyn Fn(&SpecTable) -> Result<T, RegistryError> + Send + Sync;

/// After-build step of a registry: gets the spec table and the built value (for example the
/// solver registry's multi-start wrapper).
type Wrap<T> = fn(&SpecTable, T) -> Result<T, RegistryError>;

/// One registered choice: its name, what it is, its keys and how to build it.
pub struct Entry<T> {
    /// Registry name.
    pub name: &'static str,
    /// One line on what it is for and what it requires.
    pub summary: &'static str,
    /// Its keys (besides the registry's own key).
    pub params: Vec<ParamSpec>,
    build: Arc<Build<T>>,
}

impl<T> Clone for Entry<T> {
    fn clone(&self) -> Self {
        Entry {
            name: self.name,
            summary: self.summary,
            params: self.params.clone(),
            build: Arc::clone(&self.build),
        }
    }
}

impl<T> fmt::Debug for Entry<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Entry")
            .field("name", &self.name)
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl<T> Entry<T> {
    /// An entry; `build` receives the whole spec table, its keys already checked against
    /// `params`.
    pub fn new(
        name: &'static str,
        summary: &'static str,
        params: Vec<ParamSpec>,
        build: impl Fn(&SpecTable) -> Result<T, RegistryError> + Send + Sync + 'static,
    ) -> Self {
        Entry {
            name,
            summary,
            params,
            build: Arc::new(build),
        }
    }
}

/// Registered choices of one kind (noise models, criteria, solvers), by name. A spec table
/// names its choice under the registry's [`key`](Self::key) and holds the entry's keys.
pub struct Registry<T> {
    key: &'static str,
    kind: &'static str,
    reserved: Vec<ParamSpec>,
    wrap: Option<Wrap<T>>,
    entries: Vec<Entry<T>>,
}

impl<T> Clone for Registry<T> {
    fn clone(&self) -> Self {
        Registry {
            key: self.key,
            kind: self.kind,
            reserved: self.reserved.clone(),
            wrap: self.wrap,
            entries: self.entries.clone(),
        }
    }
}

impl<T> fmt::Debug for Registry<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Registry")
            .field("key", &self.key)
            .field("entries", &self.entries)
            .finish_non_exhaustive()
    }
}

impl<T> Registry<T> {
    /// An empty registry whose tables name their choice under `key` (a `kind` of thing, for
    /// messages); `reserved` are keys every entry takes, handled by `wrap` after the build.
    pub(crate) fn empty(
        key: &'static str,
        kind: &'static str,
        reserved: Vec<ParamSpec>,
        wrap: Option<Wrap<T>>,
    ) -> Self {
        Registry {
            key,
            kind,
            reserved,
            wrap,
            entries: Vec::new(),
        }
    }

    /// The key that names the choice in a spec table (`"noise"`, `"criterion"`, `"solver"`).
    pub fn key(&self) -> &'static str {
        self.key
    }

    /// Keys every entry takes besides its own (the solvers' multi-start keys).
    pub fn common_keys(&self) -> &[ParamSpec] {
        &self.reserved
    }

    /// Adds an entry of the crate's own (names known to be distinct).
    pub(crate) fn insert(&mut self, entry: Entry<T>) {
        self.entries.push(entry);
    }

    /// Adds an entry.
    ///
    /// # Errors
    ///
    /// [`RegistryError::Duplicate`] if the name is taken.
    pub fn register(&mut self, entry: Entry<T>) -> Result<(), RegistryError> {
        if self.entry(entry.name).is_some() {
            return Err(RegistryError::Duplicate {
                name: entry.name.to_string(),
            });
        }
        self.entries.push(entry);
        Ok(())
    }

    /// The entry called `name`.
    pub fn entry(&self, name: &str) -> Option<&Entry<T>> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// All entries, in registration order.
    pub fn entries(&self) -> &[Entry<T>] {
        &self.entries
    }

    /// Builds the choice named under [`key`](Self::key) from its keys.
    ///
    /// # Errors
    ///
    /// A [`RegistryError`] naming the offending key: an unknown name, a key the entry does
    /// not take, a missing key, a value of the wrong type or outside its domain.
    pub fn build(&self, table: &SpecTable) -> Result<T, RegistryError> {
        let name = name_at(table, self.key)?;
        let entry = self.entry(name).ok_or_else(|| {
            let names: Vec<&str> = self.entries.iter().map(|e| e.name).collect();
            unknown(self.key, self.kind, name, &names)
        })?;
        let mut reserved = vec![self.key];
        reserved.extend(self.reserved.iter().map(|s| s.key.as_str()));
        check_keys(table, entry.name, &reserved, &entry.params)?;
        let value = (entry.build)(table)?;
        match self.wrap {
            Some(wrap) => wrap(table, value),
            None => Ok(value),
        }
    }
}

/// The string under `key`.
pub(crate) fn name_at<'a>(table: &'a SpecTable, key: &str) -> Result<&'a str, RegistryError> {
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
pub(crate) fn check_keys(
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
pub(crate) fn number(
    table: &SpecTable,
    spec: &ParamSpec,
    entry: &str,
) -> Result<f64, RegistryError> {
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
pub(crate) fn count(
    table: &SpecTable,
    spec: &ParamSpec,
    entry: &str,
) -> Result<u64, RegistryError> {
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
pub(crate) fn numbers(table: &SpecTable, key: &str) -> Result<Vec<f64>, RegistryError> {
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
pub(crate) fn unknown(key: &str, kind: &'static str, name: &str, known: &[&str]) -> RegistryError {
    RegistryError::UnknownName {
        key: key.to_string(),
        kind,
        name: name.to_string(),
        known: known.join(", "),
    }
}
