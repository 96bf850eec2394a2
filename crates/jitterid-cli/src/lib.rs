//! The `jitterid` command line: argument parsing, one module per subcommand, output files,
//! SVG figures and a progress bar, on the study layer ([`jitterid_study`]), which decides
//! everything about the model. See `docs/experiments.md`.
//!
//! The binary is a thin wrapper around [`run`]; the modules are public so that tests can reach
//! them directly.
#![warn(missing_docs)]

pub mod cli;
pub mod commands;
pub mod exit;
pub mod output;
pub mod plots;
pub mod progress;
pub mod svg;

pub use cli::run;
