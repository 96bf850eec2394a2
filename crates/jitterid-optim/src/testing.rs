//! The contract every [`Solver`] of this crate keeps, as a public check that a solver of your
//! own can be run against (in the style of `jitterid_jitter::testing::check_contract`).
//!
//! [`check_solver`] minimises a few well-conditioned problems of known minimum and checks what
//! the [`Solver`] trait promises: a report whose parameters have the start's length, whose
//! cost is finite, not above the cost at the start and equal to the problem's cost at the
//! reported parameters; `converged` only on a convergence test; the same report twice from the
//! same start (solvers are deterministic); a start of the wrong length, with a non-finite
//! entry, or where the problem is not finite is an `Err`, not a report.

use crate::{LeastSquares, Objective, Solver, SolverError, SolverReport};
use faer::Mat;

/// `r(θ) = (θ_j − c_j)_j` stacked with `10(θ₁ − θ₀²)` when there are two parameters or more
/// (a Rosenbrock valley), analytic Jacobian. Minimum 0 at `θ = c` (with `c₁ = c₀²`).
#[derive(Debug, Clone)]
pub struct Valley {
    centre: Vec<f64>,
}

impl Valley {
    /// The problem in `n ≥ 1` parameters, minimum at `(0.7, 0.49, 1, 1, …)`.
    pub fn new(n: usize) -> Self {
        let centre = (0..n.max(1))
            .map(|j| match j {
                0 => 0.7,
                1 => 0.49,
                _ => 1.0,
            })
            .collect();
        Valley { centre }
    }

    /// The minimiser.
    pub fn minimum(&self) -> &[f64] {
        &self.centre
    }

    /// A start away from the minimum.
    pub fn start(&self) -> Vec<f64> {
        self.centre.iter().map(|c| c - 0.4).collect()
    }
}

impl LeastSquares for Valley {
    fn num_params(&self) -> usize {
        self.centre.len()
    }
    fn num_residuals(&self) -> usize {
        self.centre.len() + usize::from(self.centre.len() >= 2)
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        let mut r: Vec<f64> = p.iter().zip(&self.centre).map(|(x, c)| x - c).collect();
        if p.len() >= 2 {
            r.push(10.0 * (p[1] - p[0] * p[0]));
        }
        Ok(r)
    }
    fn jacobian(&self, p: &[f64]) -> Result<Mat<f64>, SolverError> {
        let n = p.len();
        Ok(Mat::from_fn(self.num_residuals(), n, |i, j| {
            if i < n {
                f64::from(u8::from(i == j))
            } else if j == 0 {
                -20.0 * p[0]
            } else if j == 1 {
                10.0
            } else {
                0.0
            }
        }))
    }
}

/// Why a solver broke its contract.
#[derive(Debug, Clone, PartialEq)]
pub struct ContractViolation(pub String);

impl std::fmt::Display for ContractViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ContractViolation {}

fn fail(what: impl Into<String>) -> ContractViolation {
    ContractViolation(what.into())
}

/// Checks the [`Solver`] contract of `solver` on `problem` from `start` (see the module docs).
/// `tolerance` is how close (in the infinity norm) a converged report must come to `minimum`,
/// when one is given.
///
/// # Errors
///
/// The first broken promise, in words.
pub fn check_solver_on<P, S>(
    solver: &S,
    problem: &P,
    start: &[f64],
    minimum: Option<(&[f64], f64)>,
) -> Result<SolverReport, ContractViolation>
where
    P: Objective + ?Sized,
    S: Solver<P> + ?Sized,
{
    let n = start.len();
    let report = solver
        .minimize(problem, start)
        .map_err(|e| fail(format!("minimize failed from a valid start: {e}")))?;
    if report.params.len() != n {
        return Err(fail(format!(
            "{} parameters reported for a start of {n}",
            report.params.len()
        )));
    }
    if !report.cost.is_finite() {
        return Err(fail(format!("non-finite cost {}", report.cost)));
    }
    let at_start = problem.cost(start);
    if report.cost > at_start {
        return Err(fail(format!(
            "cost {} above the cost at the start {at_start}",
            report.cost
        )));
    }
    let at_params = problem.cost(&report.params);
    if (report.cost - at_params).abs() > 1e-9 * at_params.abs().max(1e-300) + 1e-300 {
        return Err(fail(format!(
            "reported cost {} but the problem's cost at the reported parameters is {at_params}",
            report.cost
        )));
    }
    if report.converged && !report.termination.is_convergence() {
        return Err(fail(format!(
            "converged, but stopped on `{}`",
            report.termination
        )));
    }
    if let (true, Some((minimum, tolerance))) = (report.converged, minimum) {
        let off = report
            .params
            .iter()
            .zip(minimum)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if !(off <= tolerance) {
            return Err(fail(format!(
                "converged {off} away from the minimum (tolerance {tolerance})"
            )));
        }
    }
    let again = solver
        .minimize(problem, start)
        .map_err(|e| fail(format!("second run failed: {e}")))?;
    if again != report {
        return Err(fail("two runs from the same start differ"));
    }
    let mut long = start.to_vec();
    long.push(0.0);
    if solver.minimize(problem, &long).is_ok() {
        return Err(fail("a start of the wrong length was accepted"));
    }
    let mut nan = start.to_vec();
    nan[0] = f64::NAN;
    if solver.minimize(problem, &nan).is_ok() {
        return Err(fail("a start with a NaN was accepted"));
    }
    Ok(report)
}

/// [`check_solver_on`] over [`Valley`] problems of `dims` parameters each; every report must
/// converge within `tolerance` of the minimum.
///
/// # Errors
///
/// The first broken promise, naming the dimension.
pub fn check_solver<S>(solver: &S, dims: &[usize], tolerance: f64) -> Result<(), ContractViolation>
where
    S: Solver<Valley> + ?Sized,
{
    for &n in dims {
        let problem = Valley::new(n);
        let report = check_solver_on(
            solver,
            &problem,
            &problem.start(),
            Some((problem.minimum(), tolerance)),
        )
        .map_err(|e| fail(format!("{n} parameter(s): {e}")))?;
        if !report.converged {
            return Err(fail(format!(
                "{n} parameter(s): did not converge ({})",
                report.termination
            )));
        }
    }
    Ok(())
}
