//! `jitterid select`: fit the `[select]` grid of model orders × jitter families and rank them.
//!
//! Candidates are ranked by the information criterion (BIC of the BCLS fit, see
//! `docs/method.md`); with a validation record each candidate's fit percent on it is reported
//! beside the criterion, and `best_validation` names the candidate that fits it best.

use crate::cli_err;
use crate::commands::{read_data, read_experiment, read_input};
use crate::error::CliResult;
use crate::exit::{Outcome, Status};
use crate::experiment::Purpose;
use crate::fitting;
use crate::output::OutputSet;
use jitterid::estimate::selection::{select as run_select, Candidate, SelectionOptions};
use jitterid::jitter::registry::JitterRegistry;
use jitterid::signal::Input;
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
        "converged": c.converged,
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
    let validation = match &o.validation {
        Some(path) => {
            let t = read_data(&exp, path)?;
            let vi = read_input(&exp, path, None)?.unwrap_or_else(|| input.clone());
            let r = fitting::record(&exp.grid, t.column("y")?.to_vec())
                .map_err(|e| cli_err!("{}: {e}", t.name))?;
            Some((r, vi))
        }
        None => None,
    };
    let ranked = run_select(
        &record,
        &input,
        &grid,
        JitterRegistry::builtin(),
        &SelectionOptions::default(),
    )
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
        "{:>5}  {:>5}  {:<14}  {:>14}  {:>9}  {:>14}",
        "poles", "zeros", "family", "BIC", "converged", "validation fit"
    );
    for (c, f) in ranked.iter().zip(&fits) {
        let _ = writeln!(
            out,
            "{:>5}  {:>5}  {:<14}  {:>14.4}  {:>9}  {:>14}",
            c.poles,
            c.zeros,
            c.family,
            c.criterion,
            if c.converged { "yes" } else { "no" },
            f.map_or("–".into(), |v| format!("{v:.2} %"))
        );
    }
    Ok(Outcome { text: out, status })
}
