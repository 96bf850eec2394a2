//! Profiling over an integer-valued parameter of a jitter family.
//!
//! A structural parameter that takes whole values (the `n` of the uniform-sum family, the
//! number of components of a mixture, …) is not a solver parameter: the criterion is minimised
//! over the continuous parameters for each value in a range, and the value with the best
//! criterion wins. This is how the paper's `n̂` is defined (its mean `E[n̂] = 0.2145` is a mean
//! of integers). The family enters only through a builder `Fn(i64) -> Result<J, E>` that makes
//! the start jitter for a value, so any family with such a parameter can be profiled.

use crate::criterion::Criterion;
use crate::data::Record;
use crate::fit::{estimate, EstimateOptions, FitProblem};
use crate::noise::NoiseModel;
use crate::result::Fit;
use crate::structure::ModelStructure;
use crate::EstimateError;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;
use jitterid_window::Window;

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

/// Fits `structure` with its jitter replaced by `build(v)` for every `v` in `values`, and
/// returns the best converged fit (the best of all if none converged).
///
/// `build` makes the start jitter for a value: for the uniform-sum family with the standard
/// deviation of the start kept, `|n| UniformSum::new(n as u32, σ √(3(n+1)))`. The covariance,
/// if asked for, is computed for the winner only.
///
/// # Errors
///
/// The first error if no value could be fitted (including errors of `build`).
pub fn profile<S, J, N, C, V, W, E>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &EstimateOptions<V, W>,
    values: impl IntoIterator<Item = i64>,
    build: impl Fn(i64) -> Result<J, E>,
) -> Result<Profile<J>, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    V: for<'a> crate::solver::Solver<FitProblem<'a, S, J, N, C, W>>,
    W: Window + Clone,
    E: Into<EstimateError>,
{
    // The covariance is only wanted at the winner: fit every value without it.
    let quick = EstimateOptions {
        frequencies: options.frequencies.clone(),
        window: options.window.clone(),
        solver: &options.solver,
        covariance: false,
    };
    let at = |v: i64| -> Result<ModelStructure<S, J, N>, EstimateError> {
        let mut s = structure.clone();
        s.jitter = build(v).map_err(Into::into)?;
        Ok(s)
    };
    let fits = values
        .into_iter()
        .map(|v| {
            (
                v,
                at(v).and_then(|s| estimate(&s, record, criterion, &quick)),
            )
        })
        .collect();
    let (best, costs, first_error) = best_of(fits);
    let Some((value, mut winner)) = best else {
        return Err(first_error.unwrap_or(EstimateError::NothingToEstimate));
    };
    let start = at(value)?;
    if options.covariance {
        // Restart at the winner: the solver stops at once and the covariance is computed there.
        let refit = estimate(
            &start.with_params(&winner.params)?,
            record,
            criterion,
            options,
        )?;
        winner.covariance = refit.covariance;
        winner.std_errors = refit.std_errors;
        winner.noise_std = refit.noise_std;
    }
    Ok(Profile {
        value,
        jitter: fitted_jitter(structure, start.jitter, &winner)?,
        estimate: winner,
        costs,
    })
}
