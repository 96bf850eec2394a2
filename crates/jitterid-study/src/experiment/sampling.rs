//! `[sampling]`: the grid `t_k = t0 + kT`.

use super::diagnostics::Source;
use super::range::{MAX_INTERVAL, MIN_INTERVAL};
use super::raw::RawSampling;
use crate::error::StudyResult;
use jitterid::signal::SampleGrid;

/// Largest number of samples accepted: the library's limit
/// ([`jitterid::limits::MAX_SAMPLES`]).
pub const MAX_SAMPLES: i64 = jitterid::limits::MAX_SAMPLES as i64;

const S: &str = "sampling";

pub(super) fn parse_sampling(cx: &Source, r: &RawSampling) -> StudyResult<SampleGrid> {
    let interval = cx.required(
        S,
        "interval",
        &r.interval,
        "expected the sampling interval T in seconds",
    )?;
    cx.positive(S, "interval", interval)?;
    let interval = cx.checked(S, "interval", interval, |t| {
        if (MIN_INTERVAL..=MAX_INTERVAL).contains(&t) {
            Ok(t)
        } else {
            Err(format!(
                "expected a sampling interval in [{MIN_INTERVAL:e}, {MAX_INTERVAL:e}] s, found {t:e}"
            ))
        }
    })?;
    let samples = cx.required(S, "samples", &r.samples, "expected the number of samples N")?;
    let n = *samples.get_ref();
    if !(1..=MAX_SAMPLES).contains(&n) {
        return Err(cx.err(
            S,
            "samples",
            &samples.span(),
            format!("expected a whole number in [1, {MAX_SAMPLES}], found {n}"),
        ));
    }
    let start = cx.opt_finite(S, "start", &r.start, 0.0)?;
    let end = start + n as f64 * interval;
    if !end.is_finite() || (end - start) <= 0.0 || interval <= end.abs().max(start.abs()) * 1e-12 {
        let span = r.interval.as_ref().map(|s| s.span()).unwrap_or(0..0);
        return Err(cx.err(
            S,
            "interval",
            &span,
            "too small for the record's times to be told apart in double precision",
        ));
    }
    SampleGrid::new(start, interval, n as usize).map_err(|e| cx.err_section(S, "interval", e))
}
