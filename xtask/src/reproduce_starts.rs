//! Reproduction case of the robustness issue: `starts`.
//!
//! Over the Table 2 records (same seeds, input, jitter and noise as `table2`), how often does a
//! BCLS fit reach the global minimum from a start that does not know the truth?
//!
//! Strategies, each a Levenberg–Marquardt fit with the default options:
//! * `perturbed ±50%`: from the truth × (1 + U(−0.5, 0.5)), componentwise;
//! * `initializer`: from the data-driven initializer ([`initialize`]) alone;
//! * `initializer + multi-start` (the default): [`MultiStart`] around the initializer's start;
//! * `log-perturbed ×/÷10`: a poor start, the truth × 10^U(−1, 1) componentwise (signs kept);
//! * `generic start`: the same fixed guess for every record (gain 1, zero −1, poles −1 ± i),
//!   what a user without an initializer might type.
//!
//! The global minimum of a record is the lowest cost found for it by any strategy or by a
//! reference fit started at the truth. A fit reaches it when it reports convergence, its cost
//! is within a relative `COST_TOL` of that lowest cost, and every parameter is within
//! `PARAM_TOL` (relative to the parameter's magnitude) of the lowest-cost parameters.

use crate::outputs::{runs_range, write_outputs};
use crate::paper::{self, NOISE_STD, RUNS};
use crate::Options;
use jitterid::estimate::montecarlo::run as mc_run;
use jitterid::estimate::solver::{AnySolver, DynSolver, LevenbergMarquardt, MultiStart};
use jitterid::estimate::{
    initialize, residual_flatness, Bcls, FitOptions, InitOptions, ModelStructure, Record,
    FLATNESS_BANDS, FLATNESS_LIMIT,
};
use jitterid::prelude::*;
use rand::Rng;
use serde::Serialize;
use serde_json::json;
use std::fmt::Write as _;
use std::time::Instant;

/// Relative cost tolerance of "at the global minimum".
const COST_TOL: f64 = 1e-6;
/// Relative parameter tolerance of "at the global minimum".
const PARAM_TOL: f64 = 1e-3;
/// Perturbed starts of the default strategy (besides the initializer's own start).
pub const MULTI_STARTS: usize = 8;
/// Relative radius of the default strategy's perturbations.
pub const MULTI_RADIUS: f64 = 0.5;
/// Seed of the default strategy's perturbations (the same for every record, as a user would).
pub const MULTI_SEED: u64 = 1;

const STRATEGIES: [&str; 5] = [
    "perturbed ±50%",
    "initializer",
    "initializer + multi-start",
    "log-perturbed ×/÷10",
    "generic start",
];
/// Index of the default strategy in [`STRATEGIES`].
const DEFAULT: usize = 2;

/// The outcome of one fit.
#[derive(Debug, Clone, Serialize)]
struct Outcome {
    converged: bool,
    cost: f64,
    params: Vec<f64>,
    termination: String,
    /// The library's residual-flatness ratio ([`residual_flatness`]), computed for every fit
    /// (the estimate itself only checks converged BCLS fits that are not exact).
    flatness: f64,
}

impl Outcome {
    fn failed(why: String) -> Self {
        Outcome {
            converged: false,
            cost: f64::INFINITY,
            params: vec![f64::NAN; 4],
            termination: why,
            flatness: f64::NAN,
        }
    }
}

type Structure = ModelStructure<LtiResponse<Zpk>, UniformSum>;

fn fit(structure: &Structure, record: &Record, solver: impl DynSolver + 'static) -> Outcome {
    let options = FitOptions::default()
        .with_solver(solver)
        .with_covariance(false);
    match jitterid::estimate::fit(structure, record, &Bcls, &options) {
        Ok(e) => Outcome {
            converged: e.converged,
            cost: e.cost,
            flatness: residual_flatness(&e.residuals).unwrap_or(f64::NAN),
            params: e.params,
            termination: e.termination.to_string(),
        },
        Err(e) => Outcome::failed(format!("error: {e}")),
    }
}

/// Per record: the strategies' outcomes, the reference fit from the truth, and the
/// initializer's start.
struct RecordResult {
    outcomes: Vec<Outcome>,
    reference: Outcome,
    init_start: Option<Vec<f64>>,
}

fn one_record(truth: [f64; 4], jitter: &UniformSum, rng: &mut rand::rngs::StdRng) -> RecordResult {
    // The Table 2 draws, in the Table 2 order: input, jitter and noise, then the start.
    let g = paper::eq17(truth[0], truth[1], truth[2], truth[3]).expect("valid truth");
    let u = paper::input(rng, 8.0);
    let grid = paper::grid();
    let signal = LtiResponse::new(g.clone(), u);
    let data = simulate(&signal, jitter, &grid, NOISE_STD, rng).expect("valid setup");
    let record = Record::new(grid, data.y).expect("finite data");
    let p = paper::perturb(&truth, 0.5, rng);
    let q: Vec<f64> = truth
        .iter()
        .map(|x| x * 10f64.powf(rng.random_range(-1.0..=1.0)))
        .collect();
    let input = signal.input().clone();
    let structure_of = |m: Zpk| ModelStructure::oe(LtiResponse::new(m, input.clone()), *jitter);
    let lm = LevenbergMarquardt::default();

    let perturbed = match paper::eq17(p[0], p[1], p[2], p[3]) {
        Ok(m) => fit(&structure_of(m), &record, lm.clone()),
        Err(e) => Outcome::failed(format!("invalid start: {e}")),
    };
    // The initializer knows the structure (one real zero, one pair), not the values.
    let template = paper::eq17(1.0, 1.0, -1.0, 1.0).expect("valid template");
    let (init_alone, init_multi, init_start) = match initialize(
        &structure_of(template.clone()),
        &record,
        &InitOptions::default(),
    ) {
        Ok(start) => (
            fit(&start, &record, lm.clone()),
            fit(
                &start,
                &record,
                MultiStart::new(
                    AnySolver::new(lm.clone()),
                    MULTI_STARTS,
                    MULTI_RADIUS,
                    MULTI_SEED,
                ),
            ),
            Some(start.params()),
        ),
        Err(e) => {
            let o = Outcome::failed(format!("initializer: {e}"));
            (o.clone(), o, None)
        }
    };
    let log_perturbed = match paper::eq17(q[0], q[1], q[2], q[3]) {
        Ok(m) => fit(&structure_of(m), &record, lm.clone()),
        Err(e) => Outcome::failed(format!("invalid start: {e}")),
    };
    let generic = fit(&structure_of(template), &record, lm.clone());
    let reference = fit(&structure_of(g), &record, lm);
    RecordResult {
        outcomes: vec![perturbed, init_alone, init_multi, log_perturbed, generic],
        reference,
        init_start,
    }
}

/// Whether `o` is at the global minimum `(cost, params)`.
fn at_global(o: &Outcome, best: &Outcome) -> bool {
    o.converged
        && o.cost <= best.cost * (1.0 + COST_TOL) + f64::MIN_POSITIVE
        && o.params
            .iter()
            .zip(&best.params)
            .all(|(a, b)| (a - b).abs() <= PARAM_TOL * b.abs())
}

#[derive(Debug, Clone, Default, Serialize)]
struct Tally {
    name: String,
    fraction: f64,
    global: usize,
    /// Converged (by the solver's tests) somewhere other than the global minimum.
    converged_elsewhere: usize,
    /// Said that it failed: not converged, or an error.
    reported_failure: usize,
}

pub fn starts(o: &Options) -> Result<(), String> {
    let truth = [0.2, 0.5, -0.25, 0.3];
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).map_err(|e| e.to_string())?;
    let runs = runs_range(o, RUNS);
    let n = (runs.end - runs.start) as usize;
    let t = Instant::now();
    let results: Vec<RecordResult> = mc_run(o.seed, runs.clone(), |_, rng| {
        one_record(truth, &jitter, rng)
    });
    let secs = t.elapsed().as_secs_f64();

    let mut tallies: Vec<Tally> = STRATEGIES
        .iter()
        .map(|s| Tally {
            name: s.to_string(),
            ..Tally::default()
        })
        .collect();
    let mut reference_global = 0;
    // Residual flatness at the global minimum (all strategies' global fits), and of the fits
    // that converged elsewhere.
    let mut flat_global: Vec<f64> = Vec::new();
    let mut flat_elsewhere: Vec<f64> = Vec::new();
    let mut wrong = Vec::new();
    let mut init_err = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for (r, res) in runs.clone().zip(&results) {
        let best = res
            .outcomes
            .iter()
            .chain(std::iter::once(&res.reference))
            .filter(|o| o.cost.is_finite())
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
            .cloned()
            .unwrap_or_else(|| Outcome::failed("no fit".into()));
        reference_global += usize::from(at_global(&res.reference, &best));
        for (tally, out) in tallies.iter_mut().zip(&res.outcomes) {
            if at_global(out, &best) {
                tally.global += 1;
                flat_global.push(out.flatness);
            } else if out.converged {
                tally.converged_elsewhere += 1;
                flat_elsewhere.push(out.flatness);
                wrong.push((r, tally.name.clone(), out.clone(), best.clone()));
            } else {
                tally.reported_failure += 1;
                wrong.push((r, tally.name.clone(), out.clone(), best.clone()));
            }
        }
        if let Some(s) = &res.init_start {
            for (i, (a, b)) in s.iter().zip(&best.params).enumerate() {
                init_err[i].push(((a - b) / b).abs());
            }
        }
    }
    for t in &mut tallies {
        t.fraction = t.global as f64 / n.max(1) as f64;
    }
    let global_fraction = tallies[DEFAULT].fraction;

    let mut md = format!(
        "## Starts: convergence to the global minimum, Table 2 records (BCLS, LM)\n\n\
         {n} records (seed {}, the `table2` records), {secs:.1} s wall. Global minimum of a record: \
         the lowest cost found by any strategy or by a reference fit started at the truth; a fit \
         reaches it when it reports convergence, its cost is within {COST_TOL:e} (relative) of \
         that cost and every parameter within {PARAM_TOL:e} (relative). The default strategy runs \
         `MultiStart` with {MULTI_STARTS} perturbed starts of radius ±{:.0}% (seed {MULTI_SEED}) \
         around the initializer's start.\n\n\
         | strategy | at global minimum | fraction | converged elsewhere | reported failure |\n\
         |---|---|---|---|---|\n",
        o.seed,
        100.0 * MULTI_RADIUS
    );
    for t in &tallies {
        let _ = writeln!(
            md,
            "| {} | {} / {n} | {:.4} | {} | {} |",
            t.name, t.global, t.fraction, t.converged_elsewhere, t.reported_failure
        );
    }
    let _ = writeln!(
        md,
        "| (reference: from the truth) | {reference_global} / {n} | {:.4} | | |",
        reference_global as f64 / n.max(1) as f64
    );
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let worst = |v: &Vec<f64>| v.iter().copied().fold(f64::NAN, f64::max);
    let _ = writeln!(
        md,
        "\nInitializer's start vs the global minimum, relative error per parameter \
         [gain, zero, pole.re, pole.im]: median {}, worst {}.",
        fmt_list(&init_err.iter_mut().map(median).collect::<Vec<_>>()),
        fmt_list(&init_err.iter().map(worst).collect::<Vec<_>>()),
    );
    let max_global = flat_global.iter().copied().fold(f64::NAN, f64::max);
    let flagged_global = flat_global.iter().filter(|&&f| f > FLATNESS_LIMIT).count();
    let flagged_elsewhere = flat_elsewhere
        .iter()
        .filter(|&&f| f > FLATNESS_LIMIT)
        .count();
    let _ = writeln!(
        md,
        "\nResidual flatness (`residual_flatness`: the largest mean |Y − μ_Y|² of {FLATNESS_BANDS} bands \
         over the mean of the others; the noise floor is flat, so ≈ 1 at the global minimum): largest {max_global:.2} over \
         the {} fits at the global minimum ({flagged_global} above {FLATNESS_LIMIT}); {} of the {} \
         fits that converged elsewhere are above {FLATNESS_LIMIT} (values {}).",
        flat_global.len(),
        flagged_elsewhere,
        flat_elsewhere.len(),
        fmt_list(&flat_elsewhere),
    );
    if !wrong.is_empty() {
        md += "\nFits not at the global minimum:\n\n| record | strategy | converged | termination | cost | global cost | flatness | params |\n|---|---|---|---|---|---|---|---|\n";
        for (r, name, out, best) in &wrong {
            let _ = writeln!(
                md,
                "| {r} | {name} | {} | {} | {:.6e} | {:.6e} | {:.3} | {} |",
                out.converged,
                out.termination,
                out.cost,
                best.cost,
                out.flatness,
                fmt_list(&out.params)
            );
        }
    }
    let value = json!({
        "case": "starts",
        "records": n,
        "global_fraction": global_fraction,
        "by_strategy": tallies,
        "reference_global": reference_global,
        "flatness": {
            "limit": FLATNESS_LIMIT,
            "largest_at_global": max_global,
            "flagged_at_global": flagged_global,
            "converged_elsewhere": flat_elsewhere,
        },
        "cost_tol": COST_TOL,
        "param_tol": PARAM_TOL,
        "multi_starts": MULTI_STARTS,
        "multi_radius": MULTI_RADIUS,
        "seconds": secs,
    });
    write_outputs("starts", o, &value, &md)
}

fn fmt_list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.3e}")).collect();
    format!("[{}]", items.join(", "))
}
