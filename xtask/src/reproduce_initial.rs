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
use jitterid_study::experiment::{self, Method, Purpose};
use jitterid_study::montecarlo::{montecarlo_realizations, Realization, Realizations};
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
struct Row {
    name: String,
    #[serde(rename = "true")]
    truth: Option<f64>,
    mean: f64,
    std: f64,
    se: f64,
    /// Mean of the standard errors the fits reported.
    reported_std: Option<f64>,
    /// `(mean − true)/se`.
    bias_se: Option<f64>,
}

/// One example file's study.
#[derive(Debug, Clone, Serialize)]
struct Case {
    file: String,
    runs: u64,
    fitted: usize,
    flagged: usize,
    seconds: f64,
    parameters: Vec<Row>,
}

/// One parameter's statistics over the kept runs: its name, truth, estimates and the
/// standard errors the fits reported (`None` when a kept run reported none).
pub(crate) struct Kept {
    pub name: String,
    pub truth: Option<f64>,
    pub values: Summary,
    pub reported: Option<Summary>,
}

/// The Monte Carlo study of the example experiment `file` (with `method`, or the file's own):
/// every realisation, and the wall time it took.
pub(crate) fn realizations(
    file: &str,
    method: Option<Method>,
    runs: u64,
    seed: u64,
) -> Result<(Realizations, f64), String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/experiments")
        .join(file);
    let exp = experiment::read(&path, Purpose::Estimate(method)).map_err(|e| e.to_string())?;
    let t = Instant::now();
    let s = montecarlo_realizations(&exp, runs, seed, None).map_err(|e| e.to_string())?;
    Ok((s, t.elapsed().as_secs_f64()))
}

/// The statistics of every parameter over the runs `keep` accepts that have every estimate,
/// and how many runs those are.
pub(crate) fn kept(s: &Realizations, keep: impl Fn(&Realization) -> bool) -> (usize, Vec<Kept>) {
    let runs: Vec<(Vec<f64>, &Vec<Option<f64>>)> = s
        .runs
        .iter()
        .zip(&s.stderr)
        .filter(|(r, _)| keep(r))
        .filter_map(|(r, se)| Some((r.values.iter().copied().collect::<Option<Vec<_>>>()?, se)))
        .collect();
    let rows = s
        .names
        .iter()
        .enumerate()
        .map(|(i, name)| Kept {
            name: name.clone(),
            truth: s.truth[i],
            values: runs.iter().map(|(v, _)| v[i]).collect(),
            reported: runs.iter().map(|(_, se)| se[i]).collect(),
        })
        .collect();
    (runs.len(), rows)
}

fn study(file: &str, runs: u64, seed: u64) -> Result<Case, String> {
    let (s, seconds) = realizations(file, None, runs, seed)?;
    // Every run with estimates: a fit flagged for its residual spectrum is still a fit.
    let (fitted, rows) = kept(&s, |r| !r.termination.starts_with("failed"));
    let parameters = rows
        .into_iter()
        .map(|k| Row {
            bias_se: k.truth.map(|t| (k.values.mean - t) / k.values.se()),
            name: k.name,
            truth: k.truth,
            mean: k.values.mean,
            std: k.values.std(),
            se: k.values.se(),
            reported_std: k.reported.map(|r| r.mean),
        })
        .collect();
    Ok(Case {
        file: format!("examples/experiments/{file}"),
        runs,
        fitted,
        flagged: s.runs.iter().filter(|r| !r.converged).count(),
        seconds,
        parameters,
    })
}

fn table(rows: &[Row]) -> String {
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
