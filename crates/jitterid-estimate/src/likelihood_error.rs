//! Errors of the maximum-likelihood layer (`jitterid-likelihood`), defined here so that the
//! one error type, [`EstimateError`], can carry them.

use crate::solver::SolverError;
use crate::EstimateError;
use jitterid_jitter::JitterError;
use jitterid_signal::SignalError;
use thiserror::Error;

/// Why a likelihood, a bound or a maximum-likelihood fit could not be computed. Each variant
/// names what is wrong; none is ever replaced by a silent NaN.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MlError {
    /// The likelihood of sample `index` is zero in double precision even in logarithmic form:
    /// the model cannot produce the value observed there (for example a sample far outside the
    /// signal's range with a tiny noise level).
    #[error("the likelihood of sample {index} (y = {y}) underflows: log p = {log_p}")]
    LikelihoodUnderflow {
        /// Index of the sample.
        index: usize,
        /// Its value.
        y: f64,
        /// The logarithm of the likelihood found (`-∞` or NaN).
        log_p: f64,
    },
    /// The model's variance `λ_k = σ_v² + E[s(t_k+τ)²] − m_k²` of sample `index` is zero,
    /// negative or not finite, so the Gaussian quasi-likelihood is not defined (typically
    /// `σ_v = 0` known and a sample where the jittered signal does not vary).
    #[error(
        "the model variance of sample {index} is {variance}: the quasi-likelihood needs λ_k > 0"
    )]
    VanishingVariance {
        /// Index of the sample.
        index: usize,
        /// The variance found.
        variance: f64,
    },
    /// The jitter's reach `[lo, hi]` is wider than the record: a sample would see the signal
    /// over more than the whole record, and the jitter is not identifiable from it.
    #[error("the jitter's reach [{lo}, {hi}] s is wider than the record ({duration} s)")]
    ReachExceedsRecord {
        /// Lower end of the reach (s).
        lo: f64,
        /// Upper end of the reach (s).
        hi: f64,
        /// Duration `N·T` of the record (s).
        duration: f64,
    },
    /// The exact likelihood's quadrature rule of a sample would hold more than `limit` nodes
    /// (`jitterid_likelihood::MAX_SAMPLE_NODES`): the noise level is tiny next to the
    /// signal's range over the jitter's reach and the model passes nowhere near the sample, a
    /// point of negligible likelihood that is not evaluated. (No sample index: which sample is
    /// found first depends on how samples are shared between threads.)
    #[error("the exact likelihood needs more than {limit} quadrature nodes for a sample: the noise level {noise_std} is too small for the signal's range over the jitter's reach")]
    QuadratureTooLarge {
        /// The bound.
        limit: usize,
        /// The measurement-noise level `σ_v` of the evaluation.
        noise_std: f64,
    },
    /// The exact likelihood needs a measurement-noise level `σ_v > 0`.
    #[error("the exact likelihood needs a measurement noise std > 0, got {value}")]
    NoNoise {
        /// The noise level given.
        value: f64,
    },
    /// The criterion supports white measurement noise only.
    #[error("criterion `{criterion}` needs white measurement noise (per-sample independence)")]
    ColouredNoise {
        /// The criterion's name.
        criterion: &'static str,
    },
    /// A quantity that must be finite is not.
    #[error("{what} {index} is not finite ({value})")]
    NonFinite {
        /// What is not finite.
        what: &'static str,
        /// Its index.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A sine record too short to resolve its frequency: fewer than `min_samples` samples or
    /// fewer than two cycles of the tone (after aliasing) in the record.
    #[error("sine record too short: {samples} samples, {cycles:.2} cycles of the baseband tone (needs >= {min_samples} samples and >= 2 cycles)")]
    SineRecordTooShort {
        /// Samples in the record.
        samples: usize,
        /// Cycles of the strongest tone found in the record.
        cycles: f64,
        /// The minimum number of samples.
        min_samples: usize,
    },
    /// A parameter of an option or an argument is out of its valid range.
    #[error("`{name}` = {value} is invalid: {reason}")]
    InvalidArgument {
        /// The argument's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// Nothing to estimate, or a family that does not fit the request.
    #[error("{0}")]
    Unsupported(String),
    /// From the estimation layer (structures, records).
    #[error(transparent)]
    Estimate(#[from] EstimateError),
    /// From the signal model.
    #[error(transparent)]
    Signal(#[from] SignalError),
    /// From the jitter model.
    #[error(transparent)]
    Jitter(#[from] JitterError),
    /// From the solver layer.
    #[error(transparent)]
    Solver(#[from] SolverError),
}

impl From<MlError> for EstimateError {
    fn from(err: MlError) -> Self {
        match err {
            MlError::Estimate(e) => e,
            other => EstimateError::Likelihood(Box::new(other)),
        }
    }
}

impl EstimateError {
    /// The likelihood's typed reason, if a likelihood criterion failed
    /// ([`EstimateError::Likelihood`]).
    ///
    /// ```
    /// use jitterid_estimate::{EstimateError, MlError};
    ///
    /// let e = EstimateError::from(MlError::NoNoise { value: 0.0 });
    /// assert!(matches!(e.likelihood(), Some(MlError::NoNoise { .. })));
    /// assert!(EstimateError::NothingToEstimate.likelihood().is_none());
    /// ```
    pub fn likelihood(&self) -> Option<&MlError> {
        match self {
            EstimateError::Likelihood(e) => Some(e),
            _ => None,
        }
    }
}
