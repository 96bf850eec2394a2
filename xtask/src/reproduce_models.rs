//! `cargo xtask reproduce models`: models as engineers write them (issue 28), each case one
//! example experiment file through the command line's own Monte Carlo, summarised against the
//! standard errors the fits reported.
//!
//! Every case writes `{"case", "runs", "converged", "parameters": [{"name", "true", "mean",
//! "std", "se", "mean_stderr"}]}`: `std` is the spread of the estimates over the converged
//! runs, `se` the mean of the standard errors the fits reported, `mean_stderr` the Monte Carlo
//! standard error of the mean (`std/√converged`). A case is one row of [`CASES`]; another model
//! (several inputs) adds its file and method there.

use crate::outputs::write_outputs;
use crate::paper::RUNS;
use crate::reproduce_initial::{kept, realizations};
use crate::Options;
use jitterid_study::experiment::Method;
use serde::Serialize;
use std::fmt::Write as _;

/// The cases: name, example file, method, what it shows.
const CASES: [(&str, &str, &str, &str); 11] = [
    (
        "offset",
        "offset.toml",
        "bcls",
        "Table 2's system around an operating point y0 = 1.5, the offset estimated with the system by BCLS",
    ),
    (
        "offset-ml",
        "offset.toml",
        "ml",
        "the same records by exact maximum likelihood",
    ),
    (
        "two-input",
        "two-input.toml",
        "bcls",
        "two inputs with different jitter-sensitive dynamics (a fast first-order channel and a lightly damped one), estimated jointly by BCLS",
    ),
    (
        "two-input-ml",
        "two-input.toml",
        "ml",
        "the same records by exact maximum likelihood",
    ),
    (
        "msd-uniform",
        "msd-uniform.toml",
        "bcls",
        "grey box: a mass–spring–damper in its physical parameters (m, damp, k), uniform-sum jitter",
    ),
    (
        "msd-gaussian",
        "msd-gaussian.toml",
        "bcls",
        "grey box: the mass–spring–damper, Gaussian jitter",
    ),
    (
        "dc-motor-uniform",
        "dc-motor-uniform.toml",
        "bcls",
        "grey box: a DC motor (J, b, K; R and L known), uniform-sum jitter",
    ),
    (
        "dc-motor-gaussian",
        "dc-motor-gaussian.toml",
        "bcls",
        "grey box: the DC motor, Gaussian jitter",
    ),
    (
        "msd-delay-offset",
        "msd-delay-offset.toml",
        "bcls",
        "grey box with a dead time and an operating point: the mass–spring–damper's m, damp, k with its delay D and output offset y0, uniform-sum jitter",
    ),
    (
        "input-level",
        "input-level.toml",
        "bcls",
        "an operating point of the input: a tank 1/(s(s+1)) driven by u − u0, the level u0 = 0.5 estimated beside the output offset y0 = 1.5 by BCLS",
    ),
    (
        "input-level-ml",
        "input-level.toml",
        "ml",
        "the same records by exact maximum likelihood",
    ),
];

/// One parameter's summary over the converged runs.
#[derive(Debug, Clone, Serialize)]
struct Row {
    name: String,
    #[serde(rename = "true")]
    truth: Option<f64>,
    mean: f64,
    std: f64,
    /// Mean of the standard errors the fits reported.
    se: Option<f64>,
    /// Root mean square of the standard errors the fits reported: what the spread is to be
    /// compared with where the precision depends on the input's realisation (the Monte Carlo
    /// variance is the mean of the conditional variances over the realisations).
    rms_se: Option<f64>,
    /// Monte Carlo standard error of the mean.
    mean_stderr: f64,
}

/// One case's study.
#[derive(Debug, Clone, Serialize)]
struct Case {
    case: String,
    file: String,
    method: String,
    runs: u64,
    converged: usize,
    seconds: f64,
    parameters: Vec<Row>,
}

fn study(case: &str, file: &str, method: &str, runs: u64, seed: u64) -> Result<Case, String> {
    let m = Method::parse(method).ok_or_else(|| format!("{case}: no method {method}"))?;
    let (s, seconds) = realizations(file, Some(m), runs, seed)?;
    let (converged, rows) = kept(&s, |r| r.converged);
    let parameters = rows
        .into_iter()
        .map(|k| Row {
            name: k.name,
            truth: k.truth,
            mean: k.values.mean,
            std: k.values.std(),
            se: k.reported.map(|r| r.mean),
            rms_se: k
                .reported
                .map(|r| (r.mean * r.mean + r.m2 / r.count.max(1) as f64).sqrt()),
            mean_stderr: k.values.se(),
        })
        .collect();
    Ok(Case {
        case: case.into(),
        file: format!("examples/experiments/{file}"),
        method: method.into(),
        runs,
        converged,
        seconds,
        parameters,
    })
}

/// The Markdown table of a case: the bias in units of the mean's standard error and the
/// spread against the reported standard error, the two targets of issue 28.
fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "| parameter | true | mean | std | mean reported se | std/se − 1 | std/rms se − 1 | mean stderr | (mean − true)/mean stderr |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let against = |se: Option<f64>| {
            se.map_or("–".into(), |se| {
                format!("{:+.1} %", 100.0 * (r.std / se - 1.0))
            })
        };
        let (ratio, rms) = (against(r.se), against(r.rms_se));
        let z = r.truth.map_or("–".into(), |t| {
            format!("{:+.2}", (r.mean - t) / r.mean_stderr)
        });
        let _ = writeln!(
            s,
            "| {} | {} | {:.6} | {:.6} | {} | {ratio} | {rms} | {:.6} | {z} |",
            r.name,
            r.truth.map_or("–".into(), |t| format!("{t}")),
            r.mean,
            r.std,
            r.se.map_or("–".into(), |v| format!("{v:.6}")),
            r.mean_stderr,
        );
    }
    s
}

/// The case `models`.
pub fn models(o: &Options) -> Result<(), String> {
    if o.shard.1 > 1 {
        return Err("models: --shard is not offered".into());
    }
    let runs = o.runs.unwrap_or(RUNS);
    let mut md = format!(
        "## Models as engineers write them — `cargo xtask reproduce models`\n\n\
         {runs} realisations per case (seed {}); statistics over the converged runs.\n",
        o.seed
    );
    let mut cases = Vec::new();
    for (case, file, method, what) in CASES {
        let c = study(case, file, method, runs, o.seed)?;
        let _ = write!(
            md,
            "\n### `{case}`: {what}\n\n`{}`, method {method}: {} of {} runs converged, {:.2} s wall.\n\n",
            c.file, c.converged, c.runs, c.seconds
        );
        md += &table(&c.parameters);
        cases.push(c);
    }
    let value = serde_json::to_value(&cases).map_err(|e| e.to_string())?;
    write_outputs("models", o, &value, &md)
}
