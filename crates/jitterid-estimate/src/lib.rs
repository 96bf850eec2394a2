//! Estimation for **jitterid**: criteria, solvers and model structures.
//!
//! The paper's method end to end. A [`ModelStructure`] composes a signal, a jitter model and a
//! noise model (OE, BJ, JOE, JBJ, or any part fixed). A [`Criterion`] compares the data's DTFT
//! `Y(f)` with the model's first moment `μ_Y(f; θ)` over a frequency set: naive [`Ls`] (the
//! paper's eq. 9, jitter ignored), [`Bcls`] (eq. 14), [`WeightedBcls`] and the [`BoxJenkins`]
//! criterion; the likelihood criteria of `jitterid-likelihood` use the second moment. Every criterion is an
//! [`Objective`] for one [`solver::Solver`] trait: Levenberg–Marquardt (written here as an
//! argmin solver), Gauss–Newton with line search, Nelder–Mead, BFGS, Brent, multi-start.
//!
//! There is one way to fit: [`fit`] a structure to a record with a [`FitCriterion`] (every
//! [`Criterion`], and the likelihoods of `jitterid-likelihood`) and one [`FitOptions`]; it
//! returns one result type, [`Fit`] — `θ̂` by name, standard errors and covariance (the
//! sandwich form that accounts for the heteroscedastic jittered samples, or the inverse
//! Hessian of `−log L`), the cost, the termination reason — or one error type,
//! [`EstimateError`]. An integer-valued jitter parameter is profiled with [`fit_profile`].
//!
//! Measured data: a [`MeasuredRecord`] holds what a measurement holds (samples, requested
//! instants, the input, an optional known noise level, a name; the study layer,
//! `jitterid-study`, reads and writes its CSV files), as a [`Record`] holds what an estimator
//! needs (the samples on their grid); a fitted run-time signal is moved to another record's
//! input with [`AnySignal::with_input`](jitterid_signal::AnySignal::with_input). Several records
//! of one system are fitted together by [`estimate_joint`]. Box–Jenkins noise models of jittered
//! data carry the jitter's white floor ([`ModelStructure::with_jitter_floor`]).
//!
//! Run-time choices (a command line, Python) go through [`AnyNoise`] / [`NoiseRegistry`],
//! `AnyCriterion` / `CriterionRegistry` (in `jitterid-likelihood`, which sees every criterion)
//! and [`solver::AnySolver`] /
//! [`solver::SolverRegistry`], built from spec tables whose keys are described by
//! [`ParamSpec`].
//!
//! ```
//! use jitterid_estimate::{fit, Bcls, FitOptions, ModelStructure, Record};
//! use jitterid_jitter::UniformSum;
//! use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
//! use rand::SeedableRng;
//!
//! let truth = Zpk::new(0.2, vec![Root::Real(-0.5)], vec![Root::Pair { re: -0.25, im: 0.3 }])?;
//! let mut rng = rand::rngs::StdRng::seed_from_u64(7);
//! let u = RandomBinary::paper().generate(0.0, 200.0, &mut rng)?;
//! let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt())?;
//! let grid = SampleGrid::new(0.0, 1.0, 200)?;
//! let data = simulate(&LtiResponse::new(truth, u.clone()), &jitter, &grid, 0.01, &mut rng)?;
//! let record = Record::new(grid, data.y)?;
//!
//! // Start 10% off the truth; the jitter is known (an OE structure).
//! let start = Zpk::new(0.22, vec![Root::Real(-0.45)], vec![Root::Pair { re: -0.27, im: 0.33 }])?;
//! let structure = ModelStructure::oe(LtiResponse::new(start, u), jitter);
//! let estimate = fit(&structure, &record, &Bcls, &FitOptions::default())?;
//! assert!(estimate.converged);
//! assert!((estimate.params[0] - 0.2).abs() < 5.0 * estimate.std_errors.as_ref().unwrap()[0]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

mod any_noise;
mod boundary;
mod covariance;
mod criterion;
mod data;
mod edges;
mod error;
mod evaluation_memo;
mod even_widths;
mod fit;
mod fit_criterion;
mod flatness;
mod frequency_data;
mod init;
mod init_channels;
mod jitter_floor;
mod joint;
mod likelihood_error;
mod measured;
pub mod montecarlo;
mod noise;
mod options;
mod parseval;
mod profile;
pub mod registry;
mod restricted_noise;
mod result;
mod structure;
mod termination;
pub mod testing;

pub use any_noise::{AnyNoise, DynNoise, NoiseEntry, NoiseRegistry};
pub use criterion::{Bcls, BoxJenkins, Criterion, Ls, WeightContext, WeightedBcls};
pub use data::Record;
pub use error::EstimateError;
/// The dense matrix type of Jacobians ([`FrequencyData::jacobian`], [`solver::LeastSquares`]).
pub use faer::Mat;
pub use fit::{FitProblem, Frequencies};
pub use fit_criterion::{fit, fit_profile, FitCriterion};
pub use flatness::{residual_flatness, FLATNESS_BANDS, FLATNESS_LIMIT, FLATNESS_MIN_PER_BAND};
pub use frequency_data::FrequencyData;
pub use init::{
    fit_rational, initial_model, initialize, offset_start, InitError, InitOptions, InitialModel,
    RationalFit,
};
pub use init_channels::{fit_channels, ChannelOrder};
pub use jitter_floor::{mean_jitter_variance, JITTER_FLOOR_ROUNDS};
/// The optimisation layer (`jitterid-optim`): objectives, least squares, solvers.
pub use jitterid_optim as solver;
pub use jitterid_optim::{ArgminObjective, Objective, WithMetric};
pub use joint::{check_joint, estimate_joint, JointProblem};
pub use likelihood_error::MlError;
pub use measured::{InputLayout, MeasuredRecord};
pub use noise::{ArmaNoise, NoiseModel, WhiteNoise, WithFloor};
pub use options::FitOptions;
pub use profile::Profile;
pub use registry::{Entry, ParamSpec, Registry, RegistryError, SpecTable};
pub use restricted_noise::{restricted_noise_fit, NoiseEstimate, RESTRICTED_NOISE_MAX_SAMPLES};
pub use result::{CostKind, Fit};
pub use structure::ModelStructure;
pub use termination::FitTermination;

/// Building blocks the likelihood layer (`jitterid-likelihood`) shares with the first-moment
/// estimators of this crate, so that both judge records, reaches and profiles alike.
pub mod support {
    pub use crate::covariance::{inverse_gram, sandwich_covariance};
    pub use crate::data::check_samples;
    pub use crate::fit::reach_beyond;
    pub use crate::profile::{best_of, fitted_jitter, Best};
    pub use crate::restricted_noise::measurement_autocovariance;
}
