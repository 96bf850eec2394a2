//! Profiling over an integer-valued parameter of a jitter family.
//!
//! A structural parameter that takes whole values (the `n` of the uniform-sum family, the
//! number of components of a mixture, …) is not a solver parameter: the criterion is minimised
//! over the continuous parameters for each value in a range, and the value with the best
//! criterion wins. This is how the paper's `n̂` is defined (its mean `E[n̂] = 0.2145` is a mean
//! of integers). The family enters only through a builder `Fn(i64) -> Result<J, E>` that makes
//! the start jitter for a value, so any family with such a parameter can be profiled. The
//! entry point is [`fit_profile`](crate::fit_profile).

use crate::noise::NoiseModel;
use crate::result::Fit;
use crate::structure::ModelStructure;
use crate::EstimateError;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;

/// The result of a profile over an integer-valued family parameter.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Profile<J> {
    /// The winning value.
    pub value: i64,
    /// The fitted jitter at the winning value (its `std_dev()` is the fitted `σ̂`).
    pub jitter: J,
    /// The fit at the winning value.
    pub estimate: Fit,
    /// The final criterion for every value tried (`None` where the fit failed to run).
    pub costs: Vec<(i64, Option<f64>)>,
}

/// The outcome of [`best_of`]: the winner (value and fit), the cost of every value, the first
/// error.
pub type Best<E> = (Option<(i64, Fit)>, Vec<(i64, Option<f64>)>, Option<E>);

/// The best of the fits of a profile: converged beats not converged, then the lower cost.
pub fn best_of<E>(fits: Vec<(i64, Result<Fit, E>)>) -> Best<E> {
    let mut best: Option<(i64, Fit)> = None;
    let mut costs = Vec::new();
    let mut first_error = None;
    for (value, fit) in fits {
        match fit {
            Ok(e) => {
                costs.push((value, Some(e.cost)));
                let better = match &best {
                    None => true,
                    Some((_, b)) => {
                        (e.converged && !b.converged)
                            || (e.converged == b.converged && e.cost < b.cost)
                    }
                };
                if better {
                    best = Some((value, e));
                }
            }
            Err(err) => {
                costs.push((value, None));
                first_error.get_or_insert(err);
            }
        }
    }
    (best, costs, first_error)
}

/// The jitter of `structure` after the fit `estimate` (its estimated jitter parameters, if
/// any, put into `jitter`).
pub fn fitted_jitter<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    jitter: J,
    estimate: &Fit,
) -> Result<J, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    if !structure.estimate_jitter {
        return Ok(jitter);
    }
    let (ns, nj, _) = structure.blocks();
    Ok(jitter.with_params(&estimate.params[ns..ns + nj])?)
}
