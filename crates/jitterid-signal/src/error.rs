use jitterid_numeric::limits::{self, Limit};
use thiserror::Error;

/// Why a signal model, input or sampling grid could not be built.
///
/// Every variant names what is wrong and the offending value.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SignalError {
    /// A value was NaN or infinite.
    #[error("`{name}` must be finite, got {value}")]
    NotFinite {
        /// What the value is.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A value that must be strictly positive was not.
    #[error("`{name}` must be > 0, got {value}")]
    NotPositive {
        /// What the value is.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A count that must be at least one was zero.
    #[error("`{name}` must be at least {min}, got {value}")]
    TooFew {
        /// What is counted.
        name: &'static str,
        /// The smallest allowed count.
        min: usize,
        /// The count given.
        value: usize,
    },
    /// Times that must increase strictly did not.
    #[error("`{name}` must be strictly increasing: element {index} ({value}) is not above the one before ({previous})")]
    NotIncreasing {
        /// What the times are.
        name: &'static str,
        /// Index of the first offending element.
        index: usize,
        /// Its value.
        value: f64,
        /// The value before it.
        previous: f64,
    },
    /// Two lengths that must agree did not.
    #[error("`{name}` has length {got}, expected {expected}")]
    WrongLength {
        /// What has the wrong length.
        name: &'static str,
        /// The length expected.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A pole with a positive real part: the model is unstable. (Poles on the imaginary axis,
    /// integrators and undamped modes, are accepted: a record is finite.)
    #[error(
        "pole {re}{im:+}i is unstable (its real part must be ≤ 0; `unstable = true` accepts it)"
    )]
    Unstable {
        /// Real part of the pole.
        re: f64,
        /// Imaginary part of the pole.
        im: f64,
    },
    /// `integrators` asks for more poles at the origin than the system has there.
    #[error("`integrators` = {integrators}: the system has {poles} pole(s), {at_origin} of them exactly at the origin (list the integrators as poles at 0.0, or as trailing zeros of `den`)")]
    Integrators {
        /// The number asked for.
        integrators: usize,
        /// Poles of the system at exactly 0.
        at_origin: usize,
        /// Poles of the system.
        poles: usize,
    },
    /// More zeros than poles: the transfer function is improper.
    #[error("improper transfer function: {zeros} zeros but only {poles} poles")]
    Improper {
        /// Number of zeros (numerator degree).
        zeros: usize,
        /// Number of poles (denominator degree).
        poles: usize,
    },
    /// A complex pair was given with a non-positive imaginary part.
    #[error("complex pair `{name}` must have imaginary part > 0, got {value}")]
    BadPair {
        /// Which root.
        name: &'static str,
        /// The imaginary part given.
        value: f64,
    },
    /// The leading denominator coefficient was zero.
    #[error("the leading coefficient of `{name}` must be non-zero")]
    ZeroLeading {
        /// Which polynomial.
        name: &'static str,
    },
    /// A parameter vector of the wrong length.
    #[error("signal model takes {expected} parameter(s), got {got}")]
    WrongParamCount {
        /// How many it takes.
        expected: usize,
        /// How many were given.
        got: usize,
    },
    /// A denominator that must be monic (leading coefficient 1) was not.
    #[error("the denominator must be monic (leading coefficient 1), got {lead}")]
    NotMonic {
        /// The leading coefficient given.
        lead: f64,
    },
    /// A random input would switch more often than an input can usefully hold.
    #[error("the input would switch about {expected:e} times (at most {max:e}): the span is too long for the mean dwell")]
    TooManySwitches {
        /// The expected number of switches.
        expected: f64,
        /// The largest allowed.
        max: f64,
    },
    /// A spec table names no registered kind.
    #[error("unknown signal kind `{kind}` (known: {known})")]
    UnknownKind {
        /// The name given.
        kind: String,
        /// The registered names, written for a reader.
        known: String,
    },
    /// A spec table lacks a key that the kind needs.
    #[error("signal kind `{kind}` needs the key `{key}`")]
    MissingKey {
        /// The kind (empty when the kind itself is missing).
        kind: String,
        /// The missing key.
        key: String,
    },
    /// A spec table holds a key that the kind does not take.
    #[error("signal kind `{kind}` does not take the key `{key}` (it takes: {known})")]
    UnexpectedKey {
        /// The kind.
        kind: String,
        /// The unexpected key.
        key: String,
        /// The keys the kind takes.
        known: String,
    },
    /// A key's value is not acceptable.
    #[error("`{key}` of signal kind `{kind}`: {message}")]
    InvalidKey {
        /// The kind.
        kind: String,
        /// The offending key.
        key: String,
        /// What is wrong, for a reader.
        message: String,
    },
    /// A kind driven by an input was built without one.
    #[error("signal kind `{kind}` is driven by an input, but none was given")]
    MissingInput {
        /// The kind.
        kind: String,
    },
    /// A kind was registered twice.
    #[error("signal kind `{kind}` is already registered")]
    DuplicateKind {
        /// The kind.
        kind: String,
    },
    /// A complex root listed without its conjugate (real coefficients need pairs).
    #[error("{name} {re}{im:+}i has no complex-conjugate partner in the list")]
    Unpaired {
        /// Which list.
        name: &'static str,
        /// Real part.
        re: f64,
        /// Imaginary part.
        im: f64,
    },
    /// A feature that needs an input made of steps was given a tone input.
    #[error("{what} needs a piecewise-constant input (steps), not tones")]
    NeedsSteps {
        /// The feature.
        what: &'static str,
    },
    /// A value outside the range where the model keeps its meaning.
    #[error("`{name}` must be {expected}, got {value}")]
    OutOfRange {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The range, in words.
        expected: &'static str,
    },
    /// The work was stopped by the budget it ran under (its time limit, or the caller).
    #[error("the simulation was stopped: {0}")]
    Stopped(jitterid_numeric::budget::Stop),
    /// A size beyond one of the library's documented limits (poles, tones, switches, samples).
    #[error(transparent)]
    Limit(#[from] jitterid_numeric::limits::LimitExceeded),
    /// The roots of a polynomial could not be found to the required accuracy.
    #[error("could not find the roots of `{name}`")]
    Roots {
        /// Which polynomial.
        name: &'static str,
    },
}

impl SignalError {
    /// The spec-table key this error is about, for front ends that point at it.
    pub fn key(&self) -> Option<&str> {
        match self {
            SignalError::MissingKey { key, .. }
            | SignalError::UnexpectedKey { key, .. }
            | SignalError::InvalidKey { key, .. } => Some(key),
            SignalError::UnknownKind { .. } | SignalError::MissingInput { .. } => Some("kind"),
            _ => None,
        }
    }
}

impl From<jitterid_numeric::validate::InvalidValue> for SignalError {
    /// The same name and value as a signal error; a negative value where a non-negative one
    /// was needed reads as not positive (the signal crate asks only for finite and positive
    /// values).
    fn from(e: jitterid_numeric::validate::InvalidValue) -> Self {
        use jitterid_numeric::validate::Problem;
        let (name, value) = (e.name, e.value);
        match e.problem {
            Problem::NotFinite => SignalError::NotFinite { name, value },
            Problem::NotPositive | Problem::Negative => SignalError::NotPositive { name, value },
        }
    }
}

/// [`jitterid_numeric::validate::finite`], as a signal error.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, SignalError> {
    Ok(jitterid_numeric::validate::finite(name, value)?)
}

/// [`jitterid_numeric::validate::positive`], as a signal error.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, SignalError> {
    Ok(jitterid_numeric::validate::positive(name, value)?)
}

/// The parameters of a wrapper that appends at most one parameter of its own to a wrapped
/// signal's `inner` ones (a delay, an output offset, an input level): the wrapped signal's,
/// and the wrapper's own when `own` says it is estimated; a count other than `inner + own` is
/// [`SignalError::WrongParamCount`].
pub(crate) fn split_trailing(
    params: &[f64],
    inner: usize,
    own: bool,
) -> Result<(&[f64], Option<f64>), SignalError> {
    let expected = inner + usize::from(own);
    if params.len() != expected {
        return Err(SignalError::WrongParamCount {
            expected,
            got: params.len(),
        });
    }
    Ok((&params[..inner], own.then(|| params[inner])))
}

pub(crate) fn all_finite(name: &'static str, values: &[f64]) -> Result<(), SignalError> {
    values.iter().try_for_each(|&v| finite(name, v).map(|_| ()))
}

/// Transfer-function coefficients: finite, a numerator of at least one coefficient and a
/// denominator of at least two (degree ≥ 1).
pub(crate) fn tf_coefficients(num: &[f64], den: &[f64]) -> Result<(), SignalError> {
    all_finite("num", num)?;
    all_finite("den", den)?;
    if num.is_empty() {
        return Err(SignalError::TooFew {
            name: "num",
            min: 1,
            value: 0,
        });
    }
    if den.len() < 2 {
        return Err(SignalError::TooFew {
            name: "den",
            min: 2,
            value: den.len(),
        });
    }
    limits::check(Limit::Poles, den.len() - 1)?;
    Ok(())
}

pub(crate) fn increasing(name: &'static str, values: &[f64]) -> Result<(), SignalError> {
    all_finite(name, values)?;
    for (i, w) in values.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(SignalError::NotIncreasing {
                name,
                index: i + 1,
                value: w[1],
                previous: w[0],
            });
        }
    }
    Ok(())
}
