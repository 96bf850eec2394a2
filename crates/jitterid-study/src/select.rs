//! Selection: fit the `[select]` grid of model orders × jitter families and rank them; and the
//! data-driven start of a fit (`init = auto`).
//!
//! Candidates are ranked by an information criterion (see `docs/method.md`): the best of each
//! family by the BIC of its exact maximum-likelihood refit, the others by the BIC of their BCLS
//! fit (each candidate's `ranked_by` says which). With a validation record each candidate's fit
//! percent on it is reported beside the criterion, and `best_validation` names the candidate
//! that fits it best.

use crate::error::StudyResult;
use crate::experiment::Experiment;
use crate::fit;
use crate::rational_start::{driven_input, Template};
use crate::records::{read_data, read_input};
use crate::study_err;
use jitterid::estimate::selection::{
    select as run_select, select_channels, Candidate, SelectionOptions,
};
use jitterid::estimate::{fit_rational, InitOptions};
use jitterid::jitter::JitterModel;
use jitterid::signal::{AnySignal, Input};
use serde_json::{json, Value};
use std::path::Path;

/// Which criterion ranks `c`.
pub fn ranked_by(c: &Candidate) -> &'static str {
    if c.ranked_by_likelihood {
        "exact-ml-bic"
    } else {
        "bcls-bic"
    }
}

/// The JSON of one candidate, with its fit percent on the validation record.
pub fn candidate_json(c: &Candidate, validation: Option<f64>) -> Value {
    let estimates: serde_json::Map<String, Value> = c
        .parameters
        .iter()
        .map(|(n, v)| (n.clone(), json!(v)))
        .collect();
    let mut doc = json!({
        "poles": c.poles,
        "zeros": c.zeros,
        "family": c.family,
        "criterion": c.criterion.is_finite().then_some(c.criterion),
        "ranked_by": ranked_by(c),
        "converged": c.converged,
        "bcls_criterion": c.bcls_criterion.is_finite().then_some(c.bcls_criterion),
        "bcls_converged": c.bcls_converged,
        "likelihood_criterion": c.likelihood_criterion.filter(|v| v.is_finite()),
        "likelihood_failure": c.likelihood_failure,
        "estimates": estimates,
        "validation_fit_percent": validation,
        "failure": c.failure,
        "failure_kind": c.failure_kind,
    });
    // A multi-input candidate's order per input (its `poles` and `zeros` are the totals).
    if !c.channels.is_empty() {
        let orders: serde_json::Map<String, Value> = c
            .channels
            .iter()
            .map(|(n, p, z)| (n.clone(), json!([p, z])))
            .collect();
        doc["orders"] = Value::Object(orders);
    }
    doc
}

/// A multi-input candidate's orders as `torque 1/0, brake 2/1` (input, poles/zeros), for a
/// table; `None` for one input's.
pub fn orders_text(c: &Candidate) -> Option<String> {
    let parts: Vec<String> = c
        .channels
        .iter()
        .map(|(n, p, z)| format!("{n} {p}/{z}"))
        .collect();
    (!parts.is_empty()).then(|| parts.join(", "))
}

/// A finished selection: the candidates ranked, best first.
#[derive(Debug, Clone)]
pub struct Selection {
    /// The estimation record's name (its file).
    pub data: String,
    /// The candidates, best first.
    pub ranked: Vec<Candidate>,
    /// Each candidate's fit percent on the validation record, in the order of `ranked`.
    pub validation_fits: Vec<Option<f64>>,
    /// The candidate that fits the validation record best.
    pub best_validation: Option<usize>,
}

impl Selection {
    /// The JSON of `jitterid select --json`.
    pub fn to_json(&self) -> Value {
        let candidates: Vec<Value> = self
            .ranked
            .iter()
            .zip(&self.validation_fits)
            .map(|(c, f)| candidate_json(c, *f))
            .collect();
        let mut doc = json!({ "best": candidates.first(), "candidates": candidates });
        if let Some(i) = self.best_validation {
            doc["best_validation"] = candidate_json(&self.ranked[i], self.validation_fits[i]);
        }
        doc
    }
}

/// Selects among the experiment's `[select]` grid on the record in `data` (its input from the
/// experiment or its side file), with the fit percent of each candidate on the record in
/// `validation` when given.
pub fn select(exp: &Experiment, data: &Path, validation: Option<&Path>) -> StudyResult<Selection> {
    let grid = exp.select.clone().ok_or_else(|| {
        study_err!(
            "{}: missing section [select]; expected keys poles = [min, max], zeros = [min, max], families = [...]",
            exp.file
        )
    })?;
    let table = read_data(exp, data)?;
    exp.selectable()?;
    let inputs = read_input(exp, data, None)?;
    if inputs.is_empty() {
        return Err(study_err!(
            "{}: [input]: selection needs an input to identify a system",
            exp.file
        ));
    }
    let record = fit::record(&exp.grid, table.y).map_err(|e| study_err!("{}: {e}", table.name))?;
    // The candidates carry the system's delay (a parameter when the system is estimated,
    // else the input is delayed by it), with `initial = "estimate"` a free response, and the
    // output offset of `[output]` (known, or estimated with each candidate).
    let delay = exp.system.kind.get("delay").and_then(Value::as_f64);
    let known_delay = delay.filter(|_| !exp.system.estimate);
    let delayed = |inputs: Vec<Input>| -> StudyResult<Vec<Input>> {
        inputs
            .iter()
            .map(|i| delayed_input(i, known_delay))
            .collect::<Result<_, _>>()
            .map_err(|e| study_err!("{}: [system] delay: {e}", exp.file))
    };
    let inputs = delayed(inputs)?;
    let options = SelectionOptions {
        delay: delay.filter(|_| exp.system.estimate),
        initial_state: exp.system.kind.contains_key("initial"),
        offset: exp.output_offset(),
        level: exp.input_level(),
        ..SelectionOptions::default()
    };
    let validation = match validation {
        Some(path) => {
            let t = read_data(exp, path)?;
            let vi = match read_input(exp, path, None)? {
                vi if vi.is_empty() => inputs.clone(),
                vi => delayed(vi)?,
            };
            let r = fit::record(&exp.grid, t.y).map_err(|e| study_err!("{}: {e}", t.name))?;
            Some((r, vi))
        }
        None => None,
    };
    // The whole selection under the command's time limit: candidates still fitting when it is
    // spent stop, and a ranking of unfinished fits is no ranking.
    let budget = crate::budget_of(exp, None);
    let jitters = &exp.registries.jitter;
    let ranked = budget
        .run(|| {
            let orders = &exp.select_orders;
            if orders.is_empty() {
                run_select(&record, &inputs[0], &grid, jitters, &options)
            } else {
                select_channels(&record, &inputs, &grid, orders, jitters, &options)
            }
        })
        .map_err(|e| study_err!("{}: {e}", exp.file))?;
    if let Some(stop) = budget.stop() {
        return Err(study_err!(
            "{}: the selection of {} candidates was stopped: {stop} (give a longer --time-limit, or fewer candidates)",
            exp.file,
            ranked.len()
        ));
    }
    let fits: Vec<Option<f64>> = ranked
        .iter()
        .map(|c| {
            validation
                .as_ref()
                .and_then(|(r, i)| c.validation_fit(r, i))
        })
        .collect();
    let best_validation = (0..ranked.len())
        .filter(|&i| fits[i].is_some())
        .max_by(|&a, &b| {
            fits[a]
                .unwrap_or(f64::NAN)
                .total_cmp(&fits[b].unwrap_or(f64::NAN))
        });
    Ok(Selection {
        data: table.name,
        ranked,
        validation_fits: fits,
        best_validation,
    })
}

/// Where `jitterid fit` starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InitChoice {
    /// The experiment's values.
    #[default]
    Experiment,
    /// The data-driven initializer's model (as `select` starts each candidate), with the
    /// experiment's jitter, noise and the system's other keys (delay, initial state).
    Auto,
    /// The experiment's values, and for a likelihood fit of an estimated system those values
    /// as its only start ([`LikelihoodStart::Given`](crate::experiment::LikelihoodStart::Given));
    /// by default a likelihood starts at the BCLS estimate.
    ExperimentOnly,
}

impl InitChoice {
    /// Parses `experiment`, `auto` or `experiment-only`.
    ///
    /// # Errors
    ///
    /// A message naming the accepted values.
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "experiment" => Ok(Self::Experiment),
            "auto" => Ok(Self::Auto),
            "experiment-only" => Ok(Self::ExperimentOnly),
            other => Err(format!(
                "expected experiment, auto or experiment-only, found `{other}`"
            )),
        }
    }

    /// Where a likelihood fit of an estimated system starts under this choice.
    pub fn likelihood_start(self) -> crate::experiment::LikelihoodStart {
        match self {
            Self::ExperimentOnly => crate::experiment::LikelihoodStart::Given,
            Self::Experiment | Self::Auto => crate::experiment::LikelihoodStart::Bcls,
        }
    }
}

/// `input` delayed by `delay` seconds: what drives the rational part of a system with an input
/// delay. The initializer fits the frequency response from this input to the output, so that
/// the rational model it returns does not carry the delay's phase a second time.
fn delayed_input(input: &Input, delay: Option<f64>) -> Result<Input, String> {
    match delay {
        Some(d) if d > 0.0 => input.delayed(d).map_err(|e| e.to_string()),
        _ => Ok(input.clone()),
    }
}

/// The experiment's system with its rational model replaced by the data-driven initializer's
/// ([`fit_rational`], the jitter's damping compensated with the experiment's jitter): the
/// start of `fit --init auto`. Only the model's own keys change; a delay or an initial state
/// keeps the experiment's value, and the initializer sees the input delayed by that delay. A
/// system with several inputs starts every estimated channel from the multi-input initializer
/// ([`jitterid::estimate::fit_channels`]).
pub fn auto_start(
    exp: &Experiment,
    signal: &AnySignal,
    inputs: &[Input],
    y: &[f64],
    data: &str,
) -> StudyResult<AnySignal> {
    if exp.multi_input() {
        return crate::rational_start::channels_start(exp, signal, inputs, y, data);
    }
    let input = inputs.first().ok_or_else(|| {
        study_err!(
            "{}: --init auto fits the system's frequency response to the input's, but the experiment has no [input]",
            exp.file
        )
    })?;
    let record = fit::record(&exp.grid, y.to_vec()).map_err(|e| study_err!("{data}: {e}"))?;
    let jitter: &dyn JitterModel = &exp.jitter.model;
    let mut spec = signal.spec();
    // An estimated output offset moves only the bin f = 0: the initializer leaves it out, so
    // that the system's start is not bent towards a constant (the offset's own start comes
    // from the record's mean, in the fit).
    let opts = InitOptions {
        offset: spec.get("estimate_offset") == Some(&Value::Bool(true)),
        ..InitOptions::default()
    };
    let driven = driven_input(input, &spec, &exp.file, &format!("{}: [system]", exp.file))?;
    let template = Template::of(signal.kind(), &spec, &format!("{}: [system]", exp.file))?;
    let (zeros, poles) = template.orders();
    let g = fit_rational(&record, &driven, Some(jitter), zeros, poles, &opts)
        .map_err(|e| study_err!("{data}: --init auto: the initializer failed: {e}"))?;
    template
        .write(&g, &mut spec)
        .map_err(|e| study_err!("{data}: {e}"))?;
    exp.registries
        .signal
        .build(&spec, Some(input))
        .map_err(|e| study_err!("{data}: --init auto: the initializer's model: {e}"))
}
