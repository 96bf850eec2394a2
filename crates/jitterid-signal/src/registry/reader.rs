//! Typed reading of a kind's spec table, with errors that name the key.

use super::{SignalKind, Spec, KIND_KEY};
use crate::{Root, SignalError};
use serde_json::Value;

/// A spec table checked against its kind's keys: no unknown key, every required key present.
#[derive(Debug)]
pub struct SpecReader<'a> {
    kind: &'a SignalKind,
    spec: &'a Spec,
}

impl<'a> SpecReader<'a> {
    /// Checks `spec` against `kind`'s keys.
    pub fn new(kind: &'a SignalKind, spec: &'a Spec) -> Result<Self, SignalError> {
        for key in spec.keys() {
            if key != KIND_KEY && !kind.params().iter().any(|p| &p.key == key) {
                return Err(SignalError::UnexpectedKey {
                    kind: kind.name().into(),
                    key: key.clone(),
                    known: kind
                        .params()
                        .iter()
                        .map(|p| p.key.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                });
            }
        }
        for p in kind.params() {
            if p.default.is_none()
                && !p.constraint.starts_with("optional")
                && !spec.contains_key(&p.key)
            {
                return Err(SignalError::MissingKey {
                    kind: kind.name().into(),
                    key: p.key.clone(),
                });
            }
        }
        Ok(SpecReader { kind, spec })
    }

    /// The error for `key`, with `error` as its message.
    pub fn invalid(&self, key: &str, error: impl std::fmt::Display) -> SignalError {
        SignalError::InvalidKey {
            kind: self.kind.name().into(),
            key: key.into(),
            message: error.to_string(),
        }
    }

    fn number(&self, key: &str, v: &Value) -> Result<f64, SignalError> {
        v.as_f64()
            .ok_or_else(|| self.invalid(key, format!("expected a number, found {v}")))
    }

    /// Whether the table has `key`.
    pub fn has(&self, key: &str) -> bool {
        self.spec.contains_key(key)
    }

    /// A number; its default when absent.
    pub fn f64(&self, key: &str) -> Result<f64, SignalError> {
        match self.spec.get(key) {
            Some(v) => self.number(key, v),
            None => self
                .kind
                .params()
                .iter()
                .find(|p| p.key == key)
                .and_then(|p| p.default)
                .ok_or_else(|| SignalError::MissingKey {
                    kind: self.kind.name().into(),
                    key: key.into(),
                }),
        }
    }

    /// A boolean (false when absent).
    pub fn flag(&self, key: &str) -> Result<bool, SignalError> {
        match self.spec.get(key) {
            None => Ok(false),
            Some(Value::Bool(b)) => Ok(*b),
            Some(v) => Err(self.invalid(key, format!("expected true or false, found {v}"))),
        }
    }

    /// A list of numbers (empty when absent).
    pub fn f64_list(&self, key: &str) -> Result<Vec<f64>, SignalError> {
        match self.spec.get(key) {
            None => Ok(Vec::new()),
            Some(Value::Array(a)) => a.iter().map(|v| self.number(key, v)).collect(),
            Some(v) => Err(self.invalid(key, format!("expected a list of numbers, found {v}"))),
        }
    }

    /// A list of roots: numbers (real roots) and `[re, im]` pairs (empty when absent).
    pub fn roots(&self, key: &str) -> Result<Vec<Root>, SignalError> {
        let root = |v: &Value| match v {
            Value::Array(a) if a.len() == 2 => Ok(Root::Pair {
                re: self.number(key, &a[0])?,
                im: self.number(key, &a[1])?,
            }),
            other => self.number(key, other).map(Root::Real),
        };
        match self.spec.get(key) {
            None => Ok(Vec::new()),
            Some(Value::Array(a)) => a.iter().map(root).collect(),
            Some(v) => Err(self.invalid(
                key,
                format!("expected a list of roots (numbers or [re, im]), found {v}"),
            )),
        }
    }
}
