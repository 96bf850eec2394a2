//! Experiment design under jitter: how precise will an estimate be, and which experiment makes
//! it most precise, before any data exist.
//!
//! With jitter the usual advice for identification experiments fails: a fast-switching input
//! excites frequencies where the jitter's characteristic function `γ(f)` damps the signal and
//! where the jitter adds noise of variance `≈ σ_τ² s′(t)²` right after every switch, while a
//! slow one leaves the dynamics unexcited. The best dwell and sampling interval therefore
//! depend on the jitter law, and this module computes them from a prior model (the
//! experiment's truth).
//!
//! - [`predict`]: the expected covariance of BCLS (the fit's own sandwich at the truth on the
//!   expected record) or of exact ML (the inverse exact Fisher information), averaged over
//!   seeded draws of a random input; [`derived_std`] for the static gain, a gain at one
//!   frequency, a pole's natural frequency and the jitter's σ by the delta method, the ones a
//!   report gives chosen by [`DerivedRequest`] (`[design] derived`).
//! - [`criterion_value`]: D-, A- or one parameter's optimality.
//! - [`Plan`], [`Design`]: the experiment file as a document that each candidate design edits
//!   and reads again, so every candidate is validated like a written file.
//! - [`jitter_blind`]: the same search with the jitter ignored (`γ ≡ 1`), and [`evaluate`]:
//!   any design under the true prior, so the two can be compared on jittered data.
//! - [`monte_carlo`]: a design checked by realisations on jittered data, with the Monte
//!   Carlo's standard errors.
//! - [`designed_input`]: a design's input realisation as a CSV input file and the experiment
//!   file that reads it, ready for `simulate` and `fit`.
//! - [`MultisineDesign`]: a multisine input's tones designed over a band under a power or
//!   peak constraint, with phases that lower the crest factor ([`low_crest_phases`]).
//! - [`optimise`], [`design()`]: the seeded, deterministic search over the `[design]` ranges and
//!   the report that sets the result beside the file's own design.
//! - [`DesignProgress`]: what the searches report while they run, to the observer a plan
//!   carries ([`Plan::with_observer`]).

mod blind;
mod candidate;
mod check;
mod crest;
mod criterion;
mod dac;
mod derived;
mod derived_choice;
mod jitter_scaling;
mod multisine;
mod plan;
mod predict;
mod prior;
mod progress;
mod realization;
mod report;
mod search;
mod written;

pub use blind::{evaluate, jitter_blind, JitterBlind};
pub use candidate::Design;
pub use check::{criterion_difference, monte_carlo, MonteCarloCheck};
pub use crest::{low_crest_phases, peak, rms, schroeder_phases};
pub use criterion::{covariance_criterion, criterion_value};
pub use dac::dac_samples;
pub use derived::{derived_std, Derived};
pub use derived_choice::{requested_stds, DerivedRequest, DERIVED_EXPECTED};
pub use multisine::{log_spaced_harmonics, MultisineDesign};
pub use plan::Plan;
pub use predict::{predict, Prediction};
pub use prior::prior_experiments;
pub use progress::{DesignObserver, DesignProgress};
pub use report::{
    derived_stds, design, BlindJson, DesignJson, DesignReport, PredictedDesign, PredictedStd,
};
pub use search::{optimise, Optimum};
pub use written::{designed_input, DesignedInput};
