//! The one way to fit: a [`FitCriterion`] (any first-moment [`Criterion`], or a likelihood) run
//! by [`fit`] or [`fit_profile`] with one [`FitOptions`], giving one [`Fit`] or one
//! [`EstimateError`].

use crate::criterion::Criterion;
use crate::data::Record;
use crate::fit::estimate;
use crate::noise::NoiseModel;
use crate::options::FitOptions;
use crate::profile::{best_of, fitted_jitter, Profile};
use crate::result::{CostKind, Fit};
use crate::structure::ModelStructure;
use crate::EstimateError;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;
use std::fmt;

/// Something a model structure can be fitted by: a criterion with its estimator.
///
/// Every first-moment [`Criterion`] is one (the blanket implementation runs the
/// least-squares estimator); the likelihood criteria of `jitterid-likelihood` implement it
/// with their own estimator. The trait is object safe for a given model type, so run-time
/// choices are `Arc<dyn FitCriterion<S, J, N>>` (`jitterid_likelihood::AnyCriterion` for the
/// run-time model types), and a likelihood written outside the workspace is one type
/// implementing this trait.
///
/// Required: [`name`](Self::name), [`cost_kind`](Self::cost_kind) and [`fit`](Self::fit).
/// [`profile`](Self::profile) has a default that fits every value of the profiled
/// parameter; [`as_first_moment`](Self::as_first_moment) says whether the criterion is a
/// first-moment [`Criterion`].
pub trait FitCriterion<S, J, N>: fmt::Debug + Send + Sync
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    /// Short name (`"bcls"`, `"exact-ml"`, …), as in [`Fit::criterion`].
    fn name(&self) -> &'static str;

    /// What the cost of a fit measures.
    fn cost_kind(&self) -> CostKind;

    /// The first-moment criterion this is, if it is one (so that a caller can ask about its
    /// weights, such as [`Criterion::uses_noise_model`]). `None` by default.
    fn as_first_moment(&self) -> Option<&dyn Criterion> {
        None
    }

    /// Estimates the free parameters of `structure` from `record`, starting from the
    /// structure's current parameters.
    ///
    /// # Errors
    ///
    /// The estimator's (see [`fit`]).
    fn fit(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
        options: &FitOptions,
    ) -> Result<Fit, EstimateError>;

    /// Fits `structure` with its jitter replaced by `build(v)` for every `v` in `values` and
    /// returns the best (see [`fit_profile`]).
    ///
    /// The default fits every value without the covariance, keeps the best converged fit (the
    /// best of all if none converged) and, when `options.covariance` is set, fits the winner
    /// once more from its estimate for the covariance.
    ///
    /// # Errors
    ///
    /// The first error if no value could be fitted (including errors of `build`).
    fn profile(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
        options: &FitOptions,
        values: &[i64],
        build: &(dyn Fn(i64) -> Result<J, EstimateError> + Sync),
    ) -> Result<Profile<J>, EstimateError> {
        refit_each(self, structure, record, options, values, build)
    }
}

/// A first-moment criterion fits by least squares on the DTFT ([`Fit::cost`] is
/// `½ Σ rᵢ²`).
impl<S, J, N, C> FitCriterion<S, J, N> for C
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion,
{
    fn name(&self) -> &'static str {
        Criterion::name(self)
    }

    fn cost_kind(&self) -> CostKind {
        CostKind::SumOfSquares
    }

    fn as_first_moment(&self) -> Option<&dyn Criterion> {
        Some(self)
    }

    fn fit(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
        options: &FitOptions,
    ) -> Result<Fit, EstimateError> {
        estimate(structure, record, self, &options.moment())
    }
}

/// Estimates the free parameters of `structure` from `record` with `criterion`, starting from
/// the structure's current parameters: the one entry point of every criterion.
///
/// A first-moment criterion ([`Ls`](crate::Ls), [`Bcls`](crate::Bcls),
/// [`WeightedBcls`](crate::WeightedBcls), [`BoxJenkins`](crate::BoxJenkins), any
/// [`Criterion`], a `Box<dyn Criterion>`) minimises its weighted sum of squares over
/// `options.frequencies` and reports the sandwich covariance; a likelihood
/// (`jitterid_likelihood::ExactMl`, `QuasiMl`) minimises `−log L` and reports the inverse
/// Hessian. Both give one [`Fit`].
///
/// ```
/// use jitterid_estimate::{fit, Bcls, FitOptions, ModelStructure, Record};
/// use jitterid_jitter::UniformSum;
/// use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
/// use rand::SeedableRng;
///
/// let truth = Zpk::new(0.2, vec![Root::Real(-0.5)], vec![Root::Pair { re: -0.25, im: 0.3 }])?;
/// let mut rng = rand::rngs::StdRng::seed_from_u64(7);
/// let u = RandomBinary::paper().generate(0.0, 200.0, &mut rng)?;
/// let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt())?;
/// let grid = SampleGrid::new(0.0, 1.0, 200)?;
/// let data = simulate(&LtiResponse::new(truth, u.clone()), &jitter, &grid, 0.01, &mut rng)?;
/// let record = Record::new(grid, data.y)?;
///
/// let start = Zpk::new(0.22, vec![Root::Real(-0.45)], vec![Root::Pair { re: -0.27, im: 0.33 }])?;
/// let structure = ModelStructure::oe(LtiResponse::new(start, u), jitter);
/// let estimate = fit(&structure, &record, &Bcls, &FitOptions::default())?;
/// assert!(estimate.converged);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
///
/// No free parameter; a criterion that ignores jitter asked to estimate it; fewer samples or
/// residuals than parameters; a jitter whose reach is wider than the record; an invalid
/// frequency set or weights; a criterion not defined or not finite at the start (a
/// likelihood's typed reason as [`EstimateError::Likelihood`]); invalid solver options. A
/// search that stops without converging is not an error: see [`Fit::converged`] and
/// [`Fit::termination`].
pub fn fit<S, J, N, C>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &FitOptions,
) -> Result<Fit, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: FitCriterion<S, J, N> + ?Sized,
{
    criterion.fit(structure, record, options)
}

/// Profiles an integer-valued parameter of the jitter family: fits `structure` with its jitter
/// replaced by `build(v)` for every `v` in `values` and returns the best fit with its value
/// (see [`Profile`]).
///
/// A structural parameter that takes whole values (the `n` of the uniform-sum family, the
/// number of components of a mixture) is not a solver parameter: the criterion is minimised
/// over the continuous parameters for each value, and the value with the best criterion wins.
/// This is how the paper's `n̂` is defined. `build` makes the start jitter of a value: for the
/// uniform-sum family with the standard deviation of the start kept,
/// `|n| UniformSum::new(n as u32, σ √(3(n+1)))`. The covariance, if asked for, is computed
/// for the winner only. How the values are searched is the criterion's
/// ([`FitCriterion::profile`]): the likelihoods screen them with a cheaper pass first.
///
/// # Errors
///
/// The first error if no value could be fitted (including errors of `build`).
pub fn fit_profile<S, J, N, C, E>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &FitOptions,
    values: impl IntoIterator<Item = i64>,
    build: impl Fn(i64) -> Result<J, E> + Sync,
) -> Result<Profile<J>, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: FitCriterion<S, J, N> + ?Sized,
    E: Into<EstimateError>,
{
    let values: Vec<i64> = values.into_iter().collect();
    let build = |v| build(v).map_err(Into::into);
    criterion.profile(structure, record, options, &values, &build)
}

/// The default profile of a [`FitCriterion`]: every value fitted without the covariance, the
/// best converged fit kept (the best of all if none converged), and the winner fitted once
/// more from its estimate for the covariance when `options` asks for it.
fn refit_each<S, J, N, C>(
    criterion: &C,
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    options: &FitOptions,
    values: &[i64],
    build: &(dyn Fn(i64) -> Result<J, EstimateError> + Sync),
) -> Result<Profile<J>, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: FitCriterion<S, J, N> + ?Sized,
{
    // The covariance is only wanted at the winner: fit every value without it.
    let quick = FitOptions {
        covariance: false,
        ..options.clone()
    };
    let at = |v: i64| -> Result<ModelStructure<S, J, N>, EstimateError> {
        let mut s = structure.clone();
        s.jitter = build(v)?;
        Ok(s)
    };
    let fits = values
        .iter()
        .map(|&v| (v, at(v).and_then(|s| criterion.fit(&s, record, &quick))))
        .collect();
    let (best, costs, first_error) = best_of(fits);
    let Some((value, mut winner)) = best else {
        return Err(first_error.unwrap_or(EstimateError::NothingToEstimate));
    };
    let start = at(value)?;
    if options.covariance {
        // Restart at the winner: the solver stops at once and the covariance is computed there.
        let refit = criterion.fit(&start.with_params(&winner.params)?, record, options)?;
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
