//! The `jitterid` command line: experiment files, `simulate` / `fit` / `montecarlo` / `merge`,
//! CSV and JSON, SVG figures and a progress bar. See `docs/experiments.md`.
//!
//! The binary is a thin wrapper around [`run`]; the modules are public so that tests can reach
//! the readers directly (for example to fuzz them).
#![warn(missing_docs)]

pub mod cli;
pub mod commands;
pub mod csvio;
pub mod error;
pub mod exit;
pub mod experiment;
pub mod export;
pub mod fingerprint;
pub mod fitting;
pub mod inputs;
pub mod merge;
pub mod output;
pub mod plots;
pub mod progress;
pub mod select;
pub mod svg;
pub mod validate;
pub mod whiten;

pub use cli::run;
