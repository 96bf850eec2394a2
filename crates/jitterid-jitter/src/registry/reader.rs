//! Reading a family's keys from a spec table, with errors that name the key.

use super::{Family, JitterRegistry, Spec, FAMILY_KEY, TERMS_KEY};
use crate::{AnyJitter, JitterError};
use serde_json::Value;

/// A spec table checked against its family's keys, with typed readers.
#[derive(Debug, Clone, Copy)]
pub struct SpecReader<'a> {
    family: &'a Family,
    spec: &'a Spec,
}

impl<'a> SpecReader<'a> {
    /// Checks that `spec` holds no key that `family` does not take.
    pub fn new(family: &'a Family, spec: &'a Spec) -> Result<Self, JitterError> {
        let keys = family.keys();
        if let Some(key) = spec.keys().find(|k| !keys.contains(&k.as_str())) {
            return Err(JitterError::UnexpectedKey {
                family: family.name().to_string(),
                key: key.clone(),
                allowed: keys
                    .iter()
                    .map(|k| format!("`{k}`"))
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        Ok(SpecReader { family, spec })
    }

    /// The family's name.
    pub fn family(&self) -> &str {
        self.family.name()
    }

    /// The raw table.
    pub fn spec(&self) -> &Spec {
        self.spec
    }

    /// An [`JitterError::InvalidKey`] for `key` carrying the message of `error`.
    pub fn invalid(&self, key: &str, error: impl std::fmt::Display) -> JitterError {
        JitterError::InvalidKey {
            family: self.family().to_string(),
            key: key.to_string(),
            message: error.to_string(),
        }
    }

    fn default_of(&self, key: &str) -> Option<f64> {
        self.family
            .params()
            .iter()
            .find(|p| p.key == key)
            .and_then(|p| p.default)
    }

    /// The number at `key`, if present (not its default).
    pub fn opt_f64(&self, key: &str) -> Result<Option<f64>, JitterError> {
        match self.spec.get(key) {
            None => Ok(None),
            Some(Value::Number(n)) => match n.as_f64() {
                Some(x) if x.is_finite() => Ok(Some(x)),
                _ => Err(self.invalid(key, format!("expected a finite number, found {n}"))),
            },
            Some(other) => Err(self.invalid(key, format!("expected a number, found {other}"))),
        }
    }

    /// The number at `key`, or its default; [`JitterError::MissingKey`] if neither.
    pub fn f64(&self, key: &str) -> Result<f64, JitterError> {
        match self.opt_f64(key)?.or_else(|| self.default_of(key)) {
            Some(x) => Ok(x),
            None => Err(JitterError::MissingKey {
                family: self.family().to_string(),
                key: key.to_string(),
            }),
        }
    }

    /// The whole number in `0..=max` at `key`, or its default.
    pub fn u32(&self, key: &str, max: u32) -> Result<u32, JitterError> {
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

    /// The list of numbers at `key`; [`JitterError::MissingKey`] if absent.
    pub fn f64_list(&self, key: &str) -> Result<Vec<f64>, JitterError> {
        match self.spec.get(key) {
            Some(Value::Array(items)) => items
                .iter()
                .map(|v| match v.as_f64() {
                    Some(x) if x.is_finite() => Ok(x),
                    _ => Err(self.invalid(key, format!("expected finite numbers, found {v}"))),
                })
                .collect(),
            Some(other) => {
                Err(self.invalid(key, format!("expected an array of numbers, found {other}")))
            }
            None => Err(JitterError::MissingKey {
                family: self.family().to_string(),
                key: key.to_string(),
            }),
        }
    }

    /// The boolean at `key`, or `default` when absent.
    pub fn bool_or(&self, key: &str, default: bool) -> Result<bool, JitterError> {
        match self.spec.get(key) {
            None => Ok(default),
            Some(Value::Bool(b)) => Ok(*b),
            Some(other) => Err(self.invalid(key, format!("expected true or false, found {other}"))),
        }
    }

    /// The terms of a composite family: every entry of `"terms"` built by `registry`, at
    /// least `min` of them. An error inside term `i` names its key as `terms.<i>.<key>`.
    pub fn terms(
        &self,
        registry: &JitterRegistry,
        min: usize,
    ) -> Result<Vec<AnyJitter>, JitterError> {
        let list = match self.spec.get(TERMS_KEY) {
            Some(Value::Array(list)) => list,
            Some(other) => {
                return Err(self.invalid(
                    TERMS_KEY,
                    format!("expected an array of tables, found {other}"),
                ))
            }
            None => {
                return Err(JitterError::MissingKey {
                    family: self.family().to_string(),
                    key: TERMS_KEY.into(),
                })
            }
        };
        if list.len() < min {
            return Err(self.invalid(
                TERMS_KEY,
                format!("expected at least {min} terms, found {}", list.len()),
            ));
        }
        list.iter()
            .enumerate()
            .map(|(i, term)| {
                let Value::Object(spec) = term else {
                    return Err(self.invalid(
                        &format!("{TERMS_KEY}.{i}"),
                        format!("expected a table with a `{FAMILY_KEY}` key, found {term}"),
                    ));
                };
                registry.build(spec).map_err(|e| self.in_term(i, e))
            })
            .collect()
    }

    /// `error` from inside term `i`, its key prefixed with `terms.<i>.`.
    pub fn in_term(&self, i: usize, error: JitterError) -> JitterError {
        let family = self.family().to_string();
        let key = |k: &str| format!("{TERMS_KEY}.{i}.{k}");
        match error {
            JitterError::MissingKey { key: k, .. } => JitterError::MissingKey {
                family,
                key: key(&k),
            },
            JitterError::UnexpectedKey {
                key: k, allowed, ..
            } => JitterError::UnexpectedKey {
                family,
                key: key(&k),
                allowed,
            },
            JitterError::InvalidKey {
                key: k,
                message,
                family: inner,
            } => JitterError::InvalidKey {
                family,
                key: key(&k),
                message: if inner.is_empty() {
                    message
                } else {
                    format!("{inner}: {message}")
                },
            },
            JitterError::UnknownFamily { family: f, known } => JitterError::InvalidKey {
                family,
                key: key(FAMILY_KEY),
                message: format!("unknown jitter family \"{f}\"; expected one of {known}"),
            },
            other => match other.key().map(str::to_string) {
                Some(k) => JitterError::InvalidKey {
                    family,
                    key: key(&k),
                    message: other.to_string(),
                },
                None => other,
            },
        }
    }
}
