//! Brent's method for objectives of one parameter.
//!
//! A golden-section bracket is grown from the start (infinite values count as high), then
//! argmin's [`BrentOpt`](argmin::solver::brent::BrentOpt) runs on it, or, with
//! [`Brent::from_bracket`], the same iterations started from the bracket's three known values. No gradient needed: the
//! integer profile of a Table 1 record costs about 20 likelihood evaluations per value.

use super::bfgs::Bfgs;
use super::brent_bracket::minimize_from_bracket;
use super::progress::{Progress, ProgressHook, ProgressObserver};
use super::{Solver, SolverError, SolverReport, Termination};
use crate::objective::check_objective_start;
use crate::Objective;
use argmin::core::{CostFunction, Error, Executor, IterState};
use argmin::solver::brent::BrentOpt;
use serde::{Deserialize, Serialize};

/// Brent's method for one parameter (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Brent {
    /// First bracketing step (unconstrained coordinate). Default 0.1.
    pub bracket_step: f64,
    /// Absolute tolerance on the parameter. Default `1e-8`.
    pub tolerance: f64,
    /// Iteration limit of Brent's method (and of the bracket's growth). Default 100.
    pub max_iters: u64,
    /// Receives the iteration and cost of Brent's method (after the bracket is found), when
    /// set (a front end's progress line; not serialised).
    #[serde(skip)]
    pub progress: Option<ProgressHook>,
    /// Start Brent's iterations from the bracket's three points and their known values (the
    /// first step is the parabola through them) instead of argmin's start, which evaluates a
    /// new golden-section point and discards the bracket's values. Same update rules and
    /// stopping test, so the same tolerance, in fewer evaluations; the iterates differ, so the
    /// result moves within the tolerance. Default false.
    #[serde(default)]
    pub from_bracket: bool,
    /// With [`from_bracket`](Self::from_bracket): also stop when the parabola through the
    /// three best points is convex, has its vertex inside the bracket and predicts that the
    /// best value would fall by at most this much (the value is then known to about this
    /// accuracy while the point may still be off by more than `tolerance`). For a loose fit
    /// whose value is what matters, such as the first pass of a profile. Default 0 (off).
    #[serde(default)]
    pub cost_tolerance: f64,
}

impl Default for Brent {
    fn default() -> Self {
        Brent {
            bracket_step: 0.1,
            tolerance: 1e-8,
            max_iters: 100,
            progress: None,
            from_bracket: false,
            cost_tolerance: 0.0,
        }
    }
}

struct Scalar<'a, O: ?Sized>(&'a O);

impl<O: Objective + ?Sized> CostFunction for Scalar<'_, O> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, p: &f64) -> Result<f64, Error> {
        let v = self.0.cost(&[*p]);
        Ok(if v.is_finite() { v } else { f64::INFINITY })
    }
}

impl Brent {
    /// Minimises a one-parameter `objective` from `start`.
    ///
    /// # Errors
    ///
    /// More than one parameter; invalid options; a start where the cost is not finite.
    fn run<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
    ) -> Result<SolverReport, SolverError> {
        if objective.num_params() != 1 {
            return Err(SolverError::InvalidOption {
                option: "brent parameters",
                value: objective.num_params() as f64,
                reason: "Brent's method minimises over exactly one parameter",
            });
        }
        for (option, value) in [
            ("bracket_step", self.bracket_step),
            ("tolerance", self.tolerance),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SolverError::InvalidOption {
                    option,
                    value,
                    reason: "must be finite and > 0",
                });
            }
        }
        let f0 = check_objective_start(objective, start)?;
        let f = |x: f64| {
            let v = objective.cost(&[x]);
            if v.is_finite() {
                v
            } else {
                f64::INFINITY
            }
        };
        // Bracket (a, b, c) with f(b) ≤ f(a), f(b) ≤ f(c), growing by the golden ratio.
        const GOLD: f64 = 1.618_033_988_749_895;
        let (mut a, mut fa) = (start[0], f0);
        let (mut b, mut fb) = (a + self.bracket_step, f(a + self.bracket_step));
        let mut evals = 2u64;
        if fb > fa {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut fa, &mut fb);
        }
        let mut c = b + GOLD * (b - a);
        let mut fc = f(c);
        evals += 1;
        let mut grown = 0;
        while fc < fb {
            if grown >= self.max_iters {
                return Ok(SolverReport {
                    params: vec![c],
                    cost: fc,
                    iterations: evals,
                    termination: Termination::MaxIterations,
                    converged: false,
                });
            }
            (a, fa) = (b, fb);
            (b, fb) = (c, fc);
            c = b + GOLD * (b - a);
            fc = f(c);
            evals += 1;
            grown += 1;
        }
        if self.from_bracket {
            return Ok(self.finish_from_bracket(&f, [(a, fa), (b, fb), (c, fc)], evals));
        }
        let (lo, hi) = if a < c { (a, c) } else { (c, a) };
        let solver = BrentOpt::new(lo, hi).set_tolerance(f64::EPSILON.sqrt(), self.tolerance);
        let mut executor = crate::with_budget_timeout(
            Executor::new(Scalar(objective), solver)
                .configure(|s: IterState<f64, (), (), (), (), f64>| s.max_iters(self.max_iters))
                .ctrlc(false),
        );
        if let Some(hook) = &self.progress {
            executor = executor.add_observer(
                ProgressObserver {
                    hook: hook.clone(),
                    started: std::time::Instant::now(),
                },
                argmin::core::observers::ObserverMode::Always,
            );
        }
        let result = executor
            .run()
            .map_err(|e| SolverError::Argmin(e.to_string()))?;
        let state = result.state;
        let (mut x, mut fx) = (state.best_param.unwrap_or(b), state.best_cost);
        if !(fx <= fb) {
            x = b;
            fx = fb;
        }
        let termination = match state.termination_status {
            argmin::core::TerminationStatus::Terminated(
                argmin::core::TerminationReason::SolverConverged,
            ) => Termination::SmallStep,
            argmin::core::TerminationStatus::Terminated(
                argmin::core::TerminationReason::MaxItersReached,
            ) => Termination::MaxIterations,
            argmin::core::TerminationStatus::Terminated(
                argmin::core::TerminationReason::Timeout,
            ) => Termination::TimeLimit,
            ref other => Termination::Other(format!("{other:?}")),
        };
        let termination = match crate::budget_termination() {
            Some(stop) if !termination.is_convergence() => stop,
            _ => termination,
        };
        Ok(SolverReport {
            converged: termination.is_convergence() && fx.is_finite(),
            params: vec![x],
            cost: fx,
            iterations: evals + state.iter,
            termination,
        })
    }
}

impl Brent {
    /// Brent's iterations from the bracket `[a, b, c]` (values known, `f(b)` the lowest) by
    /// [`minimize_from_bracket`], after `evals` evaluations of the bracket's growth.
    fn finish_from_bracket(
        &self,
        f: &impl Fn(f64) -> f64,
        [a, b, c]: [(f64, f64); 3],
        evals: u64,
    ) -> SolverReport {
        let started = std::time::Instant::now();
        let report = |iteration: u64, cost: f64| {
            if let Some(hook) = &self.progress {
                hook.report(&Progress {
                    iteration,
                    cost,
                    elapsed_seconds: started.elapsed().as_secs_f64(),
                });
            }
        };
        report(0, b.1);
        let r = minimize_from_bracket(
            f,
            b,
            [a, c],
            (f64::EPSILON.sqrt(), self.tolerance, self.cost_tolerance),
            self.max_iters,
            report,
        );
        let (x, fx) = r.best;
        SolverReport {
            converged: r.converged && fx.is_finite(),
            params: vec![x],
            cost: fx,
            iterations: evals + r.evaluations,
            termination: if r.converged {
                Termination::SmallStep
            } else {
                Termination::MaxIterations
            },
        }
    }
}

/// # Requirements
///
/// The problem is an [`Objective`] of exactly one parameter (else
/// [`SolverError::InvalidOption`]); no gradient is used.
impl<P> Solver<P> for Brent
where
    P: Objective + ?Sized,
{
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        self.run(problem, start)
    }
}

/// Brent's method for one parameter, dense BFGS otherwise: the default for the likelihood
/// criteria.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct BrentOrBfgs {
    /// The one-parameter solver.
    pub brent: Brent,
    /// The solver for two or more parameters.
    pub bfgs: Bfgs,
}

/// # Requirements
///
/// As [`Brent`] for one parameter and [`Bfgs`] otherwise.
impl<P> Solver<P> for BrentOrBfgs
where
    P: Objective + ?Sized,
{
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        if start.len() == 1 {
            self.brent.run(problem, start)
        } else {
            Solver::minimize(&self.bfgs, problem, start)
        }
    }
}
