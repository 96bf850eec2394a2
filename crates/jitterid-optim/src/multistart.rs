//! Multi-start wrapper around any [`Solver`].

use super::error::check_option;
use super::{Solver, SolverError, SolverReport};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Runs `solver` from the given start and from `starts` perturbed copies
/// `θⱼ · (1 + uⱼ)`, `uⱼ ~ U[−radius, radius]`, and returns the best report: the converged run
/// with the lowest cost, or, if none converged, the run with the lowest cost.
///
/// The perturbations come from a generator seeded with `seed`, so results are deterministic
/// for a seed (and a given version of `rand`). The perturbation is relative, so parameters
/// that start at zero are not perturbed; for a [`Transformed`](super::Transformed) problem it
/// acts on the internal coordinates.
///
/// Errors of the run from the given start (an invalid start, say) are returned; perturbed runs
/// that fail are skipped. [`SolverReport::iterations`] is summed over all runs.
///
/// # Example
///
/// ```
/// use jitterid_optim::{LevenbergMarquardt, MultiStart};
///
/// // LM from the start and 20 perturbed starts within ±50 %, seed 7.
/// let solver = MultiStart::new(LevenbergMarquardt::default(), 20, 0.5, 7);
/// # let _ = solver;
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct MultiStart<S> {
    /// The solver run from every start.
    pub solver: S,
    /// Number of perturbed starts (in addition to the given one).
    pub starts: usize,
    /// Relative perturbation radius `r`; finite and `≥ 0`.
    pub radius: f64,
    /// Seed of the perturbations.
    pub seed: u64,
}

impl<S> MultiStart<S> {
    /// `solver` from the start plus `starts` perturbed starts of relative `radius`, seeded.
    pub fn new(solver: S, starts: usize, radius: f64, seed: u64) -> Self {
        MultiStart {
            solver,
            starts,
            radius,
            seed,
        }
    }
}

/// Whether `a` is a better result than `b`: converged beats not converged, then lower cost.
fn better(a: &SolverReport, b: &SolverReport) -> bool {
    match (a.converged, b.converged) {
        (true, false) => true,
        (false, true) => false,
        _ => a.cost < b.cost || (a.cost.is_finite() && !b.cost.is_finite()),
    }
}

/// # Requirements
///
/// Whatever the inner solver requires of the problem.
impl<P, S> Solver<P> for MultiStart<S>
where
    P: ?Sized,
    S: Solver<P>,
{
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        check_option(
            "radius",
            self.radius,
            self.radius.is_finite() && self.radius >= 0.0,
            "must be finite and >= 0",
        )?;
        let mut best = self.solver.minimize(problem, start)?;
        let mut iterations = best.iterations;
        let mut rng = StdRng::seed_from_u64(self.seed);
        let r = self.radius;
        for _ in 0..self.starts {
            // Draw the whole start before running, so that the sequence of starts does not
            // depend on how the runs end.
            // `(2u − 1) r` with `u ~ U[0, 1)` rather than `random_range`, which panics when the
            // width of the range overflows.
            let perturbed: Vec<f64> = start
                .iter()
                .map(|&t| t * (1.0 + (2.0 * rng.random::<f64>() - 1.0) * r))
                .collect();
            if let Ok(report) = self.solver.minimize(problem, &perturbed) {
                iterations = iterations.saturating_add(report.iterations);
                if better(&report, &best) {
                    best = report;
                }
            }
        }
        best.iterations = iterations;
        Ok(best)
    }
}
