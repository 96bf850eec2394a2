//! `cargo xtask reproduce initial`: an input that ran long before the record, and a dead time,
//! from the example experiment files through the command line's own Monte Carlo.
//!
//! * `initial-state-zero.toml`: Table 2's system, its random binary input drawn from
//!   `t0 − 50 s`, fitted from the input seen from `t0` on as if at rest at `t0`: biased.
//! * `initial-state.toml`: the same records with the free response from the unknown state at
//!   `t0` estimated jointly (`initial.0`, `initial.1`, no single truth): unbiased.
//! * `dead-time.toml`: Table 2's system with its input delayed by 1.5 s, the delay estimated.
//!
//! Statistics are over every run that produced estimates, including fits the solver flags for
//! a residual spectrum that is not flat (the symptom of the missing free response), which the
//! command line's own summary leaves out.

use crate::outputs::{fmt_opt, write_outputs};
use crate::paper::RUNS;
use crate::Options;
use jitterid::estimate::montecarlo::Summary;
use jitterid_study::experiment::{self, Purpose};
use jitterid_study::montecarlo::montecarlo_realizations;
use serde::Serialize;
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// The example files and what each shows.
const CASES: [(&str, &str); 3] = [
    (
        "initial-state-zero.toml",
        "input from t0 − 50 s, initial = \"zero\" (rest at t0 assumed)",
    ),
    (
        "initial-state.toml",
        "input from t0 − 50 s, initial = \"estimate\" (free response estimated)",
    ),
    ("dead-time.toml", "input delayed by 1.5 s, delay estimated"),
];

/// One parameter's summary over the fitted runs.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct Row {
    pub(crate) name: String,
    #[serde(rename = "true")]
    pub(crate) truth: Option<f64>,
    pub(crate) mean: f64,
    pub(crate) std: f64,
    pub(crate) se: f64,
    /// Mean of the standard errors the fits reported.
    pub(crate) reported_std: Option<f64>,
    /// `(mean − true)/se`.
    pub(crate) bias_se: Option<f64>,
}

/// One example file's study.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct Case {
    pub(crate) file: String,
    pub(crate) runs: u64,
    pub(crate) fitted: usize,
    pub(crate) flagged: usize,
    pub(crate) seconds: f64,
    pub(crate) parameters: Vec<Row>,
}

pub(crate) fn study(file: &str, runs: u64, seed: u64) -> Result<Case, String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/experiments")
        .join(file);
    let exp = experiment::read(&path, Purpose::Estimate(None)).map_err(|e| e.to_string())?;
    let t = Instant::now();
    let s = montecarlo_realizations(&exp, runs, seed, None).map_err(|e| e.to_string())?;
    let seconds = t.elapsed().as_secs_f64();
    // Every run with estimates: a fit flagged for its residual spectrum is still a fit.
    let fitted: Vec<(Vec<f64>, &Vec<Option<f64>>)> = s
        .runs
        .iter()
        .zip(&s.stderr)
        .filter(|(r, _)| !r.termination.starts_with("failed"))
        .filter_map(|(r, se)| Some((r.values.iter().copied().collect::<Option<Vec<_>>>()?, se)))
        .collect();
    let parameters = s
        .names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let v: Summary = fitted.iter().map(|(v, _)| v[i]).collect();
            let reported: Option<Summary> = fitted.iter().map(|(_, se)| se[i]).collect();
            let truth = s.truth[i];
            Row {
                name: name.clone(),
                truth,
                mean: v.mean,
                std: v.std(),
                se: v.se(),
                reported_std: reported.map(|r| r.mean),
                bias_se: truth.map(|t| (v.mean - t) / v.se()),
            }
        })
        .collect();
    Ok(Case {
        file: format!("examples/experiments/{file}"),
        runs,
        fitted: fitted.len(),
        flagged: s.runs.iter().filter(|r| !r.converged).count(),
        seconds,
        parameters,
    })
}

pub(crate) fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "| parameter | true | mean | std | se of mean | mean reported std error | (mean − true)/se |\n|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {:.4} | {:.4} | {} | {} |",
            r.name,
            fmt_opt(r.truth),
            r.mean,
            r.std,
            r.se,
            fmt_opt(r.reported_std),
            r.bias_se.map_or("–".into(), |z| format!("{z:+.2}")),
        );
    }
    s
}

/// The case `initial`.
pub fn initial(o: &Options) -> Result<(), String> {
    if o.shard.1 > 1 {
        return Err("initial: --shard is not offered (the three studies take seconds)".into());
    }
    let runs = o.runs.unwrap_or(RUNS);
    let mut md = format!(
        "## Initial state, input history and dead time — `cargo xtask reproduce initial`\n\n\
         Table 2's system (BCLS, known uniform-sum jitter, N = 200, noise std 0.01) from the example \
         files, {runs} realisations each (seed {}). Statistics over every run with estimates, \
         including fits flagged for a residual spectrum that is not flat; `initial.j` have no single \
         truth (each record has its own state at t0).\n",
        o.seed
    );
    let mut cases = Vec::new();
    for (file, what) in CASES {
        let c = study(file, runs, o.seed)?;
        let _ = write!(
            md,
            "\n### `{}`: {what}\n\n{} of {} runs with estimates, {} flagged (residual spectrum not flat or not converged), {:.2} s wall.\n\n",
            c.file, c.fitted, c.runs, c.flagged, c.seconds
        );
        md += &table(&c.parameters);
        cases.push(c);
    }
    let value = json!({"case": "initial", "runs": runs, "seed": o.seed, "studies": cases});
    write_outputs("initial", o, &value, &md)
}
