//! Maximum likelihood with the second moment, the exact per-sample likelihood, Fisher
//! information and Cramér–Rao bounds (beyond the paper).
//!
//! The first moment `m_k = E[s(t_k + τ)]` carries little information about the jitter; the
//! variance `λ_k = σ_v² + E[s(t_k+τ)²] − m_k²` carries much more, because it is large exactly
//! where the signal moves fast (`docs/method.md`, "Second moments"). This module uses it:
//!
//! * [`second_moments`]: `m_k`, `λ_k` and their gradients ([`second_moments_of`]: of a bare
//!   signal, without gradients); [`dtft_covariance`]: the covariance
//!   of the residual DTFT over a frequency set that follows from them.
//! * Two [`LikelihoodCriterion`]s: [`QuasiMl`], the Gaussian likelihood of the first two
//!   moments (white or Box–Jenkins noise), and [`ExactMl`], the exact likelihood
//!   `p(y_k) = ∫ φ_{σ_v}(y_k − s(t_k + τ)) p(τ) dτ` of independent samples (white noise), by a
//!   log-sum-exp over a per-sample quadrature that resolves the narrow Gaussian factor.
//!   Both take any [`ModelStructure`](jitterid_estimate::ModelStructure) (signal, jitter, noise each fixed
//!   or estimated); `σ_v` is known (`structure.noise_std`) or estimated jointly as the last
//!   parameter ([`likelihood_param_names`]).
//! * Minimisation: [`ExactMl`] and [`QuasiMl`] are [`FitCriterion`](jitterid_estimate::FitCriterion)s,
//!   fitted by the workspace's one entry point, [`fit`](jitterid_estimate::fit), with its one
//!   [`FitOptions`](jitterid_estimate::FitOptions) (a likelihood of one's own: wrap it in
//!   [`Likelihood`]). The criteria are general cost + gradient objectives
//!   ([`Objective`](jitterid_estimate::Objective)), not sums of squares, so any solver of the one
//!   [`Solver`](jitterid_estimate::solver::Solver) trait that needs no residuals applies: by default
//!   [`BrentOrBfgs`](jitterid_estimate::solver::BrentOrBfgs) (Brent's method for one parameter, dense BFGS
//!   started from the inverse of the Gaussian Fisher information otherwise), or
//!   [`NelderMead`](jitterid_estimate::solver::NelderMead) as a derivative-free fallback. Positivity (`a`,
//!   `σ`, `σ_v`) is a [`Transform::Positive`](jitterid_estimate::solver::Transform) reparametrisation
//!   ([`default_transforms`]); other invalid trial points are rejected (infinite cost).
//!   An integer-valued jitter parameter (the `n` of the uniform sum) is profiled
//!   ([`fit_profile`](jitterid_estimate::fit_profile), screened first with a cheaper form of
//!   the criterion). The result is the crate's one result type, [`Fit`](jitterid_estimate::Fit).
//!   The covariance of the estimate is the inverse of the Hessian of `−log L`.
//! * Bounds: [`gaussian_fisher`] (Slepian–Bangs) and [`exact_fisher`] (the exact model's
//!   information by integration over `y`); [`FisherInformation::crb`].
//! * The sine record of ADC testing: [`sine_least_squares`], [`attenuation_sigma`],
//!   [`fit_sine`], and the alias question (see the [`sine`] module docs).
//!
//! * Beside the likelihoods, this crate holds what needs them: model-order [`selection`] (which
//!   refits with [`ExactMl`]), model [`validation`] (standardised residuals by the second
//!   moments) and the run-time criterion [`AnyCriterion`] with the builtin
//!   [`CriterionRegistry`] (`ls`, `bcls`, `weighted-bcls`, `bj`, `quasi-ml`, `ml`): this is the
//!   lowest crate that sees both the first-moment criteria (`jitterid-estimate`) and the
//!   likelihoods.
//!
//! Conventions: the parameter vector is the structure's free parameters in its order (signal,
//! then `jitter.`, then `noise.`), then `σ_v` (`noise.std`) when it is estimated; the cost is
//! `−log L` including every constant (not scaled by the number of samples); gradients of
//! [`ExactMl`] are analytic (the same quadrature nodes as the value), those of [`QuasiMl`]
//! analytic in the signal and by central differences (`jitterid_optim::finite_diff::LIKELIHOOD_FD_STEP`) in the jitter
//! and noise parameters; the covariance is the inverse Hessian of `−log L` by differences of
//! the gradient.
//!
//! Bad input gives a typed [`MlError`], never a silent NaN: likelihoods that underflow
//! ([`MlError::LikelihoodUnderflow`]), `λ_k → 0` ([`MlError::VanishingVariance`]), a jitter
//! reach wider than the record ([`MlError::ReachExceedsRecord`]), a sine record too short to
//! resolve its frequency ([`MlError::SineRecordTooShort`]). During a search the same
//! conditions are infinite costs that the minimisers step back from.
//!
//! ```
//! use jitterid_likelihood::ExactMl;
//! use jitterid_estimate::{fit, FitOptions, ModelStructure, Record};
//! use jitterid_jitter::UniformSum;
//! use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
//! use rand::SeedableRng;
//!
//! // The paper's Table 1 setup: G(s) = 1/(s+2) known, uniform jitter a = 1/2 estimated.
//! let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)])?;
//! let mut rng = rand::rngs::StdRng::seed_from_u64(3);
//! let u = RandomBinary::paper().generate(0.0, 201.0, &mut rng)?;
//! let signal = LtiResponse::new(g, u);
//! let grid = SampleGrid::new(0.0, 1.0, 200)?;
//! let truth = UniformSum::new(0, 0.5)?;
//! let data = simulate(&signal, &truth, &grid, 0.01, &mut rng)?;
//! let record = Record::new(grid, data.y)?;
//! let structure = ModelStructure::oe(signal, UniformSum::new(0, 0.4)?)
//!     .with_estimated(false, true, false)
//!     .with_noise_std(0.01)?;
//! let estimate = fit(&structure, &record, &ExactMl::default(), &FitOptions::default())?;
//! assert!(estimate.converged);
//! // Within four standard errors (from the inverse Hessian) of the truth.
//! let se = estimate.std_errors.as_ref().unwrap()[0];
//! assert!((estimate.params[0] - 0.5).abs() < 4.0 * se);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]
#![allow(clippy::type_complexity, clippy::needless_range_loop)]

mod cheb;
mod criteria;
mod criterion;
mod exact;
mod fastexp;
mod fisher;
mod fit;
mod fit_criterion;
mod moments;
mod objective;
mod param;
mod quasi;
pub mod selection;
mod simd;
pub mod sine;
pub mod validation;

pub use criteria::{AnyCriterion, AnyStructure, CriterionEntry, CriterionRegistry, CRITERION_KEY};
pub use criterion::{Evaluation, GradientRequest, LikelihoodCriterion, LikelihoodData};
pub use exact::{ExactMl, MAX_SAMPLE_NODES};
pub use fisher::{
    delta_method_std, exact_fisher, gaussian_fisher, FisherInformation, FisherOptions,
};
pub use fit::PROFILE_MARGIN;
pub use fit_criterion::Likelihood;
pub use jitterid_estimate::MlError;
/// The constrained form of any objective, from the optimisation layer.
pub use jitterid_optim::TransformedObjective;
pub use moments::{
    dtft_covariance, expected_squares_gradient, second_moments, second_moments_of, DtftCovariance,
    SecondMoments,
};
pub use objective::LikelihoodObjective;
pub use param::{default_transforms, likelihood_param_names, likelihood_params, NOISE_STD_NAME};
pub use quasi::{noise_autocovariance, QuasiMl};
pub use sine::{alias_start, attenuation_sigma, fit_sine, sine_least_squares, SineFit, SineLs};
