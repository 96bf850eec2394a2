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

pub(crate) use crate::kernels::validate::{finite, param_count, positive};
