//! `cargo xtask reproduce models`: models as engineers write them, from the example experiment
//! files through the command line's own Monte Carlo — grey-box state-space models identified in
//! their physical parameters (a mass–spring–damper, a DC motor) under uniform-sum and Gaussian
//! jitter.
//!
//! Each case reports, per parameter, the Monte Carlo mean and spread of the estimates and the
//! mean of the standard errors the fits reported (`mean_stderr`): the estimate is unbiased when
//! `|mean − true|` is small against `std`, and the reported standard errors are right when
//! `mean_stderr` matches `std`.

use crate::outputs::write_outputs;
use crate::paper::RUNS;
use crate::reproduce_initial::{study, table};
use crate::Options;
use serde_json::{json, Value};
use std::fmt::Write as _;

/// The example files and what each shows.
const CASES: [(&str, &str); 4] = [
    (
        "msd-uniform.toml",
        "mass–spring–damper (m, damp, k), uniform-sum jitter",
    ),
    (
        "msd-gaussian.toml",
        "mass–spring–damper (m, damp, k), Gaussian jitter",
    ),
    (
        "dc-motor-uniform.toml",
        "DC motor (J, b, K; R and L known), uniform-sum jitter",
    ),
    (
        "dc-motor-gaussian.toml",
        "DC motor (J, b, K; R and L known), Gaussian jitter",
    ),
];

/// The case `models`: one object per example file, `{case, runs, converged, parameters:
/// [{name, true, mean, std, se, mean_stderr}]}` (`se` the standard error of the mean,
/// `mean_stderr` the mean of the standard errors the fits reported).
pub fn models(o: &Options) -> Result<(), String> {
    if o.shard.1 > 1 {
        return Err("models: --shard is not offered (each study takes seconds)".into());
    }
    let runs = o.runs.unwrap_or(RUNS);
    let mut md = format!(
        "## Models in physical parameters — `cargo xtask reproduce models`\n\n\
         Grey-box state-space models from the example files (BCLS, jitter known, noise std \
         0.01), {runs} realisations each (seed {}); statistics over every run with estimates.\n",
        o.seed
    );
    let mut cases: Vec<Value> = Vec::new();
    for (file, what) in CASES {
        let c = study(file, runs, o.seed)?;
        let _ = write!(
            md,
            "\n### `{}`: {what}\n\n{} of {} runs with estimates, {} not converged.\n\n",
            c.file, c.fitted, c.runs, c.flagged
        );
        md += &table(&c.parameters);
        let parameters: Vec<Value> = c
            .parameters
            .iter()
            .map(|r| {
                json!({"name": r.name, "true": r.truth, "mean": r.mean, "std": r.std,
                       "se": r.se, "mean_stderr": r.reported_std})
            })
            .collect();
        cases.push(json!({
            "case": file.trim_end_matches(".toml"),
            "runs": c.runs,
            "converged": c.runs as usize - c.flagged,
            "parameters": parameters,
        }));
    }
    write_outputs("models", o, &json!(cases), &md)
}
