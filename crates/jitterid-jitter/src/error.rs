use thiserror::Error;

/// Why a jitter model could not be built from the given parameters.
///
/// Every variant names the parameter and the offending value, so that a message built from
/// it can be shown to a user as it is.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum JitterError {
    /// A parameter was NaN or infinite.
    #[error("jitter parameter `{name}` must be finite, got {value}")]
    NotFinite {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A parameter that must be strictly positive was zero or negative.
    #[error("jitter parameter `{name}` must be > 0, got {value}")]
    NotPositive {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A parameter that must be non-negative was negative.
    #[error("jitter parameter `{name}` must be >= 0, got {value}")]
    Negative {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A parameter was outside its allowed range.
    #[error("jitter parameter `{name}` must lie in {range}, got {value}")]
    OutOfRange {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range, written for a reader (for example `[0, 1]`).
        range: &'static str,
    },
    /// A parameter vector of the wrong length was given to `with_params`.
    #[error("jitter model `{model}` takes {expected} parameter(s), got {got}")]
    WrongParamCount {
        /// The model's name.
        model: &'static str,
        /// How many it takes.
        expected: usize,
        /// How many were given.
        got: usize,
    },
}

/// Checks that `value` is finite; the error names the parameter.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, JitterError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(JitterError::NotFinite { name, value })
    }
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, JitterError> {
    if finite(name, value)? > 0.0 {
        Ok(value)
    } else {
        Err(JitterError::NotPositive { name, value })
    }
}

/// Checks that `value` is finite and not negative.
// No built-in family has a parameter that may be 0; kept for the next one that does.
#[allow(dead_code)]
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64, JitterError> {
    if finite(name, value)? >= 0.0 {
        Ok(value)
    } else {
        Err(JitterError::Negative { name, value })
    }
}

/// Checks the length of a parameter vector given to `with_params`.
pub(crate) fn param_count(
    model: &'static str,
    expected: usize,
    params: &[f64],
) -> Result<(), JitterError> {
    if params.len() == expected {
        Ok(())
    } else {
        Err(JitterError::WrongParamCount {
            model,
            expected,
            got: params.len(),
        })
    }
}
