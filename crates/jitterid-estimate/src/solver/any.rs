//! The one run-time solver type: [`AnySolver`], a shared trait object.

use super::{
    Bfgs, Brent, BrentOrBfgs, GaussNewtonLineSearch, LevenbergMarquardt, MultiStart, NelderMead,
    Solver, SolverError, SolverReport,
};
use crate::objective::Objective;
use crate::solver::LeastSquares;
use std::fmt;
use std::sync::Arc;

/// A solver usable behind a trait object: it takes any [`Objective`] and says by a typed
/// error ([`SolverError::Unsupported`]) when the objective lacks what it needs.
///
/// Implemented for every solver of this crate; implement it for a solver of your own and wrap
/// it in [`AnySolver::new`] to register it.
pub trait DynSolver: fmt::Debug + Send + Sync {
    /// The solver's registry name (`"lm"`, `"bfgs"`, …).
    fn name(&self) -> &'static str;

    /// Minimises `problem` from `start`.
    ///
    /// # Errors
    ///
    /// Those of [`Solver::minimize`].
    fn minimize_dyn(
        &self,
        problem: &dyn Objective,
        start: &[f64],
    ) -> Result<SolverReport, SolverError>;
}

/// A solver chosen at run time (from the [`SolverRegistry`](super::SolverRegistry) or any
/// [`DynSolver`]). Cheap to clone.
#[derive(Clone, Debug)]
pub struct AnySolver(Arc<dyn DynSolver>);

impl AnySolver {
    /// Wraps a solver.
    pub fn new(solver: impl DynSolver + 'static) -> Self {
        AnySolver(Arc::new(solver))
    }

    /// The solver's name.
    pub fn name(&self) -> &'static str {
        self.0.name()
    }
}

impl Default for AnySolver {
    /// Levenberg–Marquardt with its default options.
    fn default() -> Self {
        AnySolver::new(LevenbergMarquardt::default())
    }
}

/// # Requirements
///
/// The problem is an [`Objective`]; Levenberg–Marquardt and Gauss–Newton also need its
/// residual form ([`Objective::as_least_squares`]), Brent's method a single parameter.
impl<P: Objective + ?Sized> Solver<P> for AnySolver {
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        self.0.minimize_dyn(&Borrowed(problem), start)
    }
}

impl DynSolver for AnySolver {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn minimize_dyn(
        &self,
        problem: &dyn Objective,
        start: &[f64],
    ) -> Result<SolverReport, SolverError> {
        self.0.minimize_dyn(problem, start)
    }
}

/// A borrowed objective, sized so that it coerces to `&dyn Objective`.
struct Borrowed<'a, P: ?Sized>(&'a P);

impl<P: Objective + ?Sized> Objective for Borrowed<'_, P> {
    fn num_params(&self) -> usize {
        self.0.num_params()
    }
    fn cost(&self, theta: &[f64]) -> f64 {
        self.0.cost(theta)
    }
    fn cost_gradient(&self, theta: &[f64]) -> (f64, Vec<f64>) {
        self.0.cost_gradient(theta)
    }
    fn as_least_squares(&self) -> Option<&dyn LeastSquares> {
        self.0.as_least_squares()
    }
    fn initial_metric(&self) -> Option<&[Vec<f64>]> {
        self.0.initial_metric()
    }
}

fn residual_form<'a>(
    problem: &'a dyn Objective,
    solver: &'static str,
) -> Result<&'a dyn LeastSquares, SolverError> {
    problem.as_least_squares().ok_or(SolverError::Unsupported {
        solver,
        reason: "it needs residuals (a least-squares criterion); use bfgs, brent or nelder-mead",
    })
}

impl DynSolver for LevenbergMarquardt {
    fn name(&self) -> &'static str {
        "lm"
    }
    fn minimize_dyn(&self, p: &dyn Objective, start: &[f64]) -> Result<SolverReport, SolverError> {
        Solver::minimize(self, residual_form(p, "lm")?, start)
    }
}

impl DynSolver for GaussNewtonLineSearch {
    fn name(&self) -> &'static str {
        "gauss-newton"
    }
    fn minimize_dyn(&self, p: &dyn Objective, start: &[f64]) -> Result<SolverReport, SolverError> {
        Solver::minimize(self, residual_form(p, "gauss-newton")?, start)
    }
}

macro_rules! objective_solver {
    ($ty:ty, $name:literal) => {
        impl DynSolver for $ty {
            fn name(&self) -> &'static str {
                $name
            }
            fn minimize_dyn(
                &self,
                p: &dyn Objective,
                start: &[f64],
            ) -> Result<SolverReport, SolverError> {
                Solver::minimize(self, p, start)
            }
        }
    };
}

objective_solver!(NelderMead, "nelder-mead");
objective_solver!(Bfgs, "bfgs");
objective_solver!(Brent, "brent");
objective_solver!(BrentOrBfgs, "brent-or-bfgs");
objective_solver!(MultiStart<AnySolver>, "multistart");
