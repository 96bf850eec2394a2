//! Reproduction case `select`: how often does order × family selection pick the truth?
//!
//! Records of the second-order system `G(s) = 5/((s + 1)² + 4)` (poles −1 ± 2i, 0.36 Hz
//! natural frequency) driven by a random binary input of mean dwell `T` (content up to
//! Nyquist), `N = 1000` samples at `T = 1 s`, measurement noise 0.01. The jitter cycles over
//! [`TRUTHS`] by record index (record `r` has truth `TRUTHS[r % TRUTHS.len()]`). Every record is
//! ranked by [`select`] over [`POLES`] × [`FAMILIES`] (no zeros), the grid of
//! `examples/experiments/select.toml`; a record is a success when the best candidate has the
//! true number of poles and the true family. The same run also reports what the BCLS screen
//! alone (the first stage of [`select`]) would have picked.

use crate::outputs::{runs_range, write_outputs};
use crate::Options;
use jitterid::estimate::montecarlo::run as mc_run;
use jitterid::estimate::selection::{select, Candidate, SelectionGrid, SelectionOptions};
use jitterid::estimate::Record;
use jitterid::prelude::*;
use serde_json::json;
use std::fmt::Write as _;
use std::time::Instant;

/// Records of the study.
pub const RUNS: u64 = 128;
/// Samples per record.
pub const SAMPLES: usize = 1000;
/// Mean dwell of the random binary input (s).
pub const MEAN_DWELL: f64 = 1.0;
/// Measurement noise standard deviation.
pub const NOISE_STD: f64 = 0.01;
/// The true jitter families and their standard deviations (in units of `T`), cycled by record.
pub const TRUTHS: [(&str, f64); 3] = [("periodic", 0.5), ("gaussian", 0.5), ("none", 0.0)];
/// Families of the selection grid.
pub const FAMILIES: [&str; 4] = ["none", "gaussian", "periodic", "two-point"];
/// Range of the number of poles of the grid (inclusive).
pub const POLES: (usize, usize) = (1, 3);
/// True number of poles.
const TRUE_POLES: usize = 2;

/// The system of the study.
pub fn system() -> Result<Zpk, String> {
    Zpk::new(5.0, vec![], vec![Root::Pair { re: -1.0, im: 2.0 }]).map_err(|e| e.to_string())
}

/// The selection grid of the study.
pub fn grid() -> SelectionGrid {
    SelectionGrid {
        poles: POLES,
        zeros: (0, 0),
        families: FAMILIES.iter().map(|s| s.to_string()).collect(),
    }
}

/// The true jitter of `family` at standard deviation `std · T` (T = 1 s; `"none"` ignores it).
pub fn truth_jitter(family: &str, std: f64) -> Result<AnyJitter, String> {
    JitterRegistry::builtin()
        .from_std_dev(family, std, &serde_json::Map::new())
        .map_err(|e| e.to_string())
}

/// One record of the study (realisation drawn from `rng`) and its input.
pub fn record(jitter: &AnyJitter, rng: &mut rand::rngs::StdRng) -> Result<(Record, Input), String> {
    let n = SAMPLES as f64;
    let u = RandomBinary::new(MEAN_DWELL, 0.0, 1.0)
        .and_then(|rb| rb.generate(-10.0, n + 10.0, rng))
        .map_err(|e| e.to_string())?;
    let grid = SampleGrid::new(0.0, 1.0, SAMPLES).map_err(|e| e.to_string())?;
    let signal = LtiResponse::new(system()?, u.clone());
    let data = simulate(&signal, jitter, &grid, NOISE_STD, rng).map_err(|e| e.to_string())?;
    Ok((
        Record::new(grid, data.y).map_err(|e| e.to_string())?,
        u.into(),
    ))
}

/// The picked (poles, family) of one record, by the final ranking and by the BCLS screen
/// alone, with the criterion margins of the truth over the best other candidate (positive when
/// the truth wins; `−∞` when the true candidate is not in the comparison), the finalists whose
/// likelihood fit failed, and the record's CPU-thread seconds.
struct Outcome {
    truth: usize,
    picked: Option<(usize, String)>,
    screen_picked: Option<(usize, String)>,
    margin: f64,
    screen_margin: f64,
    likelihood_failures: Vec<String>,
    seconds: f64,
}

/// The margin of the candidate `is_true` picks over the best other one, among the candidates
/// `in_race` admits, by `score`.
fn margin(
    ranked: &[Candidate],
    in_race: impl Fn(&Candidate) -> bool,
    is_true: impl Fn(&Candidate) -> bool,
    score: impl Fn(&Candidate) -> f64,
) -> f64 {
    let truth = ranked
        .iter()
        .filter(|c| in_race(c) && is_true(c))
        .map(&score)
        .fold(f64::INFINITY, f64::min);
    let other = ranked
        .iter()
        .filter(|c| in_race(c) && !is_true(c))
        .map(&score)
        .fold(f64::INFINITY, f64::min);
    if truth.is_finite() {
        other - truth
    } else {
        f64::NEG_INFINITY
    }
}

fn one(r: u64, rng: &mut rand::rngs::StdRng) -> Result<Outcome, String> {
    let t = Instant::now();
    let ti = (r as usize) % TRUTHS.len();
    let (family, std) = TRUTHS[ti];
    let jitter = truth_jitter(family, std)?;
    let (rec, input) = record(&jitter, rng)?;
    let ranked = select(
        &rec,
        &input,
        &grid(),
        JitterRegistry::builtin(),
        &SelectionOptions::default(),
    )
    .map_err(|e| e.to_string())?;
    let is_true = |c: &Candidate| c.poles == TRUE_POLES && c.family == family;
    let screen_best = ranked
        .iter()
        .filter(|c| c.bcls_converged)
        .min_by(|a, b| a.bcls_criterion.total_cmp(&b.bcls_criterion));
    Ok(Outcome {
        truth: ti,
        picked: ranked
            .first()
            .filter(|c| c.converged)
            .map(|c| (c.poles, c.family.clone())),
        screen_picked: screen_best.map(|c| (c.poles, c.family.clone())),
        margin: margin(
            &ranked,
            |c| c.ranked_by_likelihood,
            is_true,
            |c| c.criterion,
        ),
        screen_margin: margin(&ranked, |c| c.bcls_converged, is_true, |c| c.bcls_criterion),
        likelihood_failures: ranked
            .iter()
            .filter_map(|c| {
                c.likelihood_failure
                    .as_ref()
                    .map(|e| format!("{}/{}: {e}", c.poles, c.family))
            })
            .collect(),
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// Rows: truth; columns: every (poles, family) of `columns`, then "failed".
fn confusion(
    results: &[Outcome],
    columns: &[(usize, String)],
    pick: impl Fn(&Outcome) -> Option<&(usize, String)>,
) -> (Vec<Vec<usize>>, Vec<(usize, usize)>) {
    let mut counts = vec![vec![0usize; columns.len() + 1]; TRUTHS.len()];
    let mut per_truth = vec![(0usize, 0usize); TRUTHS.len()];
    for res in results {
        let picked = pick(res);
        let col = picked
            .and_then(|p| columns.iter().position(|c| c == p))
            .unwrap_or(columns.len());
        counts[res.truth][col] += 1;
        let ok = picked == Some(&(TRUE_POLES, TRUTHS[res.truth].0.to_string()));
        per_truth[res.truth].0 += usize::from(ok);
        per_truth[res.truth].1 += 1;
    }
    (counts, per_truth)
}

fn confusion_md(
    counts: &[Vec<usize>],
    per_truth: &[(usize, usize)],
    columns: &[(usize, String)],
) -> String {
    let used: Vec<usize> = (0..=columns.len())
        .filter(|&c| counts.iter().any(|row| row[c] > 0))
        .collect();
    let name = |c: usize| {
        columns
            .get(c)
            .map_or("failed".to_string(), |(p, f)| format!("{p}/{f}"))
    };
    let mut md = "| truth |".to_string();
    for &c in &used {
        let _ = write!(md, " {} |", name(c));
    }
    md += " correct |\n|---|";
    for _ in &used {
        md += "---|";
    }
    md += "---|\n";
    for (ti, row) in counts.iter().enumerate() {
        let _ = write!(md, "| {TRUE_POLES}/{} |", TRUTHS[ti].0);
        for &c in &used {
            let _ = write!(md, " {} |", row[c]);
        }
        let (h, m) = per_truth[ti];
        let _ = writeln!(md, " {h} / {m} |");
    }
    md
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

pub fn select_case(o: &Options) -> Result<(), String> {
    let runs = runs_range(o, RUNS);
    let t = Instant::now();
    let results = mc_run(o.seed, runs.clone(), one);
    let wall = t.elapsed().as_secs_f64();
    let results: Vec<Outcome> = results.into_iter().collect::<Result<_, _>>()?;
    let n = results.len();
    // Columns of the confusion tables: every (poles, family) of the grid, then "failed".
    let mut columns: Vec<(usize, String)> = Vec::new();
    for p in POLES.0..=POLES.1 {
        for f in FAMILIES {
            columns.push((p, f.to_string()));
        }
    }
    let (counts, per_truth) = confusion(&results, &columns, |r| r.picked.as_ref());
    let (screen_counts, screen_per_truth) =
        confusion(&results, &columns, |r| r.screen_picked.as_ref());
    let hits: usize = per_truth.iter().map(|t| t.0).sum();
    let screen_hits: usize = screen_per_truth.iter().map(|t| t.0).sum();
    let rate = hits as f64 / n.max(1) as f64;
    let screen_rate = screen_hits as f64 / n.max(1) as f64;
    let cpu: f64 = results.iter().map(|r| r.seconds).sum();
    let margins = sorted(results.iter().map(|r| r.margin).collect());
    let screen_margins = sorted(results.iter().map(|r| r.screen_margin).collect());
    let failures: Vec<String> = results
        .iter()
        .flat_map(|r| r.likelihood_failures.iter().cloned())
        .collect();
    let mut md = format!(
        "## Select: order × family selection, {n} records\n\n\
         G(s) = 5/((s + 1)² + 4), random binary input of mean dwell {MEAN_DWELL} s (levels 0, 1), \
         N = {SAMPLES}, T = 1 s, noise std {NOISE_STD}; the true jitter cycles over {} by record \
         index. Grid: {}–{} poles, no zeros, families {} (BCLS screen, exact-likelihood BIC \
         among the best of each family; `select` defaults). Seed {}.\n\n\
         True order and family picked: **{hits} / {n} = {:.1} %** (the BCLS screen alone: \
         {screen_hits} / {n} = {:.1} %). Wall time {wall:.1} s (summed per-record thread time \
         {cpu:.1} s).\n\n",
        TRUTHS
            .iter()
            .map(|(f, s)| if *f == "none" {
                "none".to_string()
            } else {
                format!("{f} (std {s} T)")
            })
            .collect::<Vec<_>>()
            .join(", "),
        POLES.0,
        POLES.1,
        FAMILIES.join(", "),
        o.seed,
        100.0 * rate,
        100.0 * screen_rate
    );
    md += "Confusion table (rows: truth; columns: picked poles/family; only columns picked at least once):\n\n";
    md += &confusion_md(&counts, &per_truth, &columns);
    md += "\nThe BCLS screen alone:\n\n";
    md += &confusion_md(&screen_counts, &screen_per_truth, &columns);
    let quantile = |v: &[f64], q: f64| {
        v.get(((v.len() as f64 - 1.0) * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    let _ = writeln!(
        md,
        "\nMargin of the true candidate over the best other one (positive: the truth wins; \
         −inf: the true candidate was not in the comparison). Exact-likelihood BIC among the \
         finalists: smallest {:.2}, 10 % {:.2}, median {:.2}. BCLS BIC: smallest {:.2}, \
         10 % {:.2}, median {:.2}.",
        quantile(&margins, 0.0),
        quantile(&margins, 0.1),
        quantile(&margins, 0.5),
        quantile(&screen_margins, 0.0),
        quantile(&screen_margins, 0.1),
        quantile(&screen_margins, 0.5),
    );
    let _ = writeln!(
        md,
        "\nFinalists whose likelihood fit failed or did not converge: {}.{}",
        failures.len(),
        failures
            .iter()
            .take(10)
            .map(|f| format!("\n- {f}"))
            .collect::<String>()
    );
    let value = json!({
        "case": "select",
        "records": n,
        "correct": hits,
        "rate": rate,
        "screen_correct": screen_hits,
        "screen_rate": screen_rate,
        "confusion": counts,
        "screen_confusion": screen_counts,
        "columns": columns.iter().map(|(p, f)| format!("{p}/{f}")).chain(["failed".to_string()]).collect::<Vec<_>>(),
        "truths": TRUTHS.iter().map(|(f, s)| json!({"family": f, "std": s})).collect::<Vec<_>>(),
        "margins": results.iter().map(|r| r.margin.is_finite().then_some(r.margin)).collect::<Vec<_>>(),
        "screen_margins": results.iter().map(|r| r.screen_margin.is_finite().then_some(r.screen_margin)).collect::<Vec<_>>(),
        "picked": results.iter().map(|r| r.picked.as_ref().map(|(p, f)| format!("{p}/{f}"))).collect::<Vec<_>>(),
        "screen_picked": results.iter().map(|r| r.screen_picked.as_ref().map(|(p, f)| format!("{p}/{f}"))).collect::<Vec<_>>(),
        "likelihood_failures": failures,
        "seconds": wall,
        "thread_seconds": cpu,
    });
    write_outputs("select", o, &value, &md)
}
