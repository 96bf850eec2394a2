//! `[sampling]`: the grid `t_k = t0 + kT`.

use super::diagnostics::Source;
use super::range::{MAX_INTERVAL, MIN_INTERVAL};
use super::raw::RawSampling;
use crate::csvio;
use crate::error::{StudyErrorKind, StudyResult};
use crate::study_err;
use jitterid::signal::SampleGrid;
use std::path::Path;

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

/// The `[sampling]` keys a document lacks, as edits from the data file at `data`: `samples`
/// its row count, `start` its first `t`, `interval` the step of its `t` column, which must then
/// be a uniform grid (every `t` within `10⁻⁶ T` of `t0 + kT`, the tolerance a fit holds the
/// column to).
///
/// # Errors
///
/// The file cannot be read; `interval` is missing and the file has no `t` column or one row;
/// or a row's `t` is off the grid its first and last rows span (of kind
/// [`StudyErrorKind::NotUniformGrid`], naming the file, the line and the value).
pub(super) fn from_data(
    data: &Path,
    missing: &[&'static str],
) -> StudyResult<Vec<super::overrides::Override>> {
    use super::overrides::Override;
    use toml_edit::Value;
    let mut rows = csvio::open_rows(data, &data.display().to_string())?;
    let name = rows.name().to_string();
    let it = rows.index("t");
    // The instants and their lines, kept only when the grid is read from them.
    let mut t: Vec<(usize, f64)> = Vec::new();
    while let Some((line, row)) = rows.next_row()? {
        if let Some(j) = it {
            t.push((line, row[j]));
        }
    }
    let n = rows.rows();
    if n == 0 {
        return Err(rows.no_rows_error().into());
    }
    let origin = |key: &str| format!("[sampling] {key} from {name}");
    let mut edits = Vec::new();
    if missing.contains(&"samples") {
        let count = i64::try_from(n).unwrap_or(i64::MAX);
        edits.push(Override::from_source(
            &["sampling", "samples"],
            Value::from(count),
            origin("samples"),
        ));
    }
    if missing.contains(&"start") {
        if let Some(&(_, t0)) = t.first() {
            edits.push(Override::from_source(
                &["sampling", "start"],
                Value::from(t0),
                origin("start"),
            ));
        }
    }
    if missing.contains(&"interval") {
        let (Some(&(_, t0)), Some(&(_, tn))) = (t.first(), t.last()) else {
            return Err(study_err!(
                "{name}: no column `t`: the experiment's [sampling] interval is not given, so the data file must give the instants"
            ));
        };
        if n < 2 {
            return Err(study_err!(
                "{name}: one row cannot set the sampling interval; give [sampling] interval"
            ));
        }
        let interval = (tn - t0) / (n - 1) as f64;
        if !(interval.is_finite() && interval > 0.0) {
            return Err(study_err!(
                "{name}: column `t`: the instants run from {t0} to {tn}; expected increasing instants t0 + kT"
            ));
        }
        let tol = 1e-6 * interval;
        let grid = SampleGrid::new(t0, interval, n).map_err(|e| study_err!("{name}: {e}"))?;
        if let Some((k, &(line, tk))) = t
            .iter()
            .enumerate()
            .find(|(k, (_, tk))| (tk - grid.time(*k)).abs() > tol + 1e-12 * tk.abs())
        {
            return Err(study_err!(
                "{name}:{line}: column `t`: {tk} is not on the uniform grid t0 + kT (t0 = {t0}, T = {interval} from the first and last rows; row {k} should be {}): give [sampling] interval and samples, or resample the record",
                grid.time(k)
            )
            .with_kind(StudyErrorKind::NotUniformGrid));
        }
        edits.push(Override::from_source(
            &["sampling", "interval"],
            Value::from(interval),
            origin("interval"),
        ));
    }
    Ok(edits)
}
