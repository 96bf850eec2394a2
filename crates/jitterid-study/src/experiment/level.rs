//! `[input] level` and `estimate_level`: the input's operating point `u₀`, written into the
//! spec table of the system the input drives (`level`, `estimate_level`), where the signal
//! registry builds the response to `u − u₀` ([`jitterid::signal::InputLevel`]).
//!
//! A level is estimated only where the record can tell it apart: with the system (it is one
//! of its parameters, so the system must be estimated), and not beside another constant. A
//! system whose step response settles to `G(0)` turns `u₀` into the constant `−G(0) u₀` once
//! the input's first step has decayed, which an estimated output offset (or another input's
//! estimated level) also is; with an integrator the level is a ramp and stands on its own.

use super::diagnostics::Source;
use super::range;
use super::raw::RawInput;
use super::spec::{InputChannel, InputSpec, SystemSpec};
use crate::error::StudyResult;
use jitterid::signal::registry::{SpecTable, KIND_KEY};
use jitterid::signal::superposition::SUPERPOSITION_KIND;
use jitterid::signal::{Input, PiecewiseConstant, RationalModel, TransferFunction};
use serde_json::{json, Value};

const S: &str = "input";

/// One input's level as read: its place among the inputs and where its keys are written.
struct Level<'a> {
    index: usize,
    /// Whether the file has several inputs (messages then name the `[[input]]` table).
    several: bool,
    raw: &'a RawInput,
    estimated: bool,
}

/// Writes each input's `level` and `estimate_level` into the spec table of the system it
/// drives, after `[output]` has written the offset (whose estimate decides what a level may
/// estimate beside it).
pub(super) fn level_keys(
    cx: &Source,
    inputs: &[&RawInput],
    channels: &[InputChannel],
    system: &mut SystemSpec,
) -> StudyResult<()> {
    let multi = system.kind.get(KIND_KEY) == Some(&Value::from(SUPERPOSITION_KIND));
    let shared = system.kind.get("shared") == Some(&Value::Bool(true));
    let offset_estimated = system.kind.get("estimate_offset") == Some(&Value::Bool(true));
    // The constant in the output estimated so far (what a further one would be confounded
    // with), and the key that asked for it.
    let mut constant: Option<(String, &'static str)> =
        offset_estimated.then(|| ("the output offset".into(), "[output] estimate_offset"));
    for (index, raw) in inputs.iter().enumerate() {
        if raw.level.is_none() && raw.estimate_level.is_none() {
            continue;
        }
        let level = Level {
            index,
            several: inputs.len() > 1,
            raw,
            estimated: raw.estimate_level.as_ref().is_some_and(|e| *e.get_ref()),
        };
        let key = if raw.level.is_some() {
            "level"
        } else {
            "estimate_level"
        };
        let name = channels.get(index).map_or("u", |c| c.name.as_str());
        let (table, estimate) = target(system, multi, index);
        let Some(table) = table else {
            return Err(cx.err_at(
                S,
                key,
                raw.level.as_ref(),
                "the system has no input to take a level",
            ));
        };
        let kind = table
            .get(KIND_KEY)
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_string();
        let takes = cx
            .registries
            .signal
            .kind(&kind)
            .is_some_and(|k| k.params().iter().any(|p| p.key == "level"));
        if !takes {
            return Err(refuse(cx, &level, key, format!("the system kind \"{kind}\" takes no input level; expected kind = \"zpk\", \"tf\" or \"grey-box\"")));
        }
        let u0 = match &raw.level {
            Some(v) => cx.checked(S, "level", v, range::level)?,
            None => 0.0,
        };
        if level.estimated && !estimate {
            return Err(refuse(cx, &level, "estimate_level", "the level is estimated with the system it drives; expected that system's estimate = true (or estimate_level = false)"));
        }
        if level.estimated && shared {
            return Err(refuse(cx, &level, "estimate_level", "a grey-box model with a column of b per input has one set of parameters for all its inputs; give the level as known, or write one [[system]] per input to estimate it"));
        }
        table.insert("level".into(), json!(u0));
        if level.estimated {
            table.insert("estimate_level".into(), json!(true));
        }
        let tones = channels
            .get(index)
            .is_some_and(|c| matches!(c.spec, InputSpec::Known(Input::Tones(_))));
        let model = rational_of(cx, table, &level)?;
        if tones && model.rational().has_pole_at_origin() {
            return Err(refuse(cx, &level, key, format!("input \"{name}\" is a sine or multisine, on at all times, and the system has an integrator: its steady-state response to a constant level is unbounded; remove the level or use an input made of steps")));
        }
        if level.estimated && model.rational().settles() {
            if let Some((other, other_key)) = &constant {
                return Err(refuse(cx, &level, "estimate_level", format!(
                    "input \"{name}\"'s level is confounded with {other} ({other_key}): the system's step response settles to G(0), so the level moves the output by the constant −G(0)·u₀, as {other} does; estimate one of them and give the other as known (a level is estimated on its own with an integrator, whose response to it is a ramp)"
                )));
            }
            constant = Some((
                format!("input \"{name}\"'s level"),
                "[input] estimate_level",
            ));
        }
    }
    Ok(())
}

/// The spec table of the system input `index` drives, and whether it is estimated: the
/// system's own for one input, its channel's in a multi-input system.
fn target(system: &mut SystemSpec, multi: bool, index: usize) -> (Option<&mut SpecTable>, bool) {
    if !multi {
        let estimate = system.estimate;
        return ((index == 0).then_some(&mut system.kind), estimate);
    }
    let estimate = system
        .kind
        .get("estimate")
        .and_then(Value::as_array)
        .and_then(|e| e.get(index))
        .and_then(Value::as_bool)
        .unwrap_or(false);
    let table = system
        .kind
        .get_mut("channels")
        .and_then(Value::as_array_mut)
        .and_then(|c| c.get_mut(index))
        .and_then(Value::as_object_mut);
    (table, estimate)
}

/// The refusal of `level`'s `key`, naming its input table (`[[input]] 2`) in a file with
/// several.
fn refuse(
    cx: &Source,
    level: &Level<'_>,
    key: &str,
    msg: impl std::fmt::Display,
) -> crate::StudyError {
    let msg = match level.several {
        true => format!("[[input]] {}: {msg}", level.index + 1),
        false => msg.to_string(),
    };
    match key {
        "level" => cx.err_at(S, key, level.raw.level.as_ref(), msg),
        _ => cx.err_at(S, key, level.raw.estimate_level.as_ref(), msg),
    }
}

/// The transfer function of the system in `table` (without its response keys), for what its
/// poles say about the level.
fn rational_of(cx: &Source, table: &SpecTable, level: &Level<'_>) -> StudyResult<TransferFunction> {
    let step = PiecewiseConstant::new(vec![0.0, 1.0], vec![1.0])
        .map_err(|e| refuse(cx, level, "level", e))?;
    let signal = cx
        .registries
        .signal
        .build(table, Some(&step.into()))
        .map_err(|e| refuse(cx, level, "level", format!("the system it drives: {e}")))?;
    let tf = crate::export::tf_of(&signal)
        .ok()
        .flatten()
        .ok_or_else(|| {
            refuse(
                cx,
                level,
                "level",
                "the system it drives has no transfer function",
            )
        })?;
    TransferFunction::new_allowing_unstable(tf.num(), tf.den())
        .map_err(|e| refuse(cx, level, "level", format!("the system it drives: {e}")))
}
