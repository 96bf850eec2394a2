//! The error type of the crate.

use thiserror::Error;

/// Why a frequency set, a transform or a first-moment integral could not be built or computed.
///
/// Every variant names the offending parameter and the value it had.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum WindowError {
    /// A frequency set would contain no frequency.
    #[error("the frequency set is empty: at least one frequency is needed")]
    EmptyFrequencySet,
    /// A requested frequency was NaN or infinite.
    #[error("frequency #{index} must be finite, got {value}")]
    FrequencyNotFinite {
        /// Position of the frequency in the list given.
        index: usize,
        /// The value given (Hz).
        value: f64,
    },
    /// A requested frequency was outside one period `[0, 1/T)` of the DTFT.
    #[error("frequency #{index} = {value} Hz is outside one DTFT period [0, {limit}) Hz")]
    FrequencyOutOfRange {
        /// Position of the frequency in the list given.
        index: usize,
        /// The value given (Hz).
        value: f64,
        /// The exclusive upper limit `1/T` (Hz).
        limit: f64,
    },
    /// A band limit was NaN or infinite.
    #[error("band limit `{name}` must be finite, got {value}")]
    BandLimitNotFinite {
        /// `"min"` or `"max"`.
        name: &'static str,
        /// The value given (Hz).
        value: f64,
    },
    /// A band whose lower limit is above its upper limit.
    #[error("band limits must satisfy min <= max, got min = {min} Hz, max = {max} Hz")]
    InvalidBand {
        /// Lower limit given (Hz).
        min: f64,
        /// Upper limit given (Hz).
        max: f64,
    },
    /// A sequence whose length must equal the number of samples `N` did not.
    #[error("`{name}` has length {got}, expected {expected}")]
    WrongLength {
        /// What has the wrong length (`"data"`, `"weights"`).
        name: &'static str,
        /// The length expected (`N`).
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A sequence that must not be empty was.
    #[error("`{name}` must not be empty")]
    Empty {
        /// What is empty.
        name: &'static str,
    },
    /// A sample or weight was NaN or infinite.
    #[error("`{name}[{index}]` must be finite, got {value}")]
    NonFinite {
        /// The sequence (`"data"`, `"weights"`).
        name: &'static str,
        /// Index of the first offending element.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// An option of the first-moment integral was invalid.
    #[error("option `{name}` is invalid: got {value}")]
    InvalidOption {
        /// The option's name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// The integrand `S_c(ψ) γ(-ψ)` of the first-moment integral, or a spectral line, was NaN
    /// or infinite.
    #[error("the spectrum S_c(ψ)γ(-ψ) is not finite at ψ = {frequency} Hz (modulus {value})")]
    NonFiniteSpectrum {
        /// The frequency `ψ` (Hz) where it happened.
        frequency: f64,
        /// The modulus found there.
        value: f64,
    },
    /// The first-moment integral did not reach its accuracy target within the allowed number
    /// of aliases and quadrature refinements.
    #[error(
        "the first-moment integral at f = {frequency} Hz did not reach its target: error bound \
         {error_bound} > target {target} (with {aliases} aliases per side and {nodes} nodes per \
         period)"
    )]
    NotConverged {
        /// The requested frequency (Hz) with the worst ratio of bound to target.
        frequency: f64,
        /// The error bound reached there.
        error_bound: f64,
        /// The target it had to meet.
        target: f64,
        /// Aliases summed on each side of the central period.
        aliases: usize,
        /// Quadrature intervals per period.
        nodes: usize,
    },
}
