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
