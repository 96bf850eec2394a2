//! `jitterid select`: fit the `[select]` grid of model orders × jitter families and rank them.
//!
//! Candidates are ranked by an information criterion (see `docs/method.md`): the best of each
//! family by the BIC of its exact maximum-likelihood refit, the others by the BIC of their BCLS
//! fit (each candidate's `ranked_by` says which). With a validation record each candidate's fit
//! percent on it is reported beside the criterion, and `best_validation` names the candidate
//! that fits it best.

use crate::cli_err;
use crate::commands::{read_data, read_experiment, read_input};
use crate::error::CliResult;
use crate::exit::{Outcome, Status};
use crate::experiment::Experiment;
use crate::experiment::Purpose;
use crate::fitting;
use crate::output::OutputSet;
use jitterid::estimate::selection::{select as run_select, Candidate, SelectionOptions};
use jitterid::estimate::{initial_model, InitError, InitOptions};
use jitterid::jitter::registry::JitterRegistry;
use jitterid::jitter::JitterModel;
use jitterid::signal::registry::{roots_json, SignalRegistry, Spec};
use jitterid::signal::{AnySignal, Input, Root, TransferFunction, Zpk};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Options of `select`.
#[derive(Debug, Clone)]
pub struct SelectOptions {
    /// The experiment file (its `[sampling]`, `[input]` and `[select]` are used).
    pub experiment: PathBuf,
    /// The estimation record.
    pub data: PathBuf,
    /// An optional validation record (same experiment grid; input from its side file).
    pub validation: Option<PathBuf>,
    /// Print JSON instead of a table.
    pub json: bool,
    /// Write the JSON to this file instead of standard output.
    pub out: Option<PathBuf>,
}

/// Which criterion ranks `c`.
fn ranked_by(c: &Candidate) -> &'static str {
    if c.ranked_by_likelihood {
        "exact-ml-bic"
    } else {
        "bcls-bic"
    }
}

fn candidate_json(c: &Candidate, validation: Option<f64>) -> Value {
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
    })
}

/// `jitterid select`.
pub fn select(o: &SelectOptions) -> CliResult<Outcome> {
    let exp = read_experiment(&o.experiment, Purpose::Simulate, None, None)?;
    let grid = exp.select.clone().ok_or_else(|| {
        cli_err!(
            "{}: missing section [select]; expected keys poles = [min, max], zeros = [min, max], families = [...]",
            exp.file
        )
    })?;
    let table = read_data(&exp, &o.data)?;
    let input: Input = read_input(&exp, &o.data, None)?.ok_or_else(|| {
        cli_err!(
            "{}: [input]: selection needs an input to identify a system",
            exp.file
        )
    })?;
    let record = fitting::record(&exp.grid, table.column("y")?.to_vec())
        .map_err(|e| cli_err!("{}: {e}", table.name))?;
    // The candidates carry the system's delay (a parameter when the system is estimated,
    // else the input is delayed by it) and, with `initial = "estimate"`, a free response.
    let delay = exp.system.kind.get("delay").and_then(Value::as_f64);
    let known_delay = delay.filter(|_| !exp.system.estimate);
    let delay_err = |e: String| cli_err!("{}: [system] delay: {e}", exp.file);
    let input = delayed_input(&input, known_delay).map_err(delay_err)?;
    let options = SelectionOptions {
        delay: delay.filter(|_| exp.system.estimate),
        initial_state: exp.system.kind.contains_key("initial"),
        ..SelectionOptions::default()
    };
    let validation = match &o.validation {
        Some(path) => {
            let t = read_data(&exp, path)?;
            let vi = match read_input(&exp, path, None)? {
                Some(vi) => delayed_input(&vi, known_delay).map_err(delay_err)?,
                None => input.clone(),
            };
            let r = fitting::record(&exp.grid, t.column("y")?.to_vec())
                .map_err(|e| cli_err!("{}: {e}", t.name))?;
            Some((r, vi))
        }
        None => None,
    };
    let ranked = run_select(&record, &input, &grid, JitterRegistry::builtin(), &options)
        .map_err(|e| cli_err!("{}: {e}", exp.file))?;
    let fits: Vec<Option<f64>> = ranked
        .iter()
        .map(|c| {
            validation
                .as_ref()
                .and_then(|(r, i)| c.validation_fit(r, i))
        })
        .collect();
    let status = Status::of_convergence(ranked.first().is_some_and(|c| c.converged), false);
    let best_validation = (0..ranked.len())
        .filter(|&i| fits[i].is_some())
        .max_by(|&a, &b| {
            fits[a]
                .unwrap_or(f64::NAN)
                .total_cmp(&fits[b].unwrap_or(f64::NAN))
        });
    if o.json || o.out.is_some() {
        let candidates: Vec<Value> = ranked
            .iter()
            .zip(&fits)
            .map(|(c, f)| candidate_json(c, *f))
            .collect();
        let mut doc = json!({ "best": candidates.first(), "candidates": candidates });
        if let Some(i) = best_validation {
            doc["best_validation"] = candidate_json(&ranked[i], fits[i]);
        }
        let text = serde_json::to_string_pretty(&doc).map_err(|e| cli_err!("JSON: {e}"))? + "\n";
        if let Some(path) = &o.out {
            let mut outputs = OutputSet::new();
            outputs.file(path, text);
            outputs.commit()?;
            return Ok(Outcome {
                text: format!("wrote {}\n", path.display()),
                status,
            });
        }
        return Ok(Outcome { text, status });
    }
    let mut out = format!("selection on {} ({})\n", table.name, exp.file);
    let _ = writeln!(
        out,
        "{:>5}  {:>5}  {:<14}  {:>14}  {:<12}  {:>14}  {:>9}  {:>14}",
        "poles", "zeros", "family", "BIC", "ranked by", "BCLS BIC", "converged", "validation fit"
    );
    for (c, f) in ranked.iter().zip(&fits) {
        let _ = writeln!(
            out,
            "{:>5}  {:>5}  {:<14}  {:>14.4}  {:<12}  {:>14.4}  {:>9}  {:>14}",
            c.poles,
            c.zeros,
            c.family,
            c.criterion,
            ranked_by(c),
            c.bcls_criterion,
            if c.converged { "yes" } else { "no" },
            f.map_or("–".into(), |v| format!("{v:.2} %"))
        );
    }
    Ok(Outcome { text: out, status })
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
}

impl InitChoice {
    /// Parses `experiment` or `auto`.
    ///
    /// # Errors
    ///
    /// A message naming the accepted values.
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "experiment" => Ok(Self::Experiment),
            "auto" => Ok(Self::Auto),
            other => Err(format!("expected experiment or auto, found `{other}`")),
        }
    }
}

fn roots_of(spec: &Spec, key: &str) -> Option<Vec<Root>> {
    let Some(v) = spec.get(key) else {
        return Some(Vec::new());
    };
    v.as_array()?
        .iter()
        .map(|r| match r {
            Value::Array(p) => match p.as_slice() {
                [re, im] => Some(Root::Pair {
                    re: re.as_f64()?,
                    im: im.as_f64()?,
                }),
                _ => None,
            },
            x => x.as_f64().map(Root::Real),
        })
        .collect()
}

fn f64s(spec: &Spec, key: &str) -> Option<Vec<f64>> {
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
    input: Option<&Input>,
    y: &[f64],
    data: &str,
) -> CliResult<AnySignal> {
    let input = input.ok_or_else(|| {
        cli_err!(
            "{}: --init auto fits the system's frequency response to the input's, but the experiment has no [input]",
            exp.file
        )
    })?;
    let record = fitting::record(&exp.grid, y.to_vec()).map_err(|e| cli_err!("{data}: {e}"))?;
    let jitter: &dyn JitterModel = &exp.jitter.model;
    let opts = InitOptions::default();
    let init_err = |e: InitError| cli_err!("{data}: --init auto: the initializer failed: {e}");
    let mut spec = signal.spec();
    let driven = delayed_input(input, spec.get("delay").and_then(Value::as_f64))
        .map_err(|e| cli_err!("{}: [system] delay: {e}", exp.file))?;
    match signal.kind() {
        "tf" => {
            let (num, den) = f64s(&spec, "num")
                .zip(f64s(&spec, "den"))
                .ok_or_else(|| cli_err!("{}: [system] num, den: not numbers", exp.file))?;
            let tf = TransferFunction::new(&num, &den)
                .map_err(|e| cli_err!("{}: [system]: {e}", exp.file))?;
            let g = initial_model(&tf, &record, &driven, Some(jitter), &opts).map_err(init_err)?;
            spec.insert("num".into(), json!(g.num()));
            spec.insert("den".into(), json!(g.den()));
        }
        "zpk" => {
            let (zeros, poles) = roots_of(&spec, "zeros")
                .zip(roots_of(&spec, "poles"))
                .ok_or_else(|| cli_err!("{}: [system] zeros, poles: not roots", exp.file))?;
            let zpk =
                Zpk::new(1.0, zeros, poles).map_err(|e| cli_err!("{}: [system]: {e}", exp.file))?;
            let g = initial_model(&zpk, &record, &driven, Some(jitter), &opts).map_err(init_err)?;
            spec.insert("gain".into(), json!(g.gain()));
            spec.insert("zeros".into(), roots_json(g.zeros()));
            spec.insert("poles".into(), roots_json(g.poles()));
        }
        other => {
            return Err(cli_err!(
                "{}: --init auto: the initializer fits rational systems (kind tf or zpk), not `{other}`",
                exp.file
            ))
        }
    }
    SignalRegistry::builtin()
        .build(&spec, Some(input))
        .map_err(|e| cli_err!("{data}: --init auto: the initializer's model: {e}"))
}
