//! The jitter's own dependence on the sampling interval (`[design] jitter_exponent`).
//!
//! A sensor's timing error need not be fixed in seconds when its sampling interval changes: a
//! clock's phase noise is (exponent 0), an oscillator that drifts freely between samples
//! accumulates `√T` (exponent ½), and a sampler whose delay is a fraction of its period, such
//! as a wheel-speed sensor whose instants are set by the teeth passing, scales with `T`
//! (exponent 1). A design that changes `T` then also changes the jitter: at interval `T` the
//! jitter is the file's family with standard deviation `σ₀ (T / T₀)^α`, its shape kept
//! (`from_std_dev`, as a robust design's prior draws move it), `σ₀` and `T₀` the file's.

use crate::error::StudyResult;
use crate::experiment::Experiment;
use crate::study_err;
use jitterid::jitter::{AnyJitter, JitterModel};

/// `exp` with its jitter (truth and fitted model) at its own interval, for a file whose jitter
/// `file_jitter` was stated at interval `file_interval`, under exponent `alpha`; unchanged
/// when nothing moves (`α = 0`, the file's interval, or a jitter without spread).
///
/// # Errors
///
/// The moved jitter is invalid (its spread not representable); the message names
/// `[design] jitter_exponent` and the interval.
pub(crate) fn at_interval(
    mut exp: Experiment,
    file_jitter: &AnyJitter,
    file_interval: f64,
    alpha: f64,
) -> StudyResult<Experiment> {
    let interval = exp.grid.interval();
    let sigma = file_jitter.std_dev();
    if alpha == 0.0 || interval == file_interval || !(sigma > 0.0) {
        return Ok(exp);
    }
    let scaled = sigma * (interval / file_interval).powf(alpha);
    let moved = exp
        .registries
        .jitter
        .from_std_dev(file_jitter.family(), scaled, &file_jitter.spec())
        .map_err(|e| {
            study_err!(
                "{}: [design] jitter_exponent: the jitter at the interval {interval} s (σ = {scaled} s): {e}",
                exp.file
            )
        })?;
    exp.jitter.truth = moved.clone();
    exp.jitter.model = moved;
    Ok(exp)
}
