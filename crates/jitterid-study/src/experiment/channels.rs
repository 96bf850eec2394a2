//! `[[input]]` and `[[system]]`: a system with several inputs, one model per input in the same
//! order, read into one `superposition` spec table.

use super::diagnostics::Source;
use super::input::parse_channel;
use super::raw::{RawInput, RawSystem};
use super::spec::{InputChannel, InputSpec, SystemSpec};
use super::system::parse_system;
use crate::error::StudyResult;
use crate::study_err;
use jitterid::signal::registry::KIND_KEY;
use jitterid::signal::superposition::spec_table;
use jitterid::signal::{Input, SampleGrid};
use serde_json::Value;
use toml::Spanned;

/// The inputs and the systems of a multi-input experiment (more than one `[[input]]` or
/// `[[system]]` table): as many of each, every system driven by an input, distinct names.
pub(super) fn parse_channels(
    cx: &Source,
    systems: &[&RawSystem],
    inputs: &[&RawInput],
    grid: &SampleGrid,
) -> StudyResult<(SystemSpec, Vec<InputChannel>)> {
    if let [one] = systems {
        if one.kind.as_ref().map(|k| k.get_ref().as_str()) == Some("grey-box") && inputs.len() > 1 {
            return grey_box_inputs(cx, one, inputs, grid);
        }
    }
    if systems.len() != inputs.len() {
        return Err(study_err!(
            "{}: {} [[input]] table(s) and {} [[system]] table(s); a system with several inputs has one [[system]] table per [[input]] table, in the same order",
            cx.file,
            inputs.len(),
            systems.len()
        ));
    }
    let mut channels: Vec<InputChannel> = Vec::with_capacity(inputs.len());
    let mut parts = Vec::with_capacity(systems.len());
    for (i, (rs, ri)) in systems.iter().zip(inputs).enumerate() {
        let system = parse_system(cx, rs, grid)?;
        let kind = system
            .kind
            .get(KIND_KEY)
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_string();
        if !cx
            .registries
            .signal
            .kind(&kind)
            .is_some_and(|k| k.needs_input())
        {
            return Err(cx.err_at(
                "system",
                "kind",
                rs.kind.as_ref(),
                format!(
                    "[[system]] {}: a {kind} system has no input; each [[system]] table of a multi-input system is the response to its [[input]] (kind = \"zpk\", \"tf\" or \"grey-box\")",
                    i + 1
                ),
            ));
        }
        let channel = parse_channel(cx, ri, grid, &format!("u{}", i + 1))?;
        distinct(cx, &channels, &channel, ri, i)?;
        if let (Some(d), InputSpec::Known(Input::Tones(_))) = (&rs.delay, &channel.spec) {
            return Err(cx.err(
                "system",
                "delay",
                &d.span(),
                format!(
                    "[[system]] {}: needs an input made of steps (random-binary, piecewise or csv); input \"{}\" is a sine or multisine, whose delay is a phase",
                    i + 1,
                    channel.name
                ),
            ));
        }
        parts.push((channel.name.clone(), system.kind, system.estimate));
        channels.push(channel);
    }
    let estimate = parts.iter().any(|p| p.2);
    let kind = spec_table(parts, false);
    Ok((SystemSpec { kind, estimate }, channels))
}

/// Refuses `channel` (read from `[[input]]` table `i`, counted from 0) when an input read
/// before it has its name.
fn distinct(
    cx: &Source,
    before: &[InputChannel],
    channel: &InputChannel,
    ri: &RawInput,
    i: usize,
) -> StudyResult<()> {
    match before.iter().find(|c| c.name == channel.name) {
        None => Ok(()),
        Some(other) => Err(cx.err_at(
            "input",
            "name",
            ri.name.as_ref(),
            format!(
                "[[input]] {}: the name \"{}\" is already the name of another input; expected distinct names",
                i + 1,
                other.name
            ),
        )),
    }
}

/// One grey-box `[system]` whose `B` and `D` have a column per `[[input]]`: one channel per
/// input, the model with only that column, sharing the model's parameters
/// ([`jitterid::signal::Superposition::shared`]).
fn grey_box_inputs(
    cx: &Source,
    rs: &RawSystem,
    inputs: &[&RawInput],
    grid: &SampleGrid,
) -> StudyResult<(SystemSpec, Vec<InputChannel>)> {
    let m = inputs.len();
    if let Some(i) = rs.initial.as_ref().filter(|i| i.get_ref() == "estimate") {
        // The channels share every parameter, so each would add the same free response.
        return Err(cx.err(
            "system",
            "initial",
            &i.span(),
            "a grey-box model with a column of b per input has one state, shared by its inputs, and its free response would be added once per input; write one [[system]] per input to estimate each response's free part, or start the record at rest".to_string(),
        ));
    }
    let columns = |key: &str, v: &Spanned<toml::Value>, rows: Option<usize>| {
        let bad = |msg: String| cx.err("system", key, &v.span(), msg);
        let toml::Value::Array(r) = v.get_ref() else {
            return Err(bad(format!(
                "expected an array of rows with {m} entries each (one per [[input]])"
            )));
        };
        if let Some(n) = rows {
            if r.len() != n {
                return Err(bad(format!("expected {n} row(s), found {}", r.len())));
            }
        }
        let mut out = vec![Vec::with_capacity(r.len()); m];
        for (i, row) in r.iter().enumerate() {
            let entries = match row {
                toml::Value::Array(e) if e.len() == m => e,
                toml::Value::Array(e) => {
                    return Err(bad(format!(
                        "row {}: expected {m} entries (one column per [[input]]), found {}",
                        i + 1,
                        e.len()
                    )))
                }
                _ => {
                    return Err(bad(format!(
                        "row {}: expected an array of {m} entries",
                        i + 1
                    )))
                }
            };
            for (j, e) in entries.iter().enumerate() {
                out[j].push(toml::Value::Array(vec![e.clone()]));
            }
        }
        Ok(out
            .into_iter()
            .map(|rows| Spanned::new(v.span(), toml::Value::Array(rows)))
            .collect::<Vec<_>>())
    };
    let b = rs.b.as_ref().ok_or_else(|| {
        cx.err_section(
            "system",
            "b",
            "kind = \"grey-box\" needs params, a, b and c (and optionally fixed, bounds, d)",
        )
    })?;
    let b = columns("b", b, None)?;
    let d = match &rs.d {
        Some(d) => Some(columns("d", d, Some(1))?),
        None => None,
    };
    let mut channels: Vec<InputChannel> = Vec::with_capacity(m);
    let mut parts = Vec::with_capacity(m);
    let mut estimate = false;
    for (j, ri) in inputs.iter().enumerate() {
        let mut column = rs.clone();
        column.b = Some(b[j].clone());
        column.d = d.as_ref().map(|d| d[j].clone());
        let system = parse_system(cx, &column, grid)?;
        let channel = parse_channel(cx, ri, grid, &format!("u{}", j + 1))?;
        distinct(cx, &channels, &channel, ri, j)?;
        estimate = system.estimate;
        parts.push((channel.name.clone(), system.kind, system.estimate));
        channels.push(channel);
    }
    let kind = spec_table(parts, true);
    Ok((SystemSpec { kind, estimate }, channels))
}
