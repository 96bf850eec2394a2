use crate::solver::SolverError;
use jitterid_jitter::JitterError;
use jitterid_signal::SignalError;
use jitterid_window::WindowError;
use thiserror::Error;

/// Why an estimation could not be set up or run. Each variant names what is wrong.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum EstimateError {
    /// A data value is NaN or infinite.
    #[error("data value y[{index}] is not finite ({value})")]
    NonFiniteData {
        /// Index of the sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The data do not fit the sampling grid.
    #[error("data has {got} samples, the sampling grid has {expected}")]
    DataLength {
        /// Samples on the grid.
        expected: usize,
        /// Samples given.
        got: usize,
    },
    /// Fewer samples (or residuals) than free parameters.
    #[error("{available} {what} cannot determine {params} free parameters")]
    TooFewData {
        /// What is counted (samples, residuals).
        what: &'static str,
        /// How many there are.
        available: usize,
        /// Free parameters.
        params: usize,
    },
    /// Nothing is marked as estimated.
    #[error("the model structure has no free parameter")]
    NothingToEstimate,
    /// Every sample has the same value: the record carries no information about a system or a
    /// jitter (both show only through the samples' variation), so there is nothing to fit.
    #[error(
        "the data are constant (every sample equals {value}): a constant record carries no information about the system or the jitter"
    )]
    ConstantData {
        /// The value of every sample.
        value: f64,
    },
    /// The criterion ignores jitter, so it cannot estimate jitter parameters.
    #[error("criterion `{criterion}` ignores the jitter and cannot estimate its parameters")]
    JitterNotModelled {
        /// The criterion's name.
        criterion: &'static str,
    },
    /// The criterion is not finite at the start.
    #[error("the criterion is not finite at the start (residual {index} = {value})")]
    NonFiniteAtStart {
        /// First offending residual.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A weight is negative or not finite, or the weights do not match the frequency set.
    #[error("frequency weight {index} must be finite and >= 0, got {value}")]
    BadWeight {
        /// Index of the weight.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A measurement-noise standard deviation that is negative or not finite.
    #[error("noise standard deviation must be finite and >= 0, got {value}")]
    BadNoiseStd {
        /// The value given.
        value: f64,
    },
    /// A test level (the false-rejection probability of a validation test) outside `(0, 1)`.
    #[error("test level must lie strictly between 0 and 1, got {value}")]
    BadLevel {
        /// The value given.
        value: f64,
    },
    /// The noise model is invalid (for example a non-minimum-phase or unstable ARMA filter).
    #[error("noise model: {0}")]
    Noise(String),
    /// Records given to a joint fit that do not belong to one system.
    #[error("joint fit: record {record}: {message}")]
    JointRecords {
        /// The record's name (empty when the problem is the list itself).
        record: String,
        /// What differs.
        message: String,
    },
    /// A parameter vector of the wrong length.
    #[error("the model structure takes {expected} free parameter(s), got {got}")]
    WrongParamCount {
        /// Free parameters.
        expected: usize,
        /// Length given.
        got: usize,
    },
    /// The jitter's reach is wider than the record: the expectations would read the input
    /// where no sample constrains it (a search that creeps towards an ever wider jitter is
    /// stopped at this edge of the domain).
    #[error("the jitter's reach [{lo}, {hi}] is wider than the record ({duration} s)")]
    ReachExceedsRecord {
        /// Start of the reach.
        lo: f64,
        /// End of the reach.
        hi: f64,
        /// The record's duration.
        duration: f64,
    },
    /// An argument of a validation or export helper is out of its range.
    #[error("{name} = {value}: {reason}")]
    BadArgument {
        /// The argument.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
    /// From the signal model.
    #[error(transparent)]
    Signal(#[from] SignalError),
    /// From the jitter model.
    #[error(transparent)]
    Jitter(#[from] JitterError),
    /// From the frequency transforms.
    #[error(transparent)]
    Window(#[from] WindowError),
    /// From the solver.
    #[error(transparent)]
    Solver(#[from] SolverError),
    /// From a likelihood criterion.
    #[error(transparent)]
    Likelihood(Box<crate::MlError>),
}
