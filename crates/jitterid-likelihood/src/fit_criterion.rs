//! The likelihoods as [`FitCriterion`]s: what [`fit`](jitterid_estimate::fit) and
//! [`fit_profile`](jitterid_estimate::fit_profile) run for [`ExactMl`], [`QuasiMl`] and any
//! [`LikelihoodCriterion`] of one's own wrapped in [`Likelihood`].

use crate::criterion::LikelihoodCriterion;
use crate::fit::{ml_estimate, ml_profile, MlOptions};
use crate::{ExactMl, QuasiMl};
use jitterid_estimate::solver::{AnySolver, BrentOrBfgs};
use jitterid_estimate::{
    CostKind, EstimateError, Fit, FitCriterion, FitOptions, ModelStructure, NoiseModel, Profile,
    Record,
};
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;

/// A [`LikelihoodCriterion`] as a [`FitCriterion`]: how a likelihood written outside this crate
/// is fitted by [`fit`](jitterid_estimate::fit) and registered
/// ([`AnyCriterion::likelihood`](crate::AnyCriterion::likelihood) wraps it).
///
/// The shipped likelihoods ([`ExactMl`], [`QuasiMl`]) are fit criteria themselves and need no
/// wrapper.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Likelihood<C>(pub C);

/// The options of the likelihood estimator that `options` describe: its solver, or the
/// default likelihood solver ([`BrentOrBfgs`]), which the estimator recognises behind the
/// [`AnySolver`] (the integer profile's staged schedule is for it; see [`ml_profile`]).
fn ml_options(options: &FitOptions) -> MlOptions<AnySolver> {
    MlOptions {
        solver: options
            .solver
            .clone()
            .unwrap_or_else(|| AnySolver::new(BrentOrBfgs::default())),
        covariance: options.covariance,
        transforms: options.transforms.clone(),
        noise_std_start: options.noise_std_start,
    }
}

/// [`ml_estimate`] with the estimator's options from `options`.
pub(crate) fn likelihood_fit<S, J, N, C>(
    criterion: &C,
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    options: &FitOptions,
) -> Result<Fit, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
{
    Ok(ml_estimate(
        structure,
        record,
        criterion,
        &ml_options(options),
    )?)
}

/// [`ml_profile`] with the estimator's options from `options`.
fn likelihood_profile<S, J, N, C>(
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
    C: LikelihoodCriterion,
{
    let values = values.iter().copied();
    let options = ml_options(options);
    Ok(ml_profile(
        structure, record, criterion, &options, values, build,
    )?)
}

/// `FitCriterion` for a likelihood type: `−log L` minimised by the likelihood estimator, the
/// integer profile screened first (see [`ml_profile`]).
macro_rules! likelihood_fit_criterion {
    ($(impl$([$($generics:tt)*])? for $ty:ty => |$c:ident| $inner:expr;)*) => {$(
        impl<S, J, N $(, $($generics)*)?> FitCriterion<S, J, N> for $ty
        where
            S: Signal + Clone,
            J: JitterModel + Clone,
            N: NoiseModel,
        {
            fn name(&self) -> &'static str {
                let $c = self;
                LikelihoodCriterion::name($inner)
            }
            fn cost_kind(&self) -> CostKind {
                CostKind::NegLogLikelihood
            }
            fn fit(
                &self,
                structure: &ModelStructure<S, J, N>,
                record: &Record,
                options: &FitOptions,
            ) -> Result<Fit, EstimateError> {
                let $c = self;
                likelihood_fit($inner, structure, record, options)
            }
            fn profile(
                &self,
                structure: &ModelStructure<S, J, N>,
                record: &Record,
                options: &FitOptions,
                values: &[i64],
                build: &(dyn Fn(i64) -> Result<J, EstimateError> + Sync),
            ) -> Result<Profile<J>, EstimateError> {
                let $c = self;
                likelihood_profile($inner, structure, record, options, values, build)
            }
        }
    )*};
}

likelihood_fit_criterion! {
    impl for ExactMl => |c| c;
    impl for QuasiMl => |c| c;
    impl[C: LikelihoodCriterion] for Likelihood<C> => |c| &c.0;
}
