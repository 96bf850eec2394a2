//! `[input]`: the input driving a rational system, one kind per table.

use super::checks::finite_value;
use super::diagnostics::Source;
use super::paths;
use super::range;
use super::raw::RawInput;
use super::spec::{InputChannel, InputSpec, SystemSpec};
use crate::csvio;
use crate::error::StudyResult;
use crate::inputs::{input_span, piecewise, piecewise_from_table};
use crate::study_err;
use jitterid::signal::registry::KIND_KEY;
use jitterid::signal::{Input, Multisine, RandomBinary, SampleGrid, Tone};
use toml::Spanned;

/// Largest expected number of switches of a random binary input over its span: the
/// library's limit on an input's switches ([`jitterid::limits::MAX_SWITCHES`]).
pub const MAX_SWITCHES: f64 = jitterid::limits::MAX_SWITCHES as f64;

const S: &str = "input";
const KINDS: &str = "\"random-binary\", \"sine\", \"multisine\", \"piecewise\" or \"csv\"";

/// The input of `system`: none for a kind without one (a sinusoid), required for a kind the
/// signal registry drives by an input (a rational system), with its history before `t0` in
/// seconds (`[input] history`, 0 unless given) and its name (`u` unless given).
pub(super) fn parse_input_section(
    cx: &Source,
    r: Option<&RawInput>,
    system: &SystemSpec,
    grid: &SampleGrid,
) -> StudyResult<Vec<InputChannel>> {
    let name = system
        .kind
        .get(KIND_KEY)
        .and_then(|k| k.as_str())
        .unwrap_or("");
    let needs_input = cx
        .registries
        .signal
        .kind(name)
        .is_some_and(|k| k.needs_input());
    let why = format!("a {name} system has no input; remove the [input] section");
    match (needs_input, r) {
        (false, None) => Ok(Vec::new()),
        (false, Some(r)) => Err(cx.err_at(S, "kind", r.kind.as_ref(), why)),
        (true, None) => Err(study_err!(
            "{}: missing section [input]; a {name} system needs an input (kind = {KINDS})",
            cx.file,
        )),
        (true, Some(r)) => Ok(vec![parse_channel(cx, r, grid, "u")?]),
    }
}

/// One input: its name (`default_name` unless given), kind and history.
pub(super) fn parse_channel(
    cx: &Source,
    r: &RawInput,
    grid: &SampleGrid,
    default_name: &str,
) -> StudyResult<InputChannel> {
    let history = cx.opt_checked(S, "history", &r.history, 0.0, |h| range::history(h, grid))?;
    let name = match &r.name {
        None => default_name.to_string(),
        Some(n) => {
            let name = n.get_ref();
            input_name(name).map_err(|m| cx.err(S, "name", &n.span(), m))?;
            name.clone()
        }
    };
    Ok(InputChannel {
        name,
        spec: parse_input(cx, r, grid, history)?,
        history,
    })
}

/// Columns of a record's files that an input's name would collide with, and the name of the
/// output offset's parameter (an input's name prefixes its channel's parameters).
const RESERVED: &[&str] = &["k", "t", "y", "tau", "v", "offset"];

/// An input's name: it names the input's column in a record's input file and prefixes its
/// channel's parameters (`brake.a0`), so it is a word of ASCII letters, digits, `_` and `-`,
/// starting with a letter, and not a column the files already have.
fn input_name(name: &str) -> Result<(), String> {
    let ok = name.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if !ok {
        return Err(format!(
            "expected a name of ASCII letters, digits, _ and -, starting with a letter, found \"{name}\""
        ));
    }
    if RESERVED.contains(&name) {
        return Err(format!(
            "\"{name}\" is a column of the record's files or a parameter's name; expected another name"
        ));
    }
    Ok(())
}

/// The level's keys, which every kind takes ([`super::level`]).
const LEVEL: &str = "level";
const ESTIMATE: &str = "estimate_level";

fn parse_input(
    cx: &Source,
    r: &RawInput,
    grid: &SampleGrid,
    history: f64,
) -> StudyResult<InputSpec> {
    let kind = cx.required(S, "kind", &r.kind, &format!("expected kind = {KINDS}"))?;
    let name = kind.get_ref().as_str();
    let allowed: &[&str] = match name {
        "random-binary" => &[
            "name",
            "kind",
            "mean_dwell",
            "low",
            "high",
            "history",
            LEVEL,
            ESTIMATE,
        ],
        "sine" => &[
            "name",
            "kind",
            "frequency",
            "amplitude",
            "phase",
            LEVEL,
            ESTIMATE,
        ],
        "multisine" => &[
            "name",
            "kind",
            "frequencies",
            "amplitudes",
            "phases",
            LEVEL,
            ESTIMATE,
        ],
        "piecewise" => &["name", "kind", "times", "values", LEVEL, ESTIMATE],
        "csv" => &[
            "name",
            "kind",
            "path",
            "time_column",
            "value_column",
            LEVEL,
            ESTIMATE,
        ],
        other => {
            return Err(cx.err(
                S,
                "kind",
                &kind.span(),
                format!("unknown input kind \"{other}\"; expected {KINDS}"),
            ))
        }
    };
    cx.only(S, &r.present(), "kind", allowed, name)?;
    match name {
        "random-binary" => random_binary(cx, r, grid, history),
        "sine" => sine(cx, r, grid),
        "multisine" => multisine(cx, r, grid),
        "piecewise" => piecewise_levels(cx, r, grid),
        _ => csv_file(cx, r, grid),
    }
}

/// A random binary input, drawn on `[t0 − history, t0 + (N+1)T)`.
fn random_binary(
    cx: &Source,
    r: &RawInput,
    grid: &SampleGrid,
    history: f64,
) -> StudyResult<InputSpec> {
    let dwell = cx.required(
        S,
        "mean_dwell",
        &r.mean_dwell,
        "expected the mean time between switches in seconds",
    )?;
    let mean_dwell = cx.positive(S, "mean_dwell", dwell)?;
    let low = cx.opt_checked(S, "low", &r.low, 0.0, range::level)?;
    let high = cx.opt_checked(S, "high", &r.high, 1.0, range::level)?;
    let (a, b) = input_span(grid);
    let a = a - history;
    if (b - a) / mean_dwell > MAX_SWITCHES || mean_dwell < 1e-9 * a.abs().max(b.abs()) {
        return Err(cx.err(
            S,
            "mean_dwell",
            &dwell.span(),
            format!(
                "too short for a record of {} s (at most {MAX_SWITCHES:e} switches)",
                b - a
            ),
        ));
    }
    let rb = RandomBinary::new(mean_dwell, low, high)
        .map_err(|e| cx.err(S, "mean_dwell", &dwell.span(), e))?;
    Ok(InputSpec::RandomBinary(rb))
}

fn sine(cx: &Source, r: &RawInput, grid: &SampleGrid) -> StudyResult<InputSpec> {
    let f = cx.required(S, "frequency", &r.frequency, "expected the frequency in Hz")?;
    let frequency = cx.checked(S, "frequency", f, |f| range::frequency(f, grid))?;
    if frequency < 0.0 {
        return Err(cx.err(
            S,
            "frequency",
            &f.span(),
            format!("expected a frequency >= 0 Hz, found {frequency}"),
        ));
    }
    let amplitude = cx.opt_checked(S, "amplitude", &r.amplitude, 1.0, range::level)?;
    let phase = cx.opt_finite(S, "phase", &r.phase, 0.0)?;
    let m = Multisine::sine(frequency, amplitude, phase)
        .map_err(|e| cx.err(S, "frequency", &f.span(), e))?;
    Ok(InputSpec::Known(Input::Tones(m)))
}

fn multisine(cx: &Source, r: &RawInput, grid: &SampleGrid) -> StudyResult<InputSpec> {
    let fs = cx.required(
        S,
        "frequencies",
        &r.frequencies,
        "expected a list of frequencies in Hz",
    )?;
    let freqs = cx.checked_list(S, "frequencies", fs, |f| {
        finite_value(f).and_then(|f| range::frequency(f, grid))
    })?;
    if freqs.is_empty() {
        return Err(cx.err(
            S,
            "frequencies",
            &fs.span(),
            "expected at least one frequency",
        ));
    }
    if let Some(f) = freqs.iter().find(|f| **f < 0.0) {
        return Err(cx.err(
            S,
            "frequencies",
            &fs.span(),
            format!("expected frequencies >= 0 Hz, found {f}"),
        ));
    }
    let amps = per_tone(cx, "amplitudes", &r.amplitudes, freqs.len(), 1.0)?;
    if let Some(v) = &r.amplitudes {
        cx.level_list(S, "amplitudes", v)?;
    }
    let phases = per_tone(cx, "phases", &r.phases, freqs.len(), 0.0)?;
    let tones = freqs
        .iter()
        .zip(&amps)
        .zip(&phases)
        .map(|((&frequency, &amplitude), &phase)| Tone {
            frequency,
            amplitude,
            phase,
        })
        .collect();
    let m = Multisine::new(tones).map_err(|e| cx.err(S, "frequencies", &fs.span(), e))?;
    Ok(InputSpec::Known(Input::Tones(m)))
}

/// One value per tone of a multisine, or `default` for each.
fn per_tone(
    cx: &Source,
    key: &str,
    v: &Option<Spanned<Vec<f64>>>,
    tones: usize,
    default: f64,
) -> StudyResult<Vec<f64>> {
    let Some(v) = v else {
        return Ok(vec![default; tones]);
    };
    let l = cx.finite_list(S, key, v)?;
    if l.len() != tones {
        return Err(cx.err(
            S,
            key,
            &v.span(),
            format!(
                "expected {tones} values (one per frequency), found {}",
                l.len()
            ),
        ));
    }
    Ok(l)
}

fn piecewise_levels(cx: &Source, r: &RawInput, grid: &SampleGrid) -> StudyResult<InputSpec> {
    let ts = cx.required(S, "times", &r.times, "expected the switch times in seconds")?;
    let vs = cx.required(
        S,
        "values",
        &r.values,
        "expected the input level from each switch time on",
    )?;
    let times = cx.finite_list(S, "times", ts)?;
    let values = cx.level_list(S, "values", vs)?;
    let p = piecewise(&times, &values, grid).map_err(|m| cx.err(S, "times", &ts.span(), m))?;
    Ok(InputSpec::Known(Input::Piecewise(p)))
}

fn csv_file(cx: &Source, r: &RawInput, grid: &SampleGrid) -> StudyResult<InputSpec> {
    let p = cx.required(
        S,
        "path",
        &r.path,
        "expected the path of a CSV file (relative to the experiment file)",
    )?;
    let tc = r.time_column.as_ref().map_or("t", |s| s.get_ref().as_str());
    let vc = r
        .value_column
        .as_ref()
        .map_or("u", |s| s.get_ref().as_str());
    let file = paths::resolve(cx, S, "path", p)?;
    let table = csvio::read_as(&file.open, &file.name)?;
    let p = piecewise_from_table(&table, tc, vc, grid)?;
    Ok(InputSpec::Known(Input::Piecewise(p)))
}
