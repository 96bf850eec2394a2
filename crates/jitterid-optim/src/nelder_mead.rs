//! Derivative-free minimisation: argmin's Nelder–Mead on the cost.

use super::error::check_option;
use super::problem::{half_sum_sq, start_residuals, validate_start};
use super::{from_argmin_reason, Solver, SolverError, SolverReport, Termination};
use crate::objective::check_objective_start;
use crate::Objective;
use argmin::core::{CostFunction, Error, Executor, IterState, State};
use argmin::solver::neldermead::NelderMead as ArgminNelderMead;

/// argmin's Nelder–Mead simplex method on an objective's cost (`V(θ) = ½ Σ rᵢ²` for a
/// least-squares problem); needs no gradient.
///
/// The initial simplex is the start plus, for each parameter `j`, the start with `θⱼ` moved by
/// `initial_step · |θⱼ|` (or by `zero_step` if `θⱼ = 0`). The cost is divided by `V(θ₀)`, so
/// the stopping test "standard deviation of the simplex's costs `< sd_tolerance`" is relative
/// to the starting cost (to `|f(θ₀)|` for an objective that can be negative, such as `−log L`;
/// not scaled where `f(θ₀) = 0`). Trial points whose residuals are not finite, or whose evaluation
/// fails, count as infinite cost.
///
/// Slow for more than a handful of parameters; meant as a robust fallback and for checking the
/// gradient-based solvers.
#[derive(Clone, Debug, PartialEq)]
pub struct NelderMead {
    /// Maximum number of simplex iterations. Default 10 000.
    pub max_iters: u64,
    /// Stop when the standard deviation of the simplex costs, relative to `V(θ₀)`, is below
    /// this; `≥ 0`. Default `ε`.
    pub sd_tolerance: f64,
    /// Relative size of the initial simplex; `> 0`. Default 0.05.
    pub initial_step: f64,
    /// Absolute initial step for parameters that start at zero; `> 0`. Default `2.5e-4`.
    pub zero_step: f64,
}

impl Default for NelderMead {
    fn default() -> Self {
        NelderMead {
            max_iters: 10_000,
            sd_tolerance: f64::EPSILON,
            initial_step: 0.05,
            zero_step: 2.5e-4,
        }
    }
}

/// The relative cost seen by the simplex; infinite where the problem cannot be evaluated
/// (argmin's Nelder–Mead unwraps cost errors during its initialisation).
struct RelativeCost<'a, P: ?Sized> {
    problem: &'a P,
    scale: f64,
}

impl<P: Objective + ?Sized> CostFunction for RelativeCost<'_, P> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, theta: &Vec<f64>) -> Result<f64, Error> {
        let v = self.scale * self.problem.cost(theta);
        Ok(if v.is_finite() { v } else { f64::INFINITY })
    }
}

impl NelderMead {
    fn validate(&self) -> Result<(), SolverError> {
        let pos = |x: f64| x.is_finite() && x > 0.0;
        check_option(
            "sd_tolerance",
            self.sd_tolerance,
            self.sd_tolerance.is_finite() && self.sd_tolerance >= 0.0,
            "must be finite and >= 0",
        )?;
        check_option(
            "initial_step",
            self.initial_step,
            pos(self.initial_step),
            "must be finite and > 0",
        )?;
        check_option(
            "zero_step",
            self.zero_step,
            pos(self.zero_step),
            "must be finite and > 0",
        )
    }
}

/// # Requirements
///
/// The problem is an [`Objective`]; only its cost is used. A least-squares problem
/// ([`Objective::as_least_squares`]) has its start checked residual by residual.
impl<P: Objective + ?Sized> Solver<P> for NelderMead {
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        self.validate()?;
        let v0 = match problem.as_least_squares() {
            Some(ls) => {
                validate_start(ls, start)?;
                half_sum_sq(&start_residuals(ls, start)?)
            }
            None => check_objective_start(problem, start)?,
        };
        if v0 == 0.0 && problem.as_least_squares().is_some() {
            return Ok(SolverReport {
                params: start.to_vec(),
                cost: 0.0,
                iterations: 0,
                termination: Termination::SmallGradient,
                converged: true,
            });
        }
        let mut simplex = vec![start.to_vec()];
        for j in 0..start.len() {
            let mut vertex = start.to_vec();
            vertex[j] += if start[j] == 0.0 {
                self.zero_step
            } else {
                self.initial_step * start[j].abs()
            };
            simplex.push(vertex);
        }
        let solver = ArgminNelderMead::new(simplex)
            .with_sd_tolerance(self.sd_tolerance)
            .map_err(SolverError::from_argmin)?;
        let cost = RelativeCost {
            problem,
            scale: if v0 == 0.0 { 1.0 } else { 1.0 / v0.abs() },
        };
        let result = crate::with_budget_timeout(
            Executor::new(cost, solver)
                .configure(|state: IterState<Vec<f64>, (), (), (), (), f64>| {
                    state.max_iters(self.max_iters)
                })
                .ctrlc(false),
        )
        .run()
        .map_err(SolverError::from_argmin)?;
        let mut state = result.state;
        let mut termination =
            from_argmin_reason(&state.termination_status, Termination::SmallCostChange);
        if let Some(stop) = crate::budget_termination().filter(|_| !termination.is_convergence()) {
            termination = stop;
        }
        let params = state
            .take_best_param()
            .or_else(|| state.take_param())
            .unwrap_or_else(|| start.to_vec());
        let cost = problem.cost(&params);
        Ok(SolverReport {
            converged: termination.is_convergence() && cost.is_finite(),
            params,
            cost,
            iterations: state.get_iter(),
            termination,
        })
    }
}
