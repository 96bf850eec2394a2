//! Profiling over the integer `n` of the uniform-sum jitter family.
//!
//! `n` is structural (an integer), so it is not a solver parameter: the criterion is minimised
//! over the continuous parameters for each `n` in a range, and the `n` with the smallest cost
//! wins. This is how the paper's `n̂` is defined (its mean `E[n̂] = 0.2145` is a mean of
//! integers).

use crate::criterion::Criterion;
use crate::data::Record;
use crate::fit::{estimate, Estimate, EstimateOptions};
use crate::noise::NoiseModel;
use crate::solver::Solver;
use crate::structure::ModelStructure;
use crate::EstimateError;
use jitterid_jitter::{JitterModel, UniformSum};
use jitterid_signal::Signal;
use jitterid_window::Window;

/// The result of [`profile_uniform_sum`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ProfileEstimate {
    /// The winning `n̂`.
    pub n: u32,
    /// The fit at `n̂`.
    pub estimate: Estimate,
    /// The final cost for every `n` tried (`None` where the fit failed to run).
    pub costs: Vec<(u32, Option<f64>)>,
}

impl ProfileEstimate {
    /// `σ̂ = â / √(3(n̂+1))`, when the structure estimated `a` and it is the last jitter
    /// parameter reported under the name `jitter.a`.
    pub fn sigma(&self) -> Option<f64> {
        let i = self.estimate.names.iter().position(|n| n == "jitter.a")?;
        Some(self.estimate.params[i] / (3.0 * (self.n as f64 + 1.0)).sqrt())
    }
}

/// Fits `structure` (whose jitter is a [`UniformSum`]) for every `n` in `ns`, each from the
/// start `a` that keeps the structure's jitter standard deviation, and returns the best
/// converged fit (the best of all if none converged).
pub fn profile_uniform_sum<S, N, C, V, W>(
    structure: &ModelStructure<S, UniformSum, N>,
    record: &Record,
    criterion: &C,
    options: &EstimateOptions<V, W>,
    ns: impl IntoIterator<Item = u32>,
) -> Result<ProfileEstimate, EstimateError>
where
    S: Signal + Clone,
    N: NoiseModel,
    C: Criterion,
    V: Solver,
    W: Window + Clone,
{
    let sigma = structure.jitter.std_dev();
    // The covariance is only wanted at the winner: fit every n without it.
    let quick = EstimateOptions {
        frequencies: options.frequencies.clone(),
        window: options.window.clone(),
        solver: &options.solver,
        covariance: false,
    };
    let mut best: Option<(u32, Estimate)> = None;
    let mut costs = Vec::new();
    let mut first_error = None;
    for n in ns {
        let a = sigma * (3.0 * (n as f64 + 1.0)).sqrt();
        let mut s = structure.clone();
        s.jitter = UniformSum::new(n, a)?;
        match estimate(&s, record, criterion, &quick) {
            Ok(e) => {
                costs.push((n, Some(e.cost)));
                let better = match &best {
                    None => true,
                    Some((_, b)) => {
                        (e.converged && !b.converged)
                            || (e.converged == b.converged && e.cost < b.cost)
                    }
                };
                if better {
                    best = Some((n, e));
                }
            }
            Err(err) => {
                costs.push((n, None));
                first_error.get_or_insert(err);
            }
        }
    }
    let Some((n, mut winner)) = best else {
        return Err(first_error.unwrap_or(EstimateError::NothingToEstimate));
    };
    if options.covariance {
        // Restart at the winner: the solver stops at once and the covariance is computed there.
        let mut s = structure.clone();
        s.jitter = UniformSum::new(n, structure.jitter.a())?;
        let at = s.with_params(&winner.params)?;
        let refit = estimate(&at, record, criterion, options)?;
        winner.covariance = refit.covariance;
        winner.std_errors = refit.std_errors;
        winner.noise_std = refit.noise_std;
    }
    Ok(ProfileEstimate {
        n,
        estimate: winner,
        costs,
    })
}
