//! [`ParamSpec`]: one key of a spec table, described for a reader.

use serde::Serialize;

/// One key of a spec table (a jitter family's, a signal's, a noise model's, a criterion's, a
/// solver's), described for a reader (and for generated docs and help).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParamSpec {
    /// The key, as written in a spec table (for example `"sigma"`).
    pub key: String,
    /// What it means.
    pub meaning: String,
    /// Its unit (`"s"`, or `""` for a pure number).
    pub unit: String,
    /// The values it accepts, written for a reader (for example `"> 0"`).
    pub constraint: String,
    /// Whether it is a whole number (structural, not estimated: profiled instead).
    pub integer: bool,
    /// Whether it is a boolean (its default, if any, is 0 for false and 1 for true).
    pub boolean: bool,
    /// The value taken when the key is absent; `None` when the key is required.
    pub default: Option<f64>,
}

impl ParamSpec {
    /// A required real key.
    pub fn new(
        key: impl Into<String>,
        meaning: impl Into<String>,
        unit: impl Into<String>,
        constraint: impl Into<String>,
    ) -> Self {
        ParamSpec {
            key: key.into(),
            meaning: meaning.into(),
            unit: unit.into(),
            constraint: constraint.into(),
            integer: false,
            boolean: false,
            default: None,
        }
    }

    /// The same key, holding a whole number.
    pub fn integer(mut self) -> Self {
        self.integer = true;
        self
    }

    /// The same key, holding `true` or `false`, optional with this default.
    pub fn boolean(mut self, default: bool) -> Self {
        self.boolean = true;
        self.default = Some(if default { 1.0 } else { 0.0 });
        self
    }

    /// The same key, optional with this default.
    pub fn with_default(mut self, value: f64) -> Self {
        self.default = Some(value);
        self
    }
}
