//! Optimisation for **jitterid**, with no model types: objectives, least squares, solvers over
//! [argmin], finite differences, the solver registry.
//!
//! This crate knows nothing about signals, jitter or noise: an estimator above it turns its
//! criterion into one of two problem shapes and hands it to one [`Solver`] trait.
//!
//! # Conventions
//!
//! * **Parameter order.** A problem's parameters are one `&[f64]` in the problem's own order;
//!   solvers never reorder them. [`Transform`]s apply one per parameter, in that order.
//! * **Residual stacking.** A [`LeastSquares`] problem returns one residual vector `r(θ)` of
//!   length [`LeastSquares::num_residuals`]; a complex residual is stacked by its caller
//!   (real parts, then imaginary parts, as the estimators above do) before it reaches here.
//!   The Jacobian is `num_residuals × num_params`, row `i` the gradient of `rᵢ`.
//! * **Cost scaling.** The cost of a least-squares problem is `V(θ) = ½ Σ rᵢ²` (the `½` is
//!   part of every reported [`SolverReport::cost`]); an [`Objective`] reports its own cost
//!   unscaled (`−log L` for the likelihoods above).
//! * **Derivatives.** Analytic where the problem provides them ([`LeastSquares::jacobian`],
//!   [`Objective::cost_gradient`]); otherwise central finite differences ([`fd_jacobian`] with
//!   relative step [`DEFAULT_FD_STEP`], [`finite_diff`] for gradients and Hessians).
//! * **Infeasible points** are non-finite residuals or costs: the gradient-based solvers
//!   shorten or reject the step, [`NelderMead`] treats them as an infinite cost. An `Err` from a
//!   problem aborts the solve.
//! * **Verdicts.** A [`SolverReport`] says why the solver stopped ([`Termination`]); whether
//!   the fit is acceptable for the model (a residual spectrum that is not flat, say) is the
//!   estimator's verdict, not the solver's, and is not represented here.
//!
//! | solver | requires | for |
//! |---|---|---|
//! | [`LevenbergMarquardt`] | [`LeastSquares`] | first-moment criteria (the workhorse) |
//! | [`GaussNewtonLineSearch`] | [`LeastSquares`] | first-moment criteria |
//! | [`NelderMead`] | [`Objective`] (cost only) | any; derivative-free fallback |
//! | [`Bfgs`] | [`Objective`] (cost and gradient) | likelihoods, several parameters |
//! | [`Brent`] | [`Objective`] of one parameter | likelihoods, one parameter |
//! | [`BrentOrBfgs`] | [`Objective`] | the likelihoods' default |
//! | [`MultiStart`] | what its inner solver requires | escaping local minima |
//! | [`AnySolver`] | [`Objective`]; a residual form for LM and GN | a choice made at run time |
//!
//! [`LevenbergMarquardt`] is written here as an argmin [`argmin::core::Solver`] (argmin has
//! none), so it can also run under argmin's `Executor` with observers and checkpointing; see
//! [`lm`]. Run-time choices go through the [`SolverRegistry`] and [`AnySolver`]. Every shipped
//! solver passes [`testing::check_solver`], the contract a solver of your own can be run
//! against.
//!
//! # Constraints
//!
//! Solvers are unconstrained. Sign and box constraints are handled by reparametrisation: wrap the
//! problem in [`Transformed`] with one [`Transform`] per parameter. A start that violates its
//! constraint is rejected with [`SolverError::OutsideConstraint`].
//!
//! # Example
//!
//! ```
//! use jitterid_optim::{LeastSquares, LevenbergMarquardt, Solver, SolverError};
//!
//! /// Rosenbrock's function as residuals `[10(y − x²), 1 − x]`.
//! struct Rosenbrock;
//!
//! impl LeastSquares for Rosenbrock {
//!     fn num_params(&self) -> usize { 2 }
//!     fn num_residuals(&self) -> usize { 2 }
//!     fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
//!         Ok(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]])
//!     }
//!     // `jacobian` defaults to central finite differences.
//! }
//!
//! let report = LevenbergMarquardt::default().minimize(&Rosenbrock, &[-1.2, 1.0])?;
//! assert!(report.converged);
//! assert!((report.params[0] - 1.0).abs() < 1e-8 && (report.params[1] - 1.0).abs() < 1e-8);
//! # Ok::<(), SolverError>(())
//! ```
#![warn(missing_docs)]

use serde::{Deserialize, Serialize};
use std::fmt;

mod any;
mod bfgs;
mod brent;
mod brent_bracket;
mod error;
pub mod finite_diff;
mod gauss_newton;
pub mod lm;
mod multistart;
mod nelder_mead;
mod normal;
mod objective;
mod problem;
mod progress;
mod registry;
pub mod testing;
mod transform;
mod transformed_objective;

pub use any::{AnySolver, DynSolver};
pub use bfgs::Bfgs;
pub use brent::{Brent, BrentOrBfgs};
pub use error::SolverError;
pub use gauss_newton::GaussNewtonLineSearch;
pub use lm::{LevenbergMarquardt, LmModel, LmOptions, Scaling};
pub use multistart::MultiStart;
pub use nelder_mead::NelderMead;
pub use normal::{dot, gram};
pub use normal::{NormalEquations, NormalEquationsOperator};
pub use objective::{ArgminObjective, Objective, WithMetric};
pub use problem::{fd_jacobian, ArgminFaerProblem, ArgminProblem, LeastSquares, DEFAULT_FD_STEP};
pub use progress::{Progress, ProgressHook};
pub use registry::{SolverEntry, SolverRegistry, SOLVER_KEY};
pub use transform::{Transform, Transformed};
pub use transformed_objective::TransformedObjective;

/// A minimiser of problems of type `P`.
///
/// Implementations state what they need from `P` in their where-clause (for example
/// `P: LeastSquares` for Levenberg–Marquardt, `P: Objective` for BFGS) and in a
/// "Requirements" section of their docs.
pub trait Solver<P: ?Sized> {
    /// Minimises `problem` from `start`.
    ///
    /// # Errors
    ///
    /// Invalid starts ([`SolverError::WrongStartLength`], [`SolverError::NonFiniteStart`]),
    /// problems with fewer residuals than parameters ([`SolverError::TooFewResiduals`]), a start
    /// where the residuals are not finite ([`SolverError::NonFiniteResidual`]), invalid solver
    /// options ([`SolverError::InvalidOption`]), a problem without what the solver requires
    /// ([`SolverError::Unsupported`]), and errors returned by the problem itself.
    /// Running out of iterations or getting stuck is *not* an error: it is reported through
    /// [`SolverReport::termination`] with [`SolverReport::converged`] `false`.
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError>;
}

impl<P: ?Sized, S: Solver<P> + ?Sized> Solver<P> for &S {
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        (**self).minimize(problem, start)
    }
}

/// A solver of every [`Objective`] seen through a trait object: what the
/// likelihood fits ask of their solver. Implemented for every such solver.
pub trait ObjectiveSolver: for<'o> Solver<dyn Objective + 'o> {}

impl<S: ?Sized> ObjectiveSolver for S where S: for<'o> Solver<dyn Objective + 'o> {}

/// Outcome of [`Solver::minimize`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverReport {
    /// Final parameters (the best point found).
    pub params: Vec<f64>,
    /// Cost `½ Σ rᵢ²` at [`params`](Self::params); always finite.
    pub cost: f64,
    /// Iterations performed (for [`MultiStart`]: summed over all starts).
    pub iterations: u64,
    /// Why the solver stopped.
    pub termination: Termination,
    /// `true` iff the solver stopped on one of its convergence tests
    /// ([`Termination::is_convergence`]) at a finite cost.
    pub converged: bool,
}

/// Why a solver stopped.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Termination {
    /// The step became small relative to the parameters.
    SmallStep,
    /// The cost stopped decreasing (relative to the solver's tolerance).
    SmallCostChange,
    /// The gradient vanished (relative to the solver's tolerance).
    SmallGradient,
    /// The iteration limit was reached before any convergence test held.
    MaxIterations,
    /// The wall-clock budget was spent before any convergence test held.
    TimeLimit,
    /// Converged with the parameters at these indices on the boundary of their domain (a
    /// jitter width at 0: the data show no detectable jitter); the others met a convergence
    /// test with those held there. Set by the estimator that knows the domain, not by the
    /// solvers.
    AtBound {
        /// Indices (into the free parameter vector) of the parameters at their bound.
        params: Vec<usize>,
    },
    /// The solver could not leave the current point because the residuals (or the Jacobian)
    /// are not finite at every nearby trial point.
    NonFinite,
    /// The line search found no acceptable step along a non-negligible descent direction.
    LineSearchFailed,
    /// The caller stopped the work through the cancel flag of the budget the solver ran under
    /// ([`jitterid_numeric::budget`]).
    Stopped,
    /// Any other reason, described in words.
    Other(String),
}

impl Termination {
    /// Whether this reason is a convergence test (small step, cost change or gradient), in the
    /// interior or at a bound.
    pub fn is_convergence(&self) -> bool {
        matches!(
            self,
            Termination::SmallStep
                | Termination::SmallCostChange
                | Termination::SmallGradient
                | Termination::AtBound { .. }
        )
    }
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Termination::SmallStep => f.write_str("small relative step"),
            Termination::SmallCostChange => f.write_str("small relative cost change"),
            Termination::SmallGradient => f.write_str("small gradient"),
            Termination::MaxIterations => f.write_str("maximum number of iterations reached"),
            Termination::TimeLimit => f.write_str("wall-clock budget spent"),
            Termination::AtBound { params } => {
                write!(
                    f,
                    "converged with parameter(s) {params:?} at the bound of their domain"
                )
            }
            Termination::NonFinite => {
                f.write_str("residuals or Jacobian not finite at every nearby trial point")
            }
            Termination::LineSearchFailed => f.write_str("line search failed"),
            Termination::Stopped => f.write_str("stopped by the caller"),
            Termination::Other(why) => f.write_str(why),
        }
    }
}

/// Maps a termination reason of argmin's own solvers, for solvers without finer reasons.
fn from_argmin_reason(
    status: &argmin::core::TerminationStatus,
    converged_as: Termination,
) -> Termination {
    use argmin::core::{TerminationReason, TerminationStatus};
    match status {
        TerminationStatus::Terminated(TerminationReason::SolverConverged) => converged_as,
        TerminationStatus::Terminated(TerminationReason::MaxItersReached) => {
            Termination::MaxIterations
        }
        TerminationStatus::Terminated(TerminationReason::Timeout) => Termination::TimeLimit,
        TerminationStatus::Terminated(reason) => Termination::Other(reason.text().to_string()),
        TerminationStatus::NotTerminated => Termination::Other("not terminated".to_string()),
    }
}

/// The reason to report when the budget the solver ran under (see
/// [`jitterid_numeric::budget`]) is spent: its time limit, or the caller's stop. Every solver
/// asks it between iterations (the argmin-based ones after their run, with the time left as
/// the executor's timeout), so that a spent budget ends a search as it ends with its own
/// `max_seconds`.
pub fn budget_termination() -> Option<Termination> {
    jitterid_numeric::budget::stop().map(|stop| match stop {
        jitterid_numeric::budget::Stop::TimeLimit { .. } => Termination::TimeLimit,
        _ => Termination::Stopped,
    })
}

/// An argmin executor with the time left in the calling thread's budget as its timeout.
pub(crate) fn with_budget_timeout<O, S, I>(
    executor: argmin::core::Executor<O, S, I>,
) -> argmin::core::Executor<O, S, I>
where
    I: argmin::core::State,
    S: argmin::core::Solver<O, I>,
{
    match jitterid_numeric::budget::current().and_then(|b| b.seconds_left()) {
        Some(left) => executor.timeout(std::time::Duration::from_secs_f64(left)),
        None => executor,
    }
}

#[cfg(test)]
mod tests;
