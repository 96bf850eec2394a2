//! The one objective abstraction every estimator minimises.
//!
//! An [`Objective`] is a scalar `f(θ)` with a gradient: the first-moment criteria (LS, BCLS,
//! weighted BCLS, Box–Jenkins) as `f = ½ Σ rᵢ²` over their residuals, the likelihood criteria
//! (quasi-ML, exact ML) as `f = −log L`. A sum of squares keeps its residual form
//! ([`Objective::as_least_squares`]), which Levenberg–Marquardt and Gauss–Newton need; every
//! [`LeastSquares`] problem is an `Objective` through a blanket implementation, so one solver
//! trait ([`Solver`](crate::Solver)) covers both kinds.

use crate::finite_diff::{partial, LIKELIHOOD_FD_STEP};
use crate::{LeastSquares, SolverError};
use argmin::core::{CostFunction, Error, Gradient};

/// A smooth objective `f(θ)` to minimise, with its gradient. `f` is `+∞` where `θ` is
/// infeasible; minimisers treat that as a rejected trial point.
///
/// Object safe: a `&dyn Objective` can be handed to any solver of the registry.
pub trait Objective: Send + Sync {
    /// Number of parameters.
    fn num_params(&self) -> usize;

    /// `f(θ)`, or `+∞` where `θ` is infeasible.
    fn cost(&self, theta: &[f64]) -> f64;

    /// `(f(θ), ∇f(θ))`. The default takes central differences of [`cost`](Self::cost)
    /// (one-sided next to an infeasible point).
    fn cost_gradient(&self, theta: &[f64]) -> (f64, Vec<f64>) {
        let f = self.cost(theta);
        let g = (0..theta.len())
            .map(|j| partial(|p| self.cost(p), theta, j, f, LIKELIHOOD_FD_STEP))
            .collect();
        (f, g)
    }

    /// The residual form `f = ½ Σ rᵢ²`, when the objective is a sum of squares (for the
    /// Gauss–Newton-type solvers). `None` by default.
    fn as_least_squares(&self) -> Option<&dyn LeastSquares> {
        None
    }

    /// An initial inverse Hessian for quasi-Newton solvers (for example the inverse of an
    /// expected information matrix), `p × p` row-major rows. `None` by default.
    fn initial_metric(&self) -> Option<&[Vec<f64>]> {
        None
    }
}

/// A sum of squares as an objective: `f = ½ Σ rᵢ²` (`+∞` where a residual is not finite or
/// the evaluation fails), `∇f = Jᵀ r`.
impl<T: LeastSquares> Objective for T {
    fn num_params(&self) -> usize {
        LeastSquares::num_params(self)
    }

    fn cost(&self, theta: &[f64]) -> f64 {
        match self.residuals(theta) {
            Ok(r) if r.len() == self.num_residuals() => {
                let v = 0.5 * r.iter().map(|x| x * x).sum::<f64>();
                if v.is_finite() {
                    v
                } else {
                    f64::INFINITY
                }
            }
            _ => f64::INFINITY,
        }
    }

    fn cost_gradient(&self, theta: &[f64]) -> (f64, Vec<f64>) {
        let nan = || (f64::INFINITY, vec![f64::NAN; theta.len()]);
        let Ok(r) = self.residuals(theta) else {
            return nan();
        };
        let Ok(j) = self.jacobian(theta) else {
            return nan();
        };
        if r.len() != j.nrows() || j.ncols() != theta.len() {
            return nan();
        }
        let f = 0.5 * r.iter().map(|x| x * x).sum::<f64>();
        if !f.is_finite() {
            return nan();
        }
        let g = (0..j.ncols())
            .map(|c| (0..j.nrows()).map(|i| j[(i, c)] * r[i]).sum())
            .collect();
        (f, g)
    }

    fn as_least_squares(&self) -> Option<&dyn LeastSquares> {
        Some(self)
    }
}

/// An objective together with an initial inverse Hessian for quasi-Newton solvers.
#[derive(Debug)]
pub struct WithMetric<'a, O: ?Sized> {
    inner: &'a O,
    metric: Option<Vec<Vec<f64>>>,
}

impl<'a, O: Objective + ?Sized> WithMetric<'a, O> {
    /// `inner` with the initial inverse Hessian `metric` (ignored by solvers unless it is a
    /// symmetric matrix of the right size with a positive diagonal).
    pub fn new(inner: &'a O, metric: Option<Vec<Vec<f64>>>) -> Self {
        WithMetric { inner, metric }
    }
}

impl<O: Objective + ?Sized> Objective for WithMetric<'_, O> {
    fn num_params(&self) -> usize {
        self.inner.num_params()
    }
    fn cost(&self, theta: &[f64]) -> f64 {
        self.inner.cost(theta)
    }
    fn cost_gradient(&self, theta: &[f64]) -> (f64, Vec<f64>) {
        self.inner.cost_gradient(theta)
    }
    fn as_least_squares(&self) -> Option<&dyn LeastSquares> {
        self.inner.as_least_squares()
    }
    fn initial_metric(&self) -> Option<&[Vec<f64>]> {
        self.metric.as_deref()
    }
}

/// Exposes an [`Objective`] as argmin's `CostFunction` and `Gradient` on `Vec<f64>`.
#[derive(Debug)]
pub struct ArgminObjective<'a, O: ?Sized>(pub &'a O);

impl<O: Objective + ?Sized> CostFunction for ArgminObjective<'_, O> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, Error> {
        Ok(self.0.cost(p))
    }
}

impl<O: Objective + ?Sized> Gradient for ArgminObjective<'_, O> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, Error> {
        Ok(self.0.cost_gradient(p).1)
    }
}

/// Checks a start for an objective minimiser and returns the cost there.
pub(crate) fn check_objective_start<O: Objective + ?Sized>(
    objective: &O,
    start: &[f64],
) -> Result<f64, SolverError> {
    if start.len() != objective.num_params() {
        return Err(SolverError::WrongStartLength {
            expected: objective.num_params(),
            got: start.len(),
        });
    }
    if start.is_empty() {
        return Err(SolverError::NoParameters);
    }
    if let Some((index, &value)) = start.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(SolverError::NonFiniteStart { index, value });
    }
    let f = objective.cost(start);
    if !f.is_finite() {
        return Err(SolverError::NonFiniteResidual { index: 0, value: f });
    }
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Rosenbrock;

    impl LeastSquares for Rosenbrock {
        fn num_params(&self) -> usize {
            2
        }
        fn num_residuals(&self) -> usize {
            2
        }
        fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
            Ok(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]])
        }
    }

    #[test]
    fn a_sum_of_squares_gradient_is_the_difference_quotient_of_its_cost() {
        let theta = [-1.2, 1.0];
        let (f, g) = Rosenbrock.cost_gradient(&theta);
        assert_eq!(f, Rosenbrock.cost(&theta));
        for (j, gj) in g.iter().enumerate() {
            let fd = partial(|p| Rosenbrock.cost(p), &theta, j, f, LIKELIHOOD_FD_STEP);
            // Central difference, h ≈ 7e-6: truncation h²·f'''/6 below 1e-7 here.
            assert!(
                (gj - fd).abs() < 1e-5 * gj.abs().max(1.0),
                "{j}: {gj} vs {fd}"
            );
        }
        assert!(Rosenbrock.as_least_squares().is_some());
    }
}
