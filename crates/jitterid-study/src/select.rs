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
use crate::records::{read_data, read_input};
use crate::study_err;
use jitterid::estimate::selection::{select as run_select, Candidate, SelectionOptions};
use jitterid::estimate::{initial_model, InitError, InitOptions};
use jitterid::jitter::JitterModel;
use jitterid::signal::registry::{roots_json, SpecTable};
use jitterid::signal::{AnySignal, Input, Root, TransferFunction, Zpk};
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
    json!({
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
    })
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
    let input: Input = read_input(exp, data, None)?
        .into_iter()
        .next()
        .ok_or_else(|| {
            study_err!(
                "{}: [input]: selection needs an input to identify a system",
                exp.file
            )
        })?;
    let record = fit::record(&exp.grid, table.y).map_err(|e| study_err!("{}: {e}", table.name))?;
    // The candidates carry the system's delay (a parameter when the system is estimated,
    // else the input is delayed by it) and, with `initial = "estimate"`, a free response.
    let delay = exp.system.kind.get("delay").and_then(Value::as_f64);
    let known_delay = delay.filter(|_| !exp.system.estimate);
    let delay_err = |e: String| study_err!("{}: [system] delay: {e}", exp.file);
    let input = delayed_input(&input, known_delay).map_err(delay_err)?;
    let options = SelectionOptions {
        delay: delay.filter(|_| exp.system.estimate),
        initial_state: exp.system.kind.contains_key("initial"),
        ..SelectionOptions::default()
    };
    let validation = match validation {
        Some(path) => {
            let t = read_data(exp, path)?;
            let vi = match read_input(exp, path, None)?.into_iter().next() {
                Some(vi) => delayed_input(&vi, known_delay).map_err(delay_err)?,
                None => input.clone(),
            };
            let r = fit::record(&exp.grid, t.y).map_err(|e| study_err!("{}: {e}", t.name))?;
            Some((r, vi))
        }
        None => None,
    };
    // The whole selection under the command's time limit: candidates still fitting when it is
    // spent stop, and a ranking of unfinished fits is no ranking.
    let budget = crate::budget_of(exp, None);
    let ranked = budget
        .run(|| run_select(&record, &input, &grid, &exp.registries.jitter, &options))
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

fn roots_of(spec: &SpecTable, key: &str) -> Option<Vec<Root>> {
    let Some(v) = spec.get(key) else {
        return Some(Vec::new());
    };
    v.as_array()?
        .iter()
        .map(|r| Root::from_json(r).ok())
        .collect()
}

fn f64s(spec: &SpecTable, key: &str) -> Option<Vec<f64>> {
    spec.get(key)?
        .as_array()?
        .iter()
        .map(Value::as_f64)
        .collect()
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
/// ([`initial_model`], the jitter's damping compensated with the experiment's jitter): the
/// start of `fit --init auto`. Only the model's own keys change; a delay or an initial state
/// keeps the experiment's value, and the initializer sees the input delayed by that delay.
pub fn auto_start(
    exp: &Experiment,
    signal: &AnySignal,
    inputs: &[Input],
    y: &[f64],
    data: &str,
) -> StudyResult<AnySignal> {
    if exp.multi_input() {
        return Err(study_err!(
            "{}: --init auto: the initializer fits a single-input system's frequency response; a system with several inputs starts from the experiment's values (--init experiment)",
            exp.file
        ));
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
    let init_err = |e: InitError| study_err!("{data}: --init auto: the initializer failed: {e}");
    let driven = delayed_input(input, spec.get("delay").and_then(Value::as_f64))
        .map_err(|e| study_err!("{}: [system] delay: {e}", exp.file))?;
    match signal.kind() {
        "tf" => {
            let (num, den) = f64s(&spec, "num")
                .zip(f64s(&spec, "den"))
                .ok_or_else(|| study_err!("{}: [system] num, den: not numbers", exp.file))?;
            let tf = TransferFunction::new(&num, &den)
                .map_err(|e| study_err!("{}: [system]: {e}", exp.file))?;
            let g = initial_model(&tf, &record, &driven, Some(jitter), &opts).map_err(init_err)?;
            spec.insert("num".into(), json!(g.num()));
            spec.insert("den".into(), json!(g.den()));
        }
        "zpk" => {
            let (zeros, poles) = roots_of(&spec, "zeros")
                .zip(roots_of(&spec, "poles"))
                .ok_or_else(|| study_err!("{}: [system] zeros, poles: not roots", exp.file))?;
            let zpk =
                Zpk::new(1.0, zeros, poles).map_err(|e| study_err!("{}: [system]: {e}", exp.file))?;
            let g = initial_model(&zpk, &record, &driven, Some(jitter), &opts).map_err(init_err)?;
            spec.insert("gain".into(), json!(g.gain()));
            spec.insert("zeros".into(), roots_json(g.zeros()));
            spec.insert("poles".into(), roots_json(g.poles()));
        }
        other => {
            return Err(study_err!(
                "{}: --init auto: the initializer fits rational systems (kind tf or zpk), not `{other}`",
                exp.file
            ))
        }
    }
    exp.registries
        .signal
        .build(&spec, Some(input))
        .map_err(|e| study_err!("{data}: --init auto: the initializer's model: {e}"))
}
