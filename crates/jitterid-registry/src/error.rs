use crate::ParamSpec;
use serde_json::Value;
use thiserror::Error;

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
    /// An entry that needs a build context was built without one.
    #[error("`{entry}` needs a build context, but none was given")]
    MissingContext {
        /// The entry's name.
        entry: String,
    },
    /// An entry without a constructor from one number was asked for one.
    #[error("`{entry}` cannot be built from a single number")]
    NoScaledForm {
        /// The entry's name.
        entry: String,
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
            RegistryError::Duplicate { .. }
            | RegistryError::MissingContext { .. }
            | RegistryError::NoScaledForm { .. } => None,
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

/// The error type a registry reports in: each finding of a [`Registry`](crate::Registry) (a
/// name it cannot read or does not hold, a key an entry does not take, …) and of a
/// [`SpecReader`](crate::SpecReader) becomes a value of the registry's own error type, so that
/// a crate's registry keeps its crate's typed error (and its wording). [`RegistryError`] is the
/// default.
pub trait SpecError: Sized {
    /// The registry key (`key`) holds something other than a name (`found`).
    fn not_a_name(key: &str, found: &Value) -> Self;
    /// The table has no registry key `key`.
    fn missing_name(key: &str) -> Self;
    /// `name` under `key` names no entry of the registry (a `kind` of thing); `known` are the
    /// registered names.
    fn unknown_name(key: &str, kind: &'static str, name: &str, known: &[&str]) -> Self;
    /// `key` is not a key of `entry`, whose own keys are `params` and whose tables may hold the
    /// keys `allowed` (the registry key, `params`, nested tables, the registry's common keys).
    fn unknown_key(entry: &str, key: &str, params: &[ParamSpec], allowed: &[&str]) -> Self;
    /// `entry` needs `key`, which the table lacks.
    fn missing_key(entry: &str, key: &str) -> Self;
    /// The value at `key` of `entry`'s table is of the wrong type or outside its domain.
    fn bad_value(entry: &str, key: &str, message: String) -> Self;
    /// `name` is already registered.
    fn duplicate(name: &str) -> Self;
    /// `entry` needs a build context and none was given.
    fn missing_context(entry: &str) -> Self;
    /// `entry` has no constructor from one number.
    fn no_scaled_form(entry: &str) -> Self;
}

impl SpecError for RegistryError {
    fn not_a_name(key: &str, found: &Value) -> Self {
        RegistryError::bad(key, format!("expected a name, got {found}"))
    }

    fn missing_name(key: &str) -> Self {
        RegistryError::MissingKey {
            key: key.to_string(),
            entry: "the table".to_string(),
        }
    }

    fn unknown_name(key: &str, kind: &'static str, name: &str, known: &[&str]) -> Self {
        RegistryError::UnknownName {
            key: key.to_string(),
            kind,
            name: name.to_string(),
            known: known.join(", "),
        }
    }

    fn unknown_key(entry: &str, key: &str, params: &[ParamSpec], _: &[&str]) -> Self {
        RegistryError::UnknownKey {
            key: key.to_string(),
            entry: entry.to_string(),
            known: params
                .iter()
                .map(|s| s.key.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        }
    }

    fn missing_key(entry: &str, key: &str) -> Self {
        RegistryError::MissingKey {
            key: key.to_string(),
            entry: entry.to_string(),
        }
    }

    fn bad_value(_: &str, key: &str, message: String) -> Self {
        RegistryError::BadValue {
            key: key.to_string(),
            message,
        }
    }

    fn duplicate(name: &str) -> Self {
        RegistryError::Duplicate {
            name: name.to_string(),
        }
    }

    fn missing_context(entry: &str) -> Self {
        RegistryError::MissingContext {
            entry: entry.to_string(),
        }
    }

    fn no_scaled_form(entry: &str) -> Self {
        RegistryError::NoScaledForm {
            entry: entry.to_string(),
        }
    }
}
