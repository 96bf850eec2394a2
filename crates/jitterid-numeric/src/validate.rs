//! Validators of a constructor's real parameters: each returns the value or an
//! [`InvalidValue`] that names the parameter, which the crates above convert into their own
//! error types (`JitterError`, `SignalError`) with `?`.
//!
//! Every test is written so that NaN fails it (`!(x > 0.0)` rather than `x <= 0.0`).
//!
//! ```
//! use jitterid_numeric::validate::{finite, positive, InvalidValue, Problem};
//! assert_eq!(positive("amplitude", 0.5), Ok(0.5));
//! let e = positive("amplitude", 0.0).unwrap_err();
//! assert_eq!((e.name, e.problem), ("amplitude", Problem::NotPositive));
//! assert!(matches!(finite("offset", f64::NAN), Err(InvalidValue { problem: Problem::NotFinite, .. })));
//! ```

use thiserror::Error;

/// What is wrong with a value. Exhaustive on purpose: the error types that convert from
/// [`InvalidValue`] match every problem, so that a new one cannot go unconverted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Problem {
    /// NaN or infinite.
    NotFinite,
    /// Zero or negative where a strictly positive value is needed.
    NotPositive,
    /// Negative where a non-negative value is needed.
    Negative,
}

/// A parameter value that a validator rejected.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[error("`{name}` {}, got {value}", match .problem {
    Problem::NotFinite => "must be finite",
    Problem::NotPositive => "must be > 0",
    Problem::Negative => "must be >= 0",
})]
pub struct InvalidValue {
    /// The parameter's name.
    pub name: &'static str,
    /// The value given.
    pub value: f64,
    /// What is wrong with it.
    pub problem: Problem,
}

fn invalid(name: &'static str, value: f64, problem: Problem) -> InvalidValue {
    InvalidValue {
        name,
        value,
        problem,
    }
}

/// Checks that `value` is finite; the error names the parameter.
pub fn finite(name: &'static str, value: f64) -> Result<f64, InvalidValue> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(invalid(name, value, Problem::NotFinite))
    }
}

/// Checks that `value` is finite and strictly positive.
pub fn positive(name: &'static str, value: f64) -> Result<f64, InvalidValue> {
    if finite(name, value)? > 0.0 {
        Ok(value)
    } else {
        Err(invalid(name, value, Problem::NotPositive))
    }
}

/// Checks that `value` is finite and not negative.
pub fn non_negative(name: &'static str, value: f64) -> Result<f64, InvalidValue> {
    if finite(name, value)? >= 0.0 {
        Ok(value)
    } else {
        Err(invalid(name, value, Problem::Negative))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_validator_names_the_parameter_and_rejects_nan() {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for r in [finite("x", v), positive("x", v), non_negative("x", v)] {
                let e = r.unwrap_err();
                assert_eq!((e.name, e.problem), ("x", Problem::NotFinite));
            }
        }
        assert_eq!(
            positive("y", -1.0).unwrap_err().problem,
            Problem::NotPositive
        );
        assert_eq!(
            positive("y", 0.0).unwrap_err().problem,
            Problem::NotPositive
        );
        assert_eq!(non_negative("z", 0.0), Ok(0.0));
        assert_eq!(
            non_negative("z", -1e-300).unwrap_err().problem,
            Problem::Negative
        );
        assert_eq!(
            positive("amplitude", -2.0).unwrap_err().to_string(),
            "`amplitude` must be > 0, got -2"
        );
    }
}
