//! `jitterid select`: the selection of the study layer, printed as a table or JSON.
//!
//! Candidates are ranked by an information criterion (see `docs/method.md`): the best of each
//! family by the BIC of its exact maximum-likelihood refit, the others by the BIC of their BCLS
//! fit (each candidate's `ranked_by` says which). With a validation record each candidate's fit
//! percent on it is reported beside the criterion, and `best_validation` names the candidate
//! that fits it best.

use crate::exit::{Outcome, Status};
use crate::output::OutputSet;
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{Purpose, ReadOptions};
use jitterid_study::records::read_experiment;
use jitterid_study::select::{orders_text, select as run_selection};
use jitterid_study::study_err;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Options of `select`.
#[derive(Debug, Clone)]
pub struct SelectOptions {
    /// The experiment file (its `[sampling]`, `[input]` and `[select]` are used).
    pub experiment: PathBuf,
    /// How the experiment file is read (`--allow-paths-outside`, `--set`, the `[sampling]`
    /// keys a data file gives).
    pub read: ReadOptions,
    /// The estimation record.
    pub data: PathBuf,
    /// An optional validation record (same experiment grid; input from its side file).
    pub validation: Option<PathBuf>,
    /// Print JSON instead of a table.
    pub json: bool,
    /// Write the JSON to this file instead of standard output.
    pub out: Option<PathBuf>,
    /// Wall-clock budget of the whole selection in seconds (default
    /// [`DEFAULT_TIME_LIMIT`](jitterid_study::DEFAULT_TIME_LIMIT)).
    pub time_limit: Option<f64>,
}

/// `jitterid select`.
pub fn select(o: &SelectOptions) -> StudyResult<Outcome> {
    let exp = read_experiment(
        &o.experiment,
        Purpose::Simulate,
        &o.read,
        None,
        o.time_limit,
    )?;
    exp.selectable()?;
    let selection = run_selection(&exp, &o.data, o.validation.as_deref())?;
    let (ranked, fits) = (&selection.ranked, &selection.validation_fits);
    let status = Status::of_convergence(ranked.first().is_some_and(|c| c.converged), false);
    if o.json || o.out.is_some() {
        let doc = selection.to_json();
        let text = serde_json::to_string_pretty(&doc).map_err(|e| study_err!("JSON: {e}"))? + "\n";
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
    let mut out = format!("selection on {} ({})\n", selection.data, exp.file);
    // The two criteria are on different scales, so each has its column: the screen's BCLS BIC
    // (every candidate) and the final exact likelihood's BIC (the finalists, which rank first).
    // Several inputs: the poles and zeros are totals, and the last column each input's.
    let orders = |c| orders_text(c).map_or(String::new(), |t| format!("  {t}"));
    let multi = ranked.iter().any(|c| orders_text(c).is_some());
    let _ = writeln!(
        out,
        "{:>5}  {:>5}  {:<14}  {:>16}  {:>16}  {:>9}  {:>14}{}",
        "poles",
        "zeros",
        "family",
        "screen BCLS BIC",
        "final ML BIC",
        "converged",
        "validation fit",
        if multi {
            "  orders (input poles/zeros)"
        } else {
            ""
        }
    );
    for (c, f) in ranked.iter().zip(fits) {
        let final_bic = c
            .likelihood_criterion
            .filter(|_| c.ranked_by_likelihood)
            .map_or("–".into(), |b| format!("{b:.4}"));
        let _ = writeln!(
            out,
            "{:>5}  {:>5}  {:<14}  {:>16.4}  {:>16}  {:>9}  {:>14}{}",
            c.poles,
            c.zeros,
            c.family,
            c.bcls_criterion,
            final_bic,
            if c.converged { "yes" } else { "no" },
            f.map_or("–".into(), |v| format!("{v:.2} %")),
            orders(c)
        );
    }
    Ok(Outcome { text: out, status })
}
