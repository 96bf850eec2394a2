//! Whether the chosen method can fit what the file marks as estimated: checked once, with the
//! rest of the file, so that a command never meets an experiment it cannot run.

use super::diagnostics::Source;
use super::raw::RawExperiment;
use super::spec::{JitterSpec, Method, NoiseSpec, SystemSpec};
use crate::error::{StudyError, StudyResult};
use crate::study_err;

/// The parts of an experiment that decide which methods apply.
pub(super) struct Estimated<'a> {
    pub(super) system: &'a SystemSpec,
    pub(super) jitter: &'a JitterSpec,
    pub(super) noise: &'a NoiseSpec,
}

/// Refuses a method that cannot fit the estimated parts; an error names `--method` when the
/// method came from the command line, else the file's `[estimate] method`.
pub(super) fn check_method(
    cx: &Source,
    raw: &RawExperiment,
    parts: &Estimated,
    method: Method,
    from_command_line: bool,
) -> StudyResult<()> {
    let blame = |msg: &str| -> StudyError {
        if from_command_line {
            study_err!("--method {}: {msg}", method.as_str())
        } else {
            let key = raw.estimate.as_ref().and_then(|e| e.method.as_ref());
            cx.err_at("estimate", "method", key, msg)
        }
    };
    let flag = raw
        .system
        .as_ref()
        .and_then(|s| s.first())
        .and_then(|s| s.estimate.as_ref());
    let at_system = |msg: &str| cx.err_at("system", "estimate", flag, msg);
    if method.is_likelihood_in(&cx.registries.criteria) && !cfg!(feature = "ml") {
        return Err(blame(
            "maximum likelihood is not available in this build of jitterid (built without the `ml` feature); use \"bcls\" (or \"ls\", \"bj\")",
        ));
    }
    if method == Method::LS && parts.jitter.estimate {
        return Err(blame(
            "naive least squares ignores the jitter and cannot estimate it; use \"bcls\" or set [jitter] estimate = false",
        ));
    }
    let (system, jitter, noise) = (
        parts.system.estimate,
        parts.jitter.estimate,
        parts.noise.estimate,
    );
    if !system && !jitter && !noise {
        return Err(at_system(
            "nothing to estimate: set estimate = true in [system], [jitter] or [noise]",
        ));
    }
    if !system && !jitter {
        return Err(at_system(
            "only the noise level is marked for estimation; it is estimated together with the system or the jitter, so set estimate = true in [system] or [jitter]",
        ));
    }
    if method == Method::LS && !system {
        return Err(blame(
            "naive least squares has nothing to estimate when the system is known",
        ));
    }
    Ok(())
}
