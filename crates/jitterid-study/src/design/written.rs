//! A designed experiment ready to apply: the input of a design written as the CSV input file
//! that experiment files read, and the experiment file that reads it.
//!
//! A random binary input is a law, not a signal; what a test rig applies is one realisation
//! of it. The realisation written is draw 0 of the `[design]` seed (the input Monte Carlo run
//! 0 sees), and the experiment written beside it is the planned one with the design's sampling
//! and `[input] kind = "csv"` reading that file, so `jitterid simulate` and `jitterid fit` take
//! the designed experiment as they take any other. The designed dwell and levels live on in the
//! realisation (its switch times and values) and in the written file's header, not as keys,
//! since a CSV input has none of them.
//!
//! A designed multisine is a signal the experiment file states exactly: the experiment
//! written keeps `[input] kind = "multisine"` with the designed frequencies, amplitudes and
//! phases, and the CSV beside it is the sample sequence a DAC plays at its rate
//! ([`dac_samples`]).

use super::candidate::Design;
use super::dac::dac_samples;
use super::multisine::MultisineDesign;
use super::plan::Plan;
use crate::csvio::input_to_csv;
use crate::error::StudyResult;
use crate::experiment::{edited_text, Override};
use crate::simulate::realize_inputs;
use crate::study_err;
use jitterid::estimate::montecarlo::realization_rng;
use jitterid::signal::Input;

/// The files of a designed experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignedInput {
    /// The input file: columns `t,u`, each row a switch time and the level from it on, a last
    /// row of level 0 ending the input.
    pub csv: String,
    /// The experiment file reading it (the planned file with the design's keys, the input
    /// replaced and the `[design]` section left out, since nothing in it is free any more).
    pub experiment: String,
}

/// The designed experiment of `design` under `plan`, its input file named `csv_name` (a file
/// name beside the experiment file to be written).
///
/// # Errors
///
/// The experiment has several inputs or an input that is not random binary (its input is
/// already a signal the file fixes) and no designed multisine; the design's experiment is
/// invalid; the document cannot be edited; a designed multisine without `[design] dac_rate`
/// (which `--dac-rate` sets), or with one that cannot reproduce its tones ([`dac_samples`]).
pub fn designed_input(plan: &Plan, design: &Design, csv_name: &str) -> StudyResult<DesignedInput> {
    if let Some(m) = &design.multisine {
        let rate = plan.spec.multisine.as_ref().and_then(|s| s.dac_rate);
        return designed_multisine(plan, design, m, csv_name, rate);
    }
    let exp = plan.experiment(design)?;
    if exp.inputs.len() != 1 || !exp.random_input() {
        return Err(study_err!(
            "{}: [input]: only a single random binary input is written as a designed input (the file already fixes any other input)",
            exp.file
        ));
    }
    let seed = plan.spec.seed;
    let inputs = realize_inputs(&exp, &mut realization_rng(seed, 0))?;
    let Some(Input::Piecewise(u)) = inputs.first() else {
        return Err(study_err!(
            "{}: [input]: the realisation is not piecewise constant",
            exp.file
        ));
    };
    let origin = |what: &str| format!("[design] {what}");
    let mut edits = plan.edits().to_vec();
    // The design's sampling; its dwell and levels live on in the realisation, not as keys (a
    // CSV input has none, and an edit of them would keep the random binary's keys).
    edits.extend(design.edits().into_iter().filter(|e| {
        !matches!(
            e.key().as_str(),
            "input.mean_dwell" | "input.low" | "input.high"
        )
    }));
    edits.push(Override::from_source(
        &["input", "kind"],
        "csv".into(),
        origin("input"),
    ));
    edits.push(Override::from_source(
        &["input", "path"],
        csv_name.into(),
        origin("input"),
    ));
    let text = edited_text(&exp.file, plan.text(), &edits)?;
    let mut doc: toml_edit::DocumentMut = text
        .parse()
        .map_err(|e| study_err!("{}: the edited document: {e}", exp.file))?;
    doc.remove("design");
    write_scaled_jitter(plan, &exp, &mut doc)?;
    let dwell = design
        .mean_dwell
        .map_or(String::new(), |m| format!(" with mean dwell {m} s"));
    // The designed levels, which the realisation takes; the file's own when not designed.
    let levels = match super::realization::levels_of(&exp) {
        Some((low, high)) if design.low.is_some() || design.high.is_some() => {
            format!(" between the designed levels low = {low} and high = {high}")
        }
        _ => String::new(),
    };
    let header = format!(
        "# Designed by `jitterid design` from {}: the input is realisation 0 of seed {seed} of the\n\
         # random binary input{dwell}{levels}, in {csv_name}.\n",
        exp.file
    );
    Ok(DesignedInput {
        csv: input_to_csv(u),
        experiment: header + &doc.to_string(),
    })
}

/// Writes the jitter of `exp` (the design's experiment) into `doc` when it is not the file's:
/// under `[design] jitter_exponent` a design at another interval has another jitter, and the
/// experiment written for it must simulate that one. The family's keys are written as the
/// registry states them.
///
/// # Errors
///
/// A jitter whose keys are not numbers (a family of terms), which the `[jitter]` table of
/// the written file cannot take one key at a time; the message names the key.
fn write_scaled_jitter(
    plan: &Plan,
    exp: &crate::experiment::Experiment,
    doc: &mut toml_edit::DocumentMut,
) -> StudyResult<()> {
    if exp.jitter.truth == plan.baseline.jitter.truth {
        return Ok(());
    }
    let Some(table) = doc.get_mut("jitter").and_then(|t| t.as_table_like_mut()) else {
        return Err(study_err!(
            "{}: [design] jitter_exponent: the file has no [jitter] table to write the jitter at the designed interval into",
            exp.file
        ));
    };
    for (key, value) in exp.jitter.truth.spec() {
        if key == "family" {
            continue;
        }
        let v: toml_edit::Value = match &value {
            serde_json::Value::Number(n) if n.is_i64() => n.as_i64().unwrap_or_default().into(),
            serde_json::Value::Number(n) => n.as_f64().unwrap_or(f64::NAN).into(),
            _ => {
                return Err(study_err!(
                    "{}: [design] jitter_exponent: the jitter's key {key} is not a number; the designed interval's jitter cannot be written",
                    exp.file
                ))
            }
        };
        table.insert(&key, toml_edit::Item::Value(v));
    }
    Ok(())
}

/// The designed multisine's experiment (the file with the design's sampling and tones, its
/// kind unchanged) and its sample sequence at `rate` Hz.
fn designed_multisine(
    plan: &Plan,
    design: &Design,
    m: &MultisineDesign,
    csv_name: &str,
    rate: Option<f64>,
) -> StudyResult<DesignedInput> {
    let exp = plan.experiment(design)?;
    let rate = rate.ok_or_else(|| {
        study_err!(
            "{}: [design] dac_rate: a designed multisine is written as its sample sequence, which needs a DAC rate; expected --dac-rate HZ or [design] dac_rate",
            exp.file
        )
    })?;
    let start = exp.grid.start();
    let csv = dac_samples(m, rate, start, design.samples as f64 * design.interval)?;
    let mut edits = plan.edits().to_vec();
    edits.extend(design.edits());
    let text = edited_text(&exp.file, plan.text(), &edits)?;
    let mut doc: toml_edit::DocumentMut = text
        .parse()
        .map_err(|e| study_err!("{}: the edited document: {e}", exp.file))?;
    doc.remove("design");
    let header = format!(
        "# Designed by `jitterid design` from {}: a multisine of {} tones, power {}, crest factor\n\
         # {}; its sample sequence at {rate} Hz (one record, t,u) in {csv_name}.\n",
        exp.file,
        m.frequencies.len(),
        m.power,
        m.crest_factor
    );
    Ok(DesignedInput {
        csv,
        experiment: header + &doc.to_string(),
    })
}
