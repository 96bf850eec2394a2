//! The **jitterid** study layer: everything between an experiment file and a report that is not
//! about parsing arguments or printing. Every front end (the `jitterid` command line, the
//! Python package, `cargo xtask`) stands on this crate, so that a Rust program embedding
//! jitterid gets exactly what `jitterid fit`, `montecarlo`, `merge`, `select` and `validate`
//! compute.
//!
//! - [`experiment`]: experiment files (TOML), read once and validated once into an
//!   [`Experiment`](experiment::Experiment); every error names the file, the line and the key.
//! - [`records`]: measured records (the plain numeric CSV files) checked against an
//!   experiment's grid, and their inputs.
//! - [`fit`]: the fit an experiment asks for — the model structure, the solver, profiling an
//!   integer jitter parameter, the jitter floor of a Box–Jenkins noise model, the likelihood
//!   branch — and the parameters as reported (names, estimates, standard errors, covariance).
//! - [`joint`]: joint fits of several records of one system, each with its own input and
//!   length.
//! - [`notes`]: a fit's status line and what the record suggests the model misses (an input
//!   recorded on the sampling clock, an output offset).
//! - [`simulate`]: records of an experiment's truth, realisation by realisation.
//! - [`montecarlo`]: studies of many realisations, bit-identical across thread counts and
//!   shards; [`merge`] combines shards, which carry the experiment's [`fingerprint`].
//! - [`select`]: order and jitter-family selection and the data-driven start (`init = auto`).
//! - [`validate`]: fit percent, residual tests, flatness, frequency and step responses.
//! - [`design`]: the predicted precision of a planned experiment and the design (input
//!   dwell, sampling interval) that makes it most precise under jitter.
//! - [`export`]: a fitted system as zpk, tf and state space, with its Bode and step responses.
//!
//! Errors are one type, [`StudyError`]: one line of text that names what is wrong. Long work
//! reports progress through [`Watch`] hooks that a front end draws as it likes.
#![warn(missing_docs)]

pub mod bode_inputs;
pub mod csvio;
pub mod design;
pub mod error;
pub mod experiment;
pub mod export;
pub mod fingerprint;
pub mod fit;
pub mod inputs;
pub mod joint;
pub mod likelihood_start;
pub mod merge;
pub mod montecarlo;
pub mod notes;
mod rational_start;
pub mod records;
mod registries;
pub mod residual_tests;
pub mod select;
pub mod simulate;
pub mod validate;
mod watch;
pub mod whiten;

pub use error::{StudyError, StudyErrorKind, StudyResult};
pub use registries::Registries;
pub use watch::{RunsDone, Watch};

/// The time limit in seconds of a fit (its search, covariance and, in a study, simulation) and
/// of a selection when the experiment and the front end give none: no command runs unbounded.
pub const DEFAULT_TIME_LIMIT: f64 = 600.0;

/// The budget of one fit or selection of `exp`: its time limit (or [`DEFAULT_TIME_LIMIT`])
/// and `cancel`, under the calling thread's budget.
pub(crate) fn budget_of(
    exp: &experiment::Experiment,
    cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
) -> std::sync::Arc<jitterid::budget::Budget> {
    jitterid::budget::Budget::new(
        Some(exp.estimate.max_seconds.unwrap_or(DEFAULT_TIME_LIMIT)),
        cancel,
    )
}
