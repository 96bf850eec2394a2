//! Errors of the optimisation layer.

use super::Transform;

/// What went wrong before or while minimising. Each variant names the offending quantity.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// The start has a different length than the problem has parameters.
    #[error("start has {got} parameters, the problem has {expected}")]
    WrongStartLength {
        /// Number of parameters of the problem.
        expected: usize,
        /// Length of the given start.
        got: usize,
    },
    /// The problem lacks what the solver requires (for example a residual form for
    /// Levenberg–Marquardt, or one parameter for Brent's method).
    #[error("solver `{solver}` cannot minimise this problem: {reason}")]
    Unsupported {
        /// The solver's name.
        solver: &'static str,
        /// What it requires.
        reason: &'static str,
    },
    /// A start parameter is NaN or infinite.
    #[error("start parameter {index} is not finite ({value})")]
    NonFiniteStart {
        /// Index of the parameter.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A start parameter violates its constraint.
    #[error("start parameter {index} = {value} violates its constraint {constraint}")]
    OutsideConstraint {
        /// Index of the parameter.
        index: usize,
        /// Its value.
        value: f64,
        /// The constraint it violates.
        constraint: Transform,
    },
    /// A residual is NaN or infinite where it must be finite (at the start).
    #[error("residual {index} is not finite ({value}) at the start")]
    NonFiniteResidual {
        /// Index of the residual.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A Jacobian entry is NaN or infinite where it must be finite (at the start).
    #[error("Jacobian entry ({row}, {col}) is not finite ({value}) at the start")]
    NonFiniteJacobian {
        /// Residual index.
        row: usize,
        /// Parameter index.
        col: usize,
        /// Its value.
        value: f64,
    },
    /// `JᵀJ` or `Jᵀr` has a NaN or infinite entry at the start (so the Jacobian has one).
    #[error("the normal equations are not finite at the start: {what} entry {index} is {value}")]
    NonFiniteNormalEquations {
        /// `"gram"` (`JᵀJ`, row-major index) or `"gradient"` (`Jᵀr`).
        what: &'static str,
        /// Index of the entry.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The problem has fewer residuals than parameters, so the parameters are not identifiable.
    #[error("{residuals} residuals cannot determine {params} parameters")]
    TooFewResiduals {
        /// Number of residuals.
        residuals: usize,
        /// Number of parameters.
        params: usize,
    },
    /// The problem has no parameters.
    #[error("the problem has no parameters")]
    NoParameters,
    /// `residuals` returned a vector of the wrong length.
    #[error("residual vector has length {got}, the problem declares {expected}")]
    ResidualLength {
        /// Declared number of residuals.
        expected: usize,
        /// Length returned.
        got: usize,
    },
    /// `jacobian` returned a matrix of the wrong shape.
    #[error("Jacobian is {rows}×{cols}, expected {expected_rows}×{expected_cols} (residuals × parameters)")]
    JacobianShape {
        /// Expected rows (residuals).
        expected_rows: usize,
        /// Expected columns (parameters).
        expected_cols: usize,
        /// Rows returned.
        rows: usize,
        /// Columns returned.
        cols: usize,
    },
    /// The number of transforms differs from the number of parameters.
    #[error("{got} transforms given for {expected} parameters")]
    WrongTransformCount {
        /// Number of parameters of the problem.
        expected: usize,
        /// Number of transforms given.
        got: usize,
    },
    /// A `Bounded` transform with `lo ≥ hi` or a non-finite bound.
    #[error("parameter {index}: bounds ({lo}, {hi}) are not a finite interval with lo < hi")]
    InvalidBounds {
        /// Index of the parameter.
        index: usize,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// A solver option is out of its valid range.
    #[error("solver option `{option}` = {value} is invalid: {reason}")]
    InvalidOption {
        /// Name of the option.
        option: &'static str,
        /// Its value.
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// An argmin solver was run without an initial parameter vector.
    #[error("no start given: configure the executor with `param`")]
    MissingStart,
    /// The problem failed to evaluate (for use by [`LeastSquares`](super::LeastSquares)
    /// implementations).
    #[error("problem evaluation failed: {0}")]
    Evaluation(String),
    /// An error raised inside argmin.
    #[error("argmin: {0}")]
    Argmin(String),
}

impl SolverError {
    /// Recovers a `SolverError` that travelled through argmin, or wraps argmin's own error.
    pub(crate) fn from_argmin(err: argmin::core::Error) -> Self {
        match err.downcast::<SolverError>() {
            Ok(e) => e,
            Err(e) => SolverError::Argmin(e.to_string()),
        }
    }
}

/// Checks a solver option `value` with `valid`; `reason` says what it must satisfy.
pub(crate) fn check_option(
    option: &'static str,
    value: f64,
    valid: bool,
    reason: &'static str,
) -> Result<(), SolverError> {
    if valid {
        Ok(())
    } else {
        Err(SolverError::InvalidOption {
            option,
            value,
            reason,
        })
    }
}
