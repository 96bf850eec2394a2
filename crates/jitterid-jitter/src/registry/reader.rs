//! The reads of a family's spec table beyond the registry's numbers and booleans: lists of
//! numbers and the terms of a composite family, with errors that name the key.

use super::{JitterRegistry, SpecReader, FAMILY_KEY, TERMS_KEY};
use crate::{AnyJitter, JitterError};
use jitterid_numeric::limits::{self, Limit};
use serde_json::Value;

/// Reads of a family's [`SpecReader`] that only jitter families need.
pub trait FamilyReader {
    /// The list of numbers at `key`; [`JitterError::MissingKey`] if absent.
    fn f64_list(&self, key: &str) -> Result<Vec<f64>, JitterError>;

    /// The terms of a composite family: every entry of `"terms"` built by `registry`, at
    /// least `min` of them and at most `limit`'s bound (checked before any is built). An error inside term `i` names its key as `terms.<i>.<key>`.
    fn terms(
        &self,
        registry: &JitterRegistry,
        min: usize,
        limit: Limit,
    ) -> Result<Vec<AnyJitter>, JitterError>;

    /// `error` from inside term `i`, its key prefixed with `terms.<i>.`.
    fn in_term(&self, i: usize, error: JitterError) -> JitterError;
}

impl FamilyReader for SpecReader<'_> {
    fn f64_list(&self, key: &str) -> Result<Vec<f64>, JitterError> {
        match self.get(key) {
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
            None => Err(self.missing(key)),
        }
    }

    fn terms(
        &self,
        registry: &JitterRegistry,
        min: usize,
        limit: Limit,
    ) -> Result<Vec<AnyJitter>, JitterError> {
        let list = match self.get(TERMS_KEY) {
            Some(Value::Array(list)) => list,
            Some(other) => {
                return Err(self.invalid(
                    TERMS_KEY,
                    format!("expected an array of tables, found {other}"),
                ))
            }
            None => return Err(self.missing(TERMS_KEY)),
        };
        if list.len() < min {
            return Err(self.invalid(
                TERMS_KEY,
                format!("expected at least {min} terms, found {}", list.len()),
            ));
        }
        limits::check(limit, list.len())?;
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

    fn in_term(&self, i: usize, error: JitterError) -> JitterError {
        let family = self.entry().to_string();
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
