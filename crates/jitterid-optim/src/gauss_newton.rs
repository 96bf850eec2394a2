//! Gauss–Newton with a line search: argmin's `GaussNewtonLS` over [`ArgminFaerProblem`].

use super::error::check_option;
use super::normal::jt_r;
use super::problem::{
    checked_jacobian, checked_residuals, col_to_vec, half_sum_sq, start_residuals, validate_start,
    vec_to_col, ArgminFaerProblem, LeastSquares, Scaled,
};
use super::{from_argmin_reason, Solver, SolverError, SolverReport, Termination};
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{Error, Executor, IterState, State, KV};
use argmin::solver::gaussnewton::GaussNewtonLS;
use argmin::solver::linesearch::condition::ArmijoCondition;
use argmin::solver::linesearch::BacktrackingLineSearch;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use std::sync::{Arc, Mutex};

/// argmin state of `GaussNewtonLS` over faer columns.
type GnState = IterState<Mat<f64>, Mat<f64>, Mat<f64>, (), (), f64>;

/// Gauss–Newton with a backtracking line search (Armijo condition): argmin's `GaussNewtonLS`
/// run on [`ArgminFaerProblem`].
///
/// Each iteration takes the Gauss–Newton direction `p = −(JᵀJ)⁻¹Jᵀr` and backtracks
/// `α ← backtrack · α` from `α = 1` until the Armijo condition holds. argmin's line search works
/// on the residual *norm* `‖r‖`, so the residuals are divided by `‖r(θ₀)‖` first (the minimiser
/// is unchanged): the Armijo test then compares consistent quantities near the start, and
/// `tol` is relative to the starting residual norm.
///
/// Stops when one iteration changes `‖r‖` by less than `tol · ‖r(θ₀)‖`
/// ([`Termination::SmallCostChange`]); if the Gauss–Newton model at that point still predicts a
/// larger decrease, the line search is reported as failed ([`Termination::LineSearchFailed`],
/// not converged). A singular `JᵀJ` ends the run at the last iterate with
/// [`Termination::Other`]. Trial points with non-finite residuals fail the Armijo test and are
/// backtracked from.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussNewtonLineSearch {
    /// Maximum number of Gauss–Newton iterations. Default 200.
    pub max_iters: u64,
    /// Tolerance on the change of `‖r‖ / ‖r(θ₀)‖` per iteration; `> 0`. Default `√ε`.
    pub tol: f64,
    /// Armijo constant `c ∈ (0, 1)`. Default `1e-4`.
    pub armijo_c: f64,
    /// Step contraction factor of the backtracking, in `(0, 1)`. Default 0.5.
    pub backtrack: f64,
}

impl Default for GaussNewtonLineSearch {
    fn default() -> Self {
        GaussNewtonLineSearch {
            max_iters: 200,
            tol: f64::EPSILON.sqrt(),
            armijo_c: 1e-4,
            backtrack: 0.5,
        }
    }
}

/// Keeps the latest iterate, so that a run that argmin aborts (singular `JᵀJ`) still reports
/// where it got to.
#[derive(Clone, Default)]
struct LastIterate(Arc<Mutex<Option<Iterate>>>);

/// An iterate and the number of iterations that produced it.
type Iterate = (Vec<f64>, u64);

impl LastIterate {
    fn record(&self, state: &GnState, iters: u64) {
        if let (Ok(mut slot), Some(p)) = (self.0.lock(), state.get_param()) {
            *slot = Some((col_to_vec(p), iters));
        }
    }

    fn take(&self) -> Option<Iterate> {
        self.0.lock().ok().and_then(|mut slot| slot.take())
    }
}

impl Observe<GnState> for LastIterate {
    fn observe_init(&mut self, _name: &str, state: &GnState, _kv: &KV) -> Result<(), Error> {
        self.record(state, 0);
        Ok(())
    }

    fn observe_iter(&mut self, state: &GnState, _kv: &KV) -> Result<(), Error> {
        // Observed before argmin increments the counter.
        self.record(state, state.get_iter() + 1);
        Ok(())
    }
}

impl GaussNewtonLineSearch {
    fn validate(&self) -> Result<(), SolverError> {
        check_option(
            "tol",
            self.tol,
            self.tol.is_finite() && self.tol > 0.0,
            "must be finite and > 0",
        )?;
        check_option(
            "armijo_c",
            self.armijo_c,
            self.armijo_c > 0.0 && self.armijo_c < 1.0,
            "must be in (0, 1)",
        )?;
        check_option(
            "backtrack",
            self.backtrack,
            self.backtrack > 0.0 && self.backtrack < 1.0,
            "must be in (0, 1)",
        )
    }

    /// Decrease of `‖r‖` that the Gauss–Newton linear model predicts at `theta`
    /// (`‖r‖ − ‖r + Jp‖`); `None` if it cannot be computed.
    fn predicted_decrease<P: LeastSquares + ?Sized>(problem: &P, theta: &[f64]) -> Option<f64> {
        let r = checked_residuals(problem, theta).ok()?;
        let j = checked_jacobian(problem, theta).ok()?;
        let n = theta.len();
        let g = jt_r(&j, &r);
        let jtj = super::normal::gram(&j);
        let p = jtj
            .llt(Side::Lower)
            .ok()?
            .solve(Mat::from_fn(n, 1, |i, _| -g[i]));
        let jp = &j * &p;
        let lin: Vec<f64> = (0..r.len()).map(|i| r[i] + jp[(i, 0)]).collect();
        let d = (2.0 * half_sum_sq(&r)).sqrt() - (2.0 * half_sum_sq(&lin)).sqrt();
        d.is_finite().then_some(d)
    }
}

/// # Requirements
///
/// The problem is a [`LeastSquares`] problem (residuals and their Jacobian).
impl<P: LeastSquares + ?Sized> Solver<P> for GaussNewtonLineSearch {
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        self.validate()?;
        validate_start(problem, start)?;
        let r0 = start_residuals(problem, start)?;
        let norm0 = (2.0 * half_sum_sq(&r0)).sqrt();
        if norm0 == 0.0 {
            // Already an exact fit: the gradient Jᵀr vanishes.
            return Ok(SolverReport {
                params: start.to_vec(),
                cost: 0.0,
                iterations: 0,
                termination: Termination::SmallGradient,
                converged: true,
            });
        }
        let scaled = Scaled {
            problem,
            scale: if norm0.is_finite() { 1.0 / norm0 } else { 1.0 },
        };
        let linesearch = BacktrackingLineSearch::new(
            ArmijoCondition::new(self.armijo_c).map_err(SolverError::from_argmin)?,
        )
        .rho(self.backtrack)
        .map_err(SolverError::from_argmin)?;
        let solver = GaussNewtonLS::new(linesearch)
            .with_tolerance(self.tol)
            .map_err(SolverError::from_argmin)?;
        let last = LastIterate::default();
        let run = crate::with_budget_timeout(
            Executor::new(ArgminFaerProblem::new(&scaled), solver)
                .configure(|state: GnState| {
                    state.param(vec_to_col(start)).max_iters(self.max_iters)
                })
                .add_observer(last.clone(), ObserverMode::Always)
                .ctrlc(false),
        )
        .run();

        let (params, iterations, mut termination) = match run {
            Ok(result) => {
                let mut state = result.state;
                let termination =
                    from_argmin_reason(&state.termination_status, Termination::SmallCostChange);
                let best = state
                    .take_best_param()
                    .or_else(|| state.take_param())
                    .ok_or(SolverError::MissingStart)?;
                (col_to_vec(&best), state.get_iter(), termination)
            }
            Err(err) => match SolverError::from_argmin(err) {
                SolverError::Argmin(msg) => match last.take() {
                    Some((params, iterations)) => (
                        params,
                        iterations,
                        Termination::Other(format!("Gauss-Newton stopped: {msg}")),
                    ),
                    None => return Err(SolverError::Argmin(msg)),
                },
                other => return Err(other),
            },
        };

        if termination == Termination::SmallCostChange
            && Self::predicted_decrease(&scaled, &params).is_some_and(|d| d > self.tol)
        {
            termination = Termination::LineSearchFailed;
        }
        let cost = half_sum_sq(&checked_residuals(problem, &params)?);
        if !cost.is_finite() {
            termination = Termination::NonFinite;
        }
        if let Some(stop) = crate::budget_termination().filter(|_| !termination.is_convergence()) {
            termination = stop;
        }
        Ok(SolverReport {
            converged: termination.is_convergence(),
            params,
            cost,
            iterations,
            termination,
        })
    }
}
