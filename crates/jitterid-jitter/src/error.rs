use jitterid_numeric::limits::Limit;
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
    /// A spec table named a family that the registry does not hold.
    #[error("unknown jitter family \"{family}\"; expected one of {known}")]
    UnknownFamily {
        /// The name given.
        family: String,
        /// The registered names, written for a reader.
        known: String,
    },
    /// A spec table lacks a key that the family needs.
    #[error("jitter family \"{family}\" needs the key `{key}`")]
    MissingKey {
        /// The family.
        family: String,
        /// The missing key.
        key: String,
    },
    /// A spec table holds a key that the family does not take.
    #[error("jitter family \"{family}\" takes no key `{key}`; its keys are {allowed}")]
    UnexpectedKey {
        /// The family.
        family: String,
        /// The key given.
        key: String,
        /// The keys the family takes, written for a reader.
        allowed: String,
    },
    /// A key of a spec table has a value of the wrong type, or one its family rejects.
    #[error("jitter family \"{family}\", key `{key}`: {message}")]
    InvalidKey {
        /// The family.
        family: String,
        /// The offending key (for a term of a sum or a mixture, `terms.<i>.<key>`).
        key: String,
        /// What is wrong, for a reader.
        message: String,
    },
    /// `from_std_dev` was asked of a family that has no single-spread form.
    #[error("jitter family \"{family}\" cannot be built from a standard deviation alone")]
    NoStdDevForm {
        /// The family.
        family: String,
    },
    /// A family of this name is already registered.
    #[error("a jitter family named \"{family}\" is already registered")]
    DuplicateFamily {
        /// The name.
        family: String,
    },
    /// A gradient buffer of the wrong length was given to `cf_gradient`.
    #[error(
        "jitter model `{model}` has {expected} parameter(s) but the gradient buffer holds {got}"
    )]
    WrongGradientLength {
        /// The model's name.
        model: &'static str,
        /// How many parameters it has.
        expected: usize,
        /// The buffer's length.
        got: usize,
    },
    /// A member whose spread is beyond double precision (a scale of `1e308` s has an infinite
    /// variance and no characteristic function).
    #[error("jitter family `{family}` at these parameters has variance {variance:e}: its scale is beyond double precision")]
    Unrepresentable {
        /// The family.
        family: String,
        /// The variance it has.
        variance: f64,
    },
    /// A size beyond one of the library's documented limits (draws, terms of a sum,
    /// components of a mixture).
    #[error(transparent)]
    Limit(#[from] jitterid_numeric::limits::LimitExceeded),
}

impl JitterError {
    /// The key or parameter the error is about, if any: front ends use it to point at the
    /// offending entry of an input file.
    pub fn key(&self) -> Option<&str> {
        match self {
            JitterError::NotFinite { name, .. }
            | JitterError::NotPositive { name, .. }
            | JitterError::Negative { name, .. }
            | JitterError::OutOfRange { name, .. } => Some(name),
            JitterError::MissingKey { key, .. }
            | JitterError::UnexpectedKey { key, .. }
            | JitterError::InvalidKey { key, .. } => Some(key),
            JitterError::UnknownFamily { .. } => Some("family"),
            // The sizes of a composite family are those of its list of terms.
            JitterError::Limit(e)
                if matches!(
                    e.limit,
                    Limit::SumTerms | Limit::DensityTerms | Limit::MixtureComponents
                ) =>
            {
                Some(crate::registry::TERMS_KEY)
            }
            _ => None,
        }
    }
}

impl From<jitterid_numeric::validate::InvalidValue> for JitterError {
    /// The same parameter, value and problem, as a jitter error.
    fn from(e: jitterid_numeric::validate::InvalidValue) -> Self {
        use jitterid_numeric::validate::Problem;
        let (name, value) = (e.name, e.value);
        match e.problem {
            Problem::NotFinite => JitterError::NotFinite { name, value },
            Problem::NotPositive => JitterError::NotPositive { name, value },
            Problem::Negative => JitterError::Negative { name, value },
        }
    }
}

pub(crate) use crate::kernels::validate::{finite, param_count, positive};
