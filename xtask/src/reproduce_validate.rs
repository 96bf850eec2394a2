//! Reproduction case `validate`: do the residual tests have their level on the true structure
//! and power against wrong ones?
//!
//! Records of `examples/experiments/validate-true.toml` (a 2-pole, 1-zero system, Gaussian
//! jitter σ = 0.2 s estimated, N = 500), record `r` being `jitterid simulate --seed S --run r`.
//! Each record is fitted and validated (the study layer's `fit_values` and `check_record`,
//! what `jitterid validate` runs) as:
//!
//! * the true structure by BCLS (`validate-true.toml`) and by exact ML
//!   (`validate-true-ml.toml`): each test should reject in a fraction `level` of records;
//! * a one-pole model (`validate-one-pole.toml`): should be rejected;
//! * the true structure given the input as a zero-order hold of its samples on the grid
//!   (`--input <the record>`), while it really switched between samples: a misspecification
//!   the user cannot see in the input file.

use crate::outputs::{runs_range, write_outputs};
use crate::Options;
use jitterid::estimate::montecarlo::run as mc_run;
use jitterid::estimate::validation::CorrelationTest;
use jitterid::signal::Input;
use jitterid_study::experiment::{self, Experiment, Purpose};
use jitterid_study::fit::{fit_values, signal_of};
use jitterid_study::inputs::piecewise;
use jitterid_study::simulate::simulate_data;
use jitterid_study::validate::check_record;
use jitterid_study::Watch;
use serde::Serialize;
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Records of the study.
pub const RUNS: u64 = 200;
/// The levels the rejection rates are reported at (the verdict's default first).
const LEVELS: [f64; 2] = [0.01, 0.05];

/// The cases: a name, the experiment file fitted, and whether its input is the zero-order hold
/// of the record's input samples.
const CASES: [(&str, &str, bool); 5] = [
    ("true structure, BCLS", "validate-true.toml", false),
    ("true structure, ML", "validate-true-ml.toml", false),
    ("one pole, BCLS", "validate-one-pole.toml", false),
    ("ZOH input, BCLS", "validate-true.toml", true),
    ("ZOH input, ML", "validate-true-ml.toml", true),
];

/// One test of one fitted record.
#[derive(Debug, Clone, Serialize)]
struct TestOutcome {
    p_value: f64,
    statistic: f64,
    dof: usize,
    /// The per-lag rule (lags outside the 99 % bounds counted).
    lags_passed: bool,
}

impl From<&CorrelationTest> for TestOutcome {
    fn from(c: &CorrelationTest) -> Self {
        TestOutcome {
            p_value: c.p_value,
            statistic: c.statistic,
            dof: c.dof,
            lags_passed: c.lags_passed,
        }
    }
}

/// One fitted record of one case.
#[derive(Debug, Clone, Serialize)]
struct Outcome {
    converged: bool,
    fit_percent: f64,
    whiteness: TestOutcome,
    cross: TestOutcome,
    /// The fitted `a0` (denominator's constant term) where the model has one.
    a0: Option<f64>,
    /// The fitted jitter standard deviation.
    sigma: Option<f64>,
}

fn read(file: &str) -> Result<Experiment, String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/experiments")
        .join(file);
    experiment::read(&path, Purpose::Estimate(None)).map_err(|e| e.to_string())
}

fn param(f: &jitterid_study::fit::Fit, name: &str) -> Option<f64> {
    f.params.iter().find(|p| p.name == name).map(|p| p.estimate)
}

/// Fits `exp` to the record `y` with input `input` and validates it at `level`.
fn fit_and_check(exp: &Experiment, y: &[f64], input: &Input, r: u64) -> Result<Outcome, String> {
    let name = format!("run {r}");
    let inputs = std::slice::from_ref(input);
    let signal = signal_of(exp, inputs).map_err(|e| e.to_string())?;
    let f =
        fit_values(exp, signal, y.to_vec(), &name, &Watch::none()).map_err(|e| e.to_string())?;
    let (report, _) = check_record(
        &f.fitted,
        &exp.grid,
        y,
        f.noise_std,
        inputs,
        &[],
        LEVELS[0],
        &name,
    )
    .map_err(|e| e.to_string())?;
    let cross = report
        .cross_correlation
        .as_ref()
        .ok_or("the record's input is constant")?;
    Ok(Outcome {
        converged: f.converged,
        fit_percent: report.fit_percent,
        whiteness: (&report.whiteness).into(),
        cross: cross.into(),
        a0: param(&f, "a0"),
        sigma: param(&f, "jitter.sigma"),
    })
}

/// Every case on record `r`: an outcome or the reason there is none.
fn one(r: u64, seed: u64, exps: &[Experiment]) -> Vec<Result<Outcome, String>> {
    let Ok(data) = simulate_data(&exps[0], seed, r) else {
        return vec![Err("simulation failed".into()); CASES.len()];
    };
    let (Some(truth), Some(u)) = (data.inputs.first(), data.u.first()) else {
        return vec![Err("no input".into()); CASES.len()];
    };
    // The input as its samples on the grid, held: what a user with only sampled input has.
    let zoh = piecewise(&data.t, u, &exps[0].grid).map(Input::Piecewise);
    CASES
        .iter()
        .zip(exps)
        .map(|(&(_, _, held), exp)| {
            let input = if held {
                zoh.as_ref().map_err(Clone::clone)?
            } else {
                truth
            };
            fit_and_check(exp, &data.y, input, r)
        })
        .collect()
}

/// A rate and its Monte Carlo standard error.
fn rate(hits: usize, n: usize) -> (f64, f64) {
    let p = hits as f64 / n.max(1) as f64;
    (p, (p * (1.0 - p) / n.max(1) as f64).sqrt())
}

fn pct((p, se): (f64, f64)) -> String {
    format!("{:.1} % ± {:.1}", 100.0 * p, 100.0 * se)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The case `validate`.
pub fn validate_case(o: &Options) -> Result<(), String> {
    let runs = runs_range(o, RUNS);
    let exps: Vec<Experiment> = CASES
        .iter()
        .map(|(_, f, _)| read(f))
        .collect::<Result<_, _>>()?;
    let t = Instant::now();
    let seed = o.seed;
    let results = mc_run(seed, runs.clone(), |r, _| one(r, seed, &exps));
    let wall = t.elapsed().as_secs_f64();
    let mut md = format!(
        "## Validate: level and power of the residual tests, {} records\n\n\
         Records of `examples/experiments/validate-true.toml` (G(s) = (2s + 5)/(s² + 2s + 5), \
         Gaussian jitter σ = 0.2 s, T = 0.5 s, N = 500, random binary input of mean dwell 2 s, \
         noise std 0.05), seed {seed}, runs {}–{}. Rejection = p-value below the level; ± is \
         the Monte Carlo standard error √(p(1−p)/n). \"Either\" rejects when one of the two \
         tests does (nominal 1 − (1 − α)² for a true model). \"Per-lag rule\": the old verdict \
         (lags outside the 99 % bounds counted). Wall time {wall:.0} s.\n\n\
         | case | fitted | whiteness, α = 0.01 | input, α = 0.01 | either, α = 0.01 | whiteness, α = 0.05 | input, α = 0.05 | either, α = 0.05 | per-lag rule, either | median fit % |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        runs.end - runs.start,
        runs.start,
        runs.end.saturating_sub(1),
    );
    let mut cases = Vec::new();
    for (i, (name, file, held)) in CASES.iter().enumerate() {
        let outcomes: Vec<&Outcome> = results.iter().filter_map(|v| v[i].as_ref().ok()).collect();
        let errors: Vec<&String> = results.iter().filter_map(|v| v[i].as_ref().err()).collect();
        let n = outcomes.len();
        let count = |f: &dyn Fn(&Outcome) -> bool| outcomes.iter().filter(|o| f(o)).count();
        let mut row = format!("| {name} | {n} ({} converged) |", count(&|o| o.converged));
        let mut by_level = Vec::new();
        for level in LEVELS {
            let w = rate(count(&|o| o.whiteness.p_value < level), n);
            let c = rate(count(&|o| o.cross.p_value < level), n);
            let e = rate(
                count(&|o| o.whiteness.p_value < level || o.cross.p_value < level),
                n,
            );
            let _ = write!(row, " {} | {} | {} |", pct(w), pct(c), pct(e));
            by_level.push(json!({"level": level, "whiteness": w, "cross": c, "either": e}));
        }
        let lags = rate(
            count(&|o| !(o.whiteness.lags_passed && o.cross.lags_passed)),
            n,
        );
        let fit = median(outcomes.iter().map(|o| o.fit_percent).collect());
        let _ = writeln!(row, " {} | {fit:.1} |", pct(lags));
        md += &row;
        let a0 = median(outcomes.iter().filter_map(|o| o.a0).collect());
        let sigma = median(outcomes.iter().filter_map(|o| o.sigma).collect());
        cases.push(json!({
            "case": name, "file": format!("examples/experiments/{file}"), "zoh_input": held,
            "fitted": n, "errors": errors, "rates": by_level, "per_lag_rule_either": lags,
            "median_fit_percent": fit, "median_a0": a0, "median_jitter_sigma": sigma,
            "outcomes": outcomes,
        }));
    }
    md += "\nMedian estimates (true a0 = 5, jitter σ = 0.2 s):\n\n| case | a0 | jitter σ (s) |\n|---|---|---|\n";
    for c in &cases {
        let f = |k: &str| c[k].as_f64().map_or("–".into(), |v| format!("{v:.3}"));
        let _ = writeln!(
            md,
            "| {} | {} | {} |",
            c["case"].as_str().unwrap_or(""),
            f("median_a0"),
            f("median_jitter_sigma")
        );
    }
    let value = json!({"case": "validate", "seed": seed, "runs": [runs.start, runs.end], "seconds": wall, "cases": cases});
    write_outputs("validate", o, &value, &md)
}
