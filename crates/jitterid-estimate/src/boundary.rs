//! Estimates on the boundary of a parameter's domain (a jitter width at 0).
//!
//! A width parameter is valid only above 0, and the criterion is not defined below it. When its
//! best value is 0 (the data show no detectable jitter), an unconstrained solver walks it
//! towards 0 until every trial step leaves the domain, and stops with
//! [`Termination::NonFinite`] although it has found the answer. Such a parameter, once it is
//! below [`BOUND_FRACTION`] of its start, is held where it is and the others are fitted with it
//! held; the fit then ends as converged at the bound ([`Termination::AtBound`]).
//!
//! Standard errors there: the asymptotic normal theory behind the sandwich covariance does not
//! hold on a boundary, so a parameter at its bound gets none (its row and column of the
//! covariance, and its standard error, are 0, and the termination names it); the others get
//! their covariance conditional on it (the sandwich over the free parameters alone).

use crate::noise::NoiseModel;
use crate::solver::{
    LeastSquares, LevenbergMarquardt, NormalEquations, Solver, SolverError, SolverReport,
    Termination,
};
use crate::structure::ModelStructure;
use faer::Mat;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;

/// A positive parameter below this fraction of its (positive) start is on its bound: its
/// effect on the first moment is then of relative order `BOUND_FRACTION²` for a symmetric
/// jitter's width (the moment depends on the width through its square), far below any noise.
pub(crate) const BOUND_FRACTION: f64 = 1e-6;

/// For each free parameter, whether it is a jitter or noise-shape parameter that must stay
/// positive: positive at the start, and its negation leaves the model's domain.
pub(crate) fn positive_params<S, J, N>(structure: &ModelStructure<S, J, N>) -> Vec<bool>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let (ns, _, _) = structure.blocks();
    let theta = structure.params();
    (0..theta.len())
        .map(|i| {
            if i < ns || !(theta[i] > 0.0) {
                return false;
            }
            let mut negated = theta.clone();
            negated[i] = -theta[i];
            structure.with_params(&negated).is_err()
        })
        .collect()
}

/// Whether a search converged with every parameter free (not already held at a bound).
pub(crate) fn converged_inside(termination: &Termination) -> bool {
    termination.is_convergence() && !matches!(termination, Termination::AtBound { .. })
}

/// The parameters on their bound after a fit that stalled against the domain's edge, or that
/// converged with a width already there (an even width goes to 0 quadratically once the
/// search's matrix has its curvature, [`crate::even_widths`], and the search then stops on its
/// cost-change test with the width far below [`BOUND_FRACTION`] of its start).
pub(crate) fn bound_params(report: &SolverReport, start: &[f64], positive: &[bool]) -> Vec<usize> {
    if report.termination != Termination::NonFinite && !converged_inside(&report.termination) {
        return Vec::new();
    }
    (0..report.params.len())
        .filter(|&i| {
            positive.get(i).copied().unwrap_or(false)
                && report.params[i] <= BOUND_FRACTION * start[i]
        })
        .collect()
}

/// Refits the parameters not in `bound` with those held at their values in `report`, and
/// reports the whole as converged at the bound when the rest converges.
///
/// The refit is a least-squares problem in the free parameters only, so it uses
/// Levenberg–Marquardt with its defaults whatever solver made `report`: the caller's solver is
/// typed for the full problem, and the refit starts next to the answer.
///
/// # Errors
///
/// Those of the solver.
pub(crate) fn settle_at_bounds<P: LeastSquares + ?Sized>(
    problem: &P,
    report: SolverReport,
    bound: &[usize],
) -> Result<SolverReport, SolverError> {
    if bound.is_empty() {
        return Ok(report);
    }
    let free: Vec<usize> = (0..report.params.len())
        .filter(|i| !bound.contains(i))
        .collect();
    let at_bound = Termination::AtBound {
        params: bound.to_vec(),
    };
    if free.is_empty() {
        return Ok(SolverReport {
            converged: report.cost.is_finite(),
            termination: at_bound,
            ..report
        });
    }
    let held = Held {
        problem,
        full: report.params.clone(),
        free: free.clone(),
    };
    let start: Vec<f64> = free.iter().map(|&i| report.params[i]).collect();
    let sub = LevenbergMarquardt::default().minimize(&held, &start)?;
    let params = held.merge(&sub.params);
    let (converged, termination) = if sub.converged {
        (true, at_bound)
    } else {
        (false, sub.termination)
    };
    Ok(SolverReport {
        params,
        cost: sub.cost,
        iterations: report.iterations + sub.iterations,
        termination,
        converged,
    })
}

/// `problem` over the parameters `free`, the others held at their values in `full`.
struct Held<'a, P: ?Sized> {
    problem: &'a P,
    full: Vec<f64>,
    free: Vec<usize>,
}

impl<P: LeastSquares + ?Sized> Held<'_, P> {
    fn merge(&self, theta: &[f64]) -> Vec<f64> {
        let mut full = self.full.clone();
        for (&i, &v) in self.free.iter().zip(theta) {
            full[i] = v;
        }
        full
    }
}

impl<P: LeastSquares + ?Sized> LeastSquares for Held<'_, P> {
    fn num_params(&self) -> usize {
        self.free.len()
    }

    fn num_residuals(&self) -> usize {
        self.problem.num_residuals()
    }

    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        self.problem.residuals(&self.merge(theta))
    }

    fn jacobian(&self, theta: &[f64]) -> Result<Mat<f64>, SolverError> {
        let j = self.problem.jacobian(&self.merge(theta))?;
        let cols = j.ncols();
        if self.free.iter().any(|&c| c >= cols) {
            return Err(SolverError::JacobianShape {
                expected_rows: self.problem.num_residuals(),
                expected_cols: self.full.len(),
                rows: j.nrows(),
                cols,
            });
        }
        Ok(Mat::from_fn(j.nrows(), self.free.len(), |r, c| {
            j[(r, self.free[c])]
        }))
    }

    fn normal_equations(
        &self,
        theta: &[f64],
        residuals: &[f64],
    ) -> Result<NormalEquations, SolverError> {
        let full = self
            .problem
            .normal_equations(&self.merge(theta), residuals)?;
        full.check_shape(self.full.len())?;
        Ok(select(&full, &self.free))
    }
}

/// The normal equations of the parameters `keep` only (a sub-block: holding the others fixed
/// removes their columns from `J`).
pub(crate) fn select(full: &NormalEquations, keep: &[usize]) -> NormalEquations {
    NormalEquations {
        gram: Mat::from_fn(keep.len(), keep.len(), |a, b| full.gram[(keep[a], keep[b])]),
        gradient: keep.iter().map(|&i| full.gradient[i]).collect(),
    }
}
