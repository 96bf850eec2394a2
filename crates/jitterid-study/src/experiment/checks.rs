//! Checks shared by the section parsers: required keys, keys that belong to another kind, and
//! finite numbers, each refused with the key named.

use super::diagnostics::Source;
use super::range;
use crate::error::StudyResult;
use std::ops::Range;
use toml::Spanned;

impl Source<'_> {
    /// Rejects keys that exist in the section but do not apply to the chosen kind.
    pub(super) fn only(
        &self,
        section: &str,
        present: &[(&'static str, Range<usize>)],
        selector: &str,
        allowed: &[&str],
        what: &str,
    ) -> StudyResult<()> {
        for (k, span) in present {
            if !allowed.contains(k) {
                return Err(self.err(
                    section,
                    k,
                    span,
                    format!(
                        "not a key of {selector} = \"{what}\"; expected {}",
                        allowed.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    pub(super) fn required<'v, T>(
        &self,
        section: &str,
        key: &str,
        v: &'v Option<Spanned<T>>,
        why: &str,
    ) -> StudyResult<&'v Spanned<T>> {
        v.as_ref()
            .ok_or_else(|| self.err_section(section, key, format!("missing; {why}")))
    }

    pub(super) fn finite(&self, section: &str, key: &str, v: &Spanned<f64>) -> StudyResult<f64> {
        self.checked(section, key, v, Ok)
    }

    /// A finite value that `check` accepts; its message names the key.
    pub(super) fn checked(
        &self,
        section: &str,
        key: &str,
        v: &Spanned<f64>,
        check: impl FnOnce(f64) -> Result<f64, String>,
    ) -> StudyResult<f64> {
        finite_value(*v.get_ref())
            .and_then(check)
            .map_err(|m| self.err(section, key, &v.span(), m))
    }

    /// An optional finite value that `check` accepts, or `default`.
    pub(super) fn opt_checked(
        &self,
        section: &str,
        key: &str,
        v: &Option<Spanned<f64>>,
        default: f64,
        check: impl FnOnce(f64) -> Result<f64, String>,
    ) -> StudyResult<f64> {
        v.as_ref()
            .map_or(Ok(default), |v| self.checked(section, key, v, check))
    }

    /// A list whose every element `check` accepts; the message names the element.
    pub(super) fn checked_list(
        &self,
        section: &str,
        key: &str,
        v: &Spanned<Vec<f64>>,
        check: impl Fn(f64) -> Result<f64, String>,
    ) -> StudyResult<Vec<f64>> {
        v.get_ref()
            .iter()
            .enumerate()
            .map(|(i, x)| {
                check(*x).map_err(|m| {
                    self.err(section, key, &v.span(), format!("element {}: {m}", i + 1))
                })
            })
            .collect()
    }

    /// A list of finite levels (see [`range::level`]).
    pub(super) fn level_list(
        &self,
        section: &str,
        key: &str,
        v: &Spanned<Vec<f64>>,
    ) -> StudyResult<Vec<f64>> {
        self.checked_list(section, key, v, |x| finite_value(x).and_then(range::level))
    }

    pub(super) fn positive(&self, section: &str, key: &str, v: &Spanned<f64>) -> StudyResult<f64> {
        let x = self.finite(section, key, v)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(
                section,
                key,
                &v.span(),
                format!("expected a number > 0, found {x}"),
            ))
        }
    }

    pub(super) fn opt_finite(
        &self,
        section: &str,
        key: &str,
        v: &Option<Spanned<f64>>,
        default: f64,
    ) -> StudyResult<f64> {
        self.opt_checked(section, key, v, default, Ok)
    }

    pub(super) fn finite_list(
        &self,
        section: &str,
        key: &str,
        v: &Spanned<Vec<f64>>,
    ) -> StudyResult<Vec<f64>> {
        self.checked_list(section, key, v, finite_value)
    }
}

/// `x` if it is finite.
pub(super) fn finite_value(x: f64) -> Result<f64, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("expected a finite number, found {x}"))
    }
}

pub(super) fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

pub(super) fn describe(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => format!("the string {s:?}"),
        toml::Value::Integer(i) => format!("the integer {i}"),
        toml::Value::Float(x) => format!("the number {x}"),
        toml::Value::Boolean(b) => format!("the boolean {b}"),
        toml::Value::Datetime(d) => format!("the date {d}"),
        toml::Value::Array(a) => format!("an array of {} element(s)", a.len()),
        toml::Value::Table(_) => "a table".to_string(),
    }
}

/// Values of a table read without a fixed set of keys (a section whose keys depend on a
/// choice made in it): each read names the key when the type is wrong.
impl Source<'_> {
    fn wrong_type(
        &self,
        section: &str,
        key: &str,
        v: &Spanned<toml::Value>,
        what: &str,
    ) -> crate::error::StudyError {
        self.err(
            section,
            key,
            &v.span(),
            format!("expected {what}, found {}", describe(v.get_ref())),
        )
    }

    /// `true` or `false`.
    pub(super) fn bool_value(
        &self,
        section: &str,
        key: &str,
        v: &Spanned<toml::Value>,
    ) -> StudyResult<bool> {
        match v.get_ref() {
            toml::Value::Boolean(b) => Ok(*b),
            _ => Err(self.wrong_type(section, key, v, "true or false")),
        }
    }

    /// A string.
    pub(super) fn string_value<'v>(
        &self,
        section: &str,
        key: &str,
        v: &'v Spanned<toml::Value>,
    ) -> StudyResult<&'v str> {
        match v.get_ref() {
            toml::Value::String(s) => Ok(s),
            _ => Err(self.wrong_type(section, key, v, "a string")),
        }
    }
}
