//! Estimation for **jitterid**: criteria, solvers and model structures.
//!
//! The paper's method end to end. A [`ModelStructure`] composes a signal, a jitter model and a
//! noise model (OE, BJ, JOE, JBJ, or any part fixed). A [`Criterion`] compares the data's DTFT
//! `Y(f)` with the model's first moment `μ_Y(f; θ)` over a frequency set: naive [`Ls`] (the
//! paper's eq. 9, jitter ignored), [`Bcls`] (eq. 14), [`WeightedBcls`] and the [`BoxJenkins`]
//! criterion. A [`solver::Solver`] minimises it: Levenberg–Marquardt (written here as an
//! argmin solver), Gauss–Newton with line search, Nelder–Mead, multi-start. [`estimate`] is the
//! one entry point; its [`Estimate`] carries `θ̂`, the cost, the termination reason and the
//! asymptotic (sandwich) covariance that accounts for the heteroscedastic jittered samples.
//!
//! ```
//! use jitterid_estimate::{estimate, Bcls, EstimateOptions, ModelStructure, Record};
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
//! let fit = estimate(&structure, &record, &Bcls, &EstimateOptions::default())?;
//! assert!(fit.converged);
//! assert!((fit.params[0] - 0.2).abs() < 5.0 * fit.std_errors.as_ref().unwrap()[0]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

mod boundary;
mod covariance;
mod criterion;
mod data;
mod error;
mod fit;
mod flatness;
mod init;
pub mod ml;
pub mod montecarlo;
mod noise;
mod parseval;
mod profile;
pub mod solver;
mod structure;

pub use criterion::{Bcls, BoxJenkins, Criterion, FrequencyData, Ls, WeightedBcls};
pub use data::Record;
pub use error::EstimateError;
pub use fit::{estimate, Estimate, EstimateOptions, FitProblem, Frequencies};
pub use flatness::{residual_flatness, FLATNESS_BANDS, FLATNESS_LIMIT, FLATNESS_MIN_PER_BAND};
pub use init::{
    fit_rational, initial_model, initialize, InitError, InitOptions, InitialModel, RationalFit,
};
pub use noise::{ArmaNoise, NoiseModel, WhiteNoise, WithFloor};
pub use profile::{profile_uniform_sum, ProfileEstimate};
pub use structure::ModelStructure;
