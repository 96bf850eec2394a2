//! The reads of a kind's spec table beyond the registry's numbers and booleans: lists of
//! numbers, flags and roots, with errors that name the key.

use super::SpecReader;
use crate::{Root, SignalError};
use serde_json::Value;

/// Reads of a kind's [`SpecReader`] that only signal kinds need.
pub trait KindReader {
    /// A boolean (false when absent).
    fn flag(&self, key: &str) -> Result<bool, SignalError>;

    /// A list of numbers (empty when absent).
    fn f64_list(&self, key: &str) -> Result<Vec<f64>, SignalError>;

    /// A list of roots: numbers (real roots) and `[re, im]` pairs (empty when absent).
    fn roots(&self, key: &str) -> Result<Vec<Root>, SignalError>;
}

/// The number `v` at `key`.
fn number(r: &SpecReader<'_>, key: &str, v: &Value) -> Result<f64, SignalError> {
    v.as_f64()
        .ok_or_else(|| r.invalid(key, format!("expected a number, found {v}")))
}

impl KindReader for SpecReader<'_> {
    fn flag(&self, key: &str) -> Result<bool, SignalError> {
        self.bool_or(key, false)
    }

    fn f64_list(&self, key: &str) -> Result<Vec<f64>, SignalError> {
        match self.get(key) {
            None => Ok(Vec::new()),
            Some(Value::Array(a)) => a.iter().map(|v| number(self, key, v)).collect(),
            Some(v) => Err(self.invalid(key, format!("expected a list of numbers, found {v}"))),
        }
    }

    fn roots(&self, key: &str) -> Result<Vec<Root>, SignalError> {
        let root = |v: &Value| Root::from_json(v).map_err(|m| self.invalid(key, m));
        match self.get(key) {
            None => Ok(Vec::new()),
            Some(Value::Array(a)) => a.iter().map(root).collect(),
            Some(v) => Err(self.invalid(
                key,
                format!("expected a list of roots (numbers, [re, im] or {{a1, a0}}), found {v}"),
            )),
        }
    }
}
