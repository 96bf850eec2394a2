//! `jitterid montecarlo`: the study layer's Monte Carlo study, printed as a table or JSON, with
//! its figures and a progress bar.

use super::{fmt_num, name_width};
use crate::exit::{Outcome, Status};
use crate::output::OutputSet;
use crate::plots;
use crate::progress::Progress;
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{Method, Purpose, ReadOptions};
use jitterid_study::fit::Structure;
use jitterid_study::montecarlo::{run_study, Keep, McJson, Shard};
use jitterid_study::records::read_experiment;
use jitterid_study::study_err;
use jitterid_study::{RunsDone, Watch};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Options of `montecarlo`.
#[derive(Debug, Clone)]
pub struct MonteCarloOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// How the experiment file is read (`--allow-paths-outside`, `--set`, the `[sampling]`
    /// keys a data file gives).
    pub read: ReadOptions,
    /// Total number of realisations.
    pub runs: u64,
    /// Master seed.
    pub seed: u64,
    /// Worker threads (rayon's default if `None`).
    pub threads: Option<usize>,
    /// JSON output.
    pub json: bool,
    /// Plot directory.
    pub plot: Option<PathBuf>,
    /// Which shard of the runs.
    pub shard: Option<Shard>,
    /// Method override.
    pub method: Option<Method>,
    /// Write the JSON to this file (atomically) instead of stdout.
    pub out: Option<PathBuf>,
    /// Exit 0 even when no fit converged.
    pub accept_unconverged: bool,
    /// Iteration limit of every fit (overrides `[estimate] max_iterations`).
    pub max_iterations: Option<u64>,
    /// Wall-clock budget of every fit in seconds.
    pub time_limit: Option<f64>,
    /// Report the study's wall time (`seconds`); without it two runs of the same study print
    /// and write the same bytes.
    pub timing: bool,
}

fn mc_table(j: &McJson) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Monte Carlo of {} with {}: {} runs (seed {}), {} converged{}",
        j.experiment,
        j.method,
        j.runs,
        j.seed,
        j.converged,
        j.seconds.map_or(String::new(), |s| format!(", {s:.2} s"))
    );
    let reasons: Vec<String> = j
        .terminations
        .iter()
        .map(|(reason, count)| format!("{count} × {reason}"))
        .collect();
    let _ = writeln!(out, "terminations: {}", reasons.join("; "));
    if let Some(s) = &j.shard {
        let _ = writeln!(
            out,
            "shard {}/{}: runs {}..{} of {}",
            s.index, s.count, s.first, s.end, s.runs_total
        );
    }
    let w = name_width(j.parameters.iter().map(|p| p.name.as_str()));
    let _ = writeln!(
        out,
        "{:<w$}  {:>12}  {:>12}  {:>12}  {:>12}  {:>12}",
        "parameter", "true", "mean", "std", "se", "rmse"
    );
    let f = |x: Option<f64>| x.map_or("–".into(), fmt_num);
    for p in &j.parameters {
        let _ = writeln!(
            out,
            "{:<w$}  {:>12}  {:>12}  {:>12}  {:>12}  {:>12}",
            p.name,
            f(p.truth),
            f(p.mean),
            f(p.std),
            f(p.se),
            f(p.rmse)
        );
    }
    out
}

/// `jitterid montecarlo`: the text to print (empty if the JSON is written to `--out`), and exit
/// status [`Status::NotConverged`] when no fit converged (unless `accept_unconverged`).
pub fn montecarlo(o: &MonteCarloOptions) -> StudyResult<Outcome> {
    let exp = read_experiment(
        &o.experiment,
        Purpose::Estimate(o.method),
        &o.read,
        o.max_iterations,
        o.time_limit,
    )?;
    let keep = Keep {
        fitted: o.plot.is_some(),
        stderr: false,
    };
    // The bar starts with the first finished run, which knows the study's size.
    let bar: Arc<OnceLock<Progress>> = Arc::new(OnceLock::new());
    let ticks = Arc::clone(&bar);
    let watch = Watch {
        runs: Some(Arc::new(move |p: RunsDone| {
            ticks.get_or_init(|| Progress::new(p.total)).tick();
        })),
        ..Watch::none()
    };
    let study = run_study(&exp, o.runs, o.seed, o.shard, o.threads, keep, &watch);
    if let Some(bar) = bar.get() {
        bar.finish();
    }
    let mut study = study?;
    if !o.timing {
        study.json.seconds = None;
    }
    let j = &study.json;
    let mut outputs = OutputSet::new();
    if let Some(dir) = &o.plot {
        let conv: Vec<Vec<f64>> = study
            .outs
            .iter()
            .map(|o| &o.realization)
            .filter(|r| r.converged)
            .map(|r| r.values.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
            .collect();
        let fitted: Vec<&Structure> = study
            .outs
            .iter()
            .filter(|o| o.realization.converged)
            .filter_map(|o| o.fitted.as_ref())
            .collect();
        let figs = plots::montecarlo_figures(&plots::McPlots {
            exp: &exp,
            method: &j.method,
            names: &study.names,
            truth: &study.truth,
            values: conv.iter().map(Vec::as_slice).collect(),
            true_signal: &study.signal0,
            fitted,
        });
        outputs.figures(
            &dir.join(plots::MONTECARLO_DIR),
            figs,
            &plots::MONTECARLO_FIGURES,
        );
    }
    let text = emit(j, o.json, o.out.as_deref(), outputs)?;
    Ok(Outcome {
        text,
        status: Status::of_convergence(j.converged > 0, o.accept_unconverged),
    })
}

/// Writes the JSON to `out` together with the other `outputs`; returns what to print.
pub fn emit(
    j: &McJson,
    json: bool,
    out: Option<&Path>,
    mut outputs: OutputSet,
) -> StudyResult<String> {
    let text = serde_json::to_string_pretty(j).map_err(|e| study_err!("JSON: {e}"))? + "\n";
    let printed = match out {
        Some(path) => {
            outputs.file(path, text);
            if json {
                String::new()
            } else {
                mc_table(j)
            }
        }
        None if json => text,
        None => mc_table(j),
    };
    outputs.commit()?;
    Ok(printed)
}
