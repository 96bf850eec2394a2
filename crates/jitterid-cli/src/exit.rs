//! Exit statuses: what a script may conclude from `$?` alone.

use std::process::ExitCode;

/// The exit status of a command that ran (errors exit with [`BAD_INPUT`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// 0: the fit converged; for `montecarlo`, the study ran and at least one fit converged.
    Success,
    /// 1: the fit did not converge; for `montecarlo`, no fit converged. The results are
    /// printed as usual.
    NotConverged,
}

/// The exit status of an error: bad arguments, a bad experiment or data file, an output that
/// cannot be written, a shard that does not belong.
pub const BAD_INPUT: u8 = 2;

impl Status {
    /// The status for `converged`, or success whatever it is when `accept` is set.
    pub fn of_convergence(converged: bool, accept: bool) -> Self {
        if converged || accept {
            Status::Success
        } else {
            Status::NotConverged
        }
    }

    /// The process exit code.
    pub fn code(self) -> ExitCode {
        match self {
            Status::Success => ExitCode::SUCCESS,
            Status::NotConverged => ExitCode::from(1),
        }
    }
}

/// What a command prints, and how it exits.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Outcome {
    /// Text for standard output.
    pub text: String,
    /// The exit status.
    pub status: Status,
}

impl Outcome {
    /// A successful outcome printing `text`.
    pub fn success(text: String) -> Self {
        Self {
            text,
            status: Status::Success,
        }
    }
}
