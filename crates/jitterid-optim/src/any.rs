//! The one run-time solver type: [`AnySolver`], a shared trait object.

use super::{
    Bfgs, Brent, BrentOrBfgs, GaussNewtonLineSearch, LevenbergMarquardt, MultiStart, NelderMead,
    ProgressHook, Solver, SolverError, SolverReport,
};
use crate::LeastSquares;
use crate::Objective;
use std::any::Any;
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

    /// A copy of this solver that reports to `hook` after the start and after every
    /// iteration, or `None` for a solver that has no progress reports (the default).
    fn with_progress_dyn(&self, hook: ProgressHook) -> Option<AnySolver> {
        let _ = hook;
        None
    }

    /// The solver as [`Any`], so that a caller can recognise a solver it has a faster
    /// schedule for ([`AnySolver::downcast_ref`]); `None` (the default) hides the type.
    fn as_any(&self) -> Option<&dyn Any> {
        None
    }
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

    /// Whether the solver reports its progress ([`DynSolver::with_progress_dyn`]).
    pub fn reports_progress(&self) -> bool {
        self.0
            .with_progress_dyn(ProgressHook::new(|_| {}))
            .is_some()
    }

    /// This solver reporting to `hook` after the start and after every iteration; a solver
    /// without progress reports is returned as it is. A [`MultiStart`] passes the hook to
    /// the solver it runs.
    ///
    /// ```
    /// use jitterid_optim::{ProgressHook, SolverRegistry};
    ///
    /// let table = serde_json::json!({ "solver": "lm", "starts": 3 });
    /// let solver = SolverRegistry::builtin().build(table.as_object().unwrap())?;
    /// let solver = solver.with_progress(ProgressHook::new(|p| eprintln!("{}", p.cost)));
    /// assert!(solver.reports_progress());
    /// # Ok::<(), jitterid_registry::RegistryError>(())
    /// ```
    #[must_use]
    pub fn with_progress(&self, hook: ProgressHook) -> AnySolver {
        self.0
            .with_progress_dyn(hook)
            .unwrap_or_else(|| self.clone())
    }

    /// The wrapped solver if it is a `T` (every solver of this crate shows its type).
    ///
    /// ```
    /// use jitterid_optim::{AnySolver, Bfgs, BrentOrBfgs};
    ///
    /// let solver = AnySolver::new(BrentOrBfgs::default());
    /// assert!(solver.downcast_ref::<BrentOrBfgs>().is_some());
    /// assert!(solver.downcast_ref::<Bfgs>().is_none());
    /// ```
    pub fn downcast_ref<T: Any>(&self) -> Option<&T> {
        self.0.as_any()?.downcast_ref()
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
    fn with_progress_dyn(&self, hook: ProgressHook) -> Option<AnySolver> {
        self.0.with_progress_dyn(hook)
    }
    fn as_any(&self) -> Option<&dyn Any> {
        self.0.as_any()
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
    fn with_progress_dyn(&self, hook: ProgressHook) -> Option<AnySolver> {
        Some(AnySolver::new(self.clone().with_progress(hook)))
    }
    fn as_any(&self) -> Option<&dyn Any> {
        Some(self)
    }
}

impl DynSolver for GaussNewtonLineSearch {
    fn name(&self) -> &'static str {
        "gauss-newton"
    }
    fn minimize_dyn(&self, p: &dyn Objective, start: &[f64]) -> Result<SolverReport, SolverError> {
        Solver::minimize(self, residual_form(p, "gauss-newton")?, start)
    }
    fn as_any(&self) -> Option<&dyn Any> {
        Some(self)
    }
}

macro_rules! objective_solver {
    ($ty:ty, $name:literal) => {
        objective_solver!($ty, $name, |_s: &$ty, _h: ProgressHook| None);
    };
    ($ty:ty, $name:literal, $hooked:expr) => {
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
            fn with_progress_dyn(&self, hook: ProgressHook) -> Option<AnySolver> {
                ($hooked)(self, hook)
            }
            fn as_any(&self) -> Option<&dyn Any> {
                Some(self)
            }
        }
    };
}

objective_solver!(NelderMead, "nelder-mead");
objective_solver!(Bfgs, "bfgs", |s: &Bfgs, hook| Some(AnySolver::new(Bfgs {
    progress: Some(hook),
    ..s.clone()
})));
objective_solver!(Brent, "brent", |s: &Brent, hook| Some(AnySolver::new(
    Brent {
        progress: Some(hook),
        ..s.clone()
    }
)));
objective_solver!(
    BrentOrBfgs,
    "brent-or-bfgs",
    |s: &BrentOrBfgs, hook: ProgressHook| {
        let mut s = s.clone();
        s.brent.progress = Some(hook.clone());
        s.bfgs.progress = Some(hook);
        Some(AnySolver::new(s))
    }
);
// The wrapper reports the runs of the solver it wraps.
objective_solver!(
    MultiStart<AnySolver>,
    "multistart",
    |s: &MultiStart<AnySolver>, hook| s.solver.with_progress_dyn(hook).map(|inner| {
        AnySolver::new(MultiStart {
            solver: inner,
            ..s.clone()
        })
    })
);
