//! Reproduction case `select`: how often does order × family selection pick the truth?
//!
//! Records of the second-order system `G(s) = 5/((s + 1)² + 4)` (poles −1 ± 2i, 0.36 Hz
//! natural frequency) driven by a random binary input of mean dwell `T` (content up to
//! Nyquist), `N = 1000` samples at `T = 1 s`, measurement noise 0.01. The jitter cycles over
//! [`TRUTHS`] by record index (record `r` has truth `TRUTHS[r % TRUTHS.len()]`). Every record is
//! ranked by [`select`] over [`POLES`] × [`FAMILIES`] (no zeros), the grid of
//! `examples/experiments/select.toml`; a record is a success when the best candidate has the
//! true number of poles and the true family.

use crate::reproduce::{runs_range, write_outputs};
use crate::Options;
use jitterid::estimate::montecarlo::run as mc_run;
use jitterid::estimate::selection::{select, SelectionGrid, SelectionOptions};
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

/// The picked (poles, family) of one record, with the criterion margin of the truth over the
/// best other candidate (positive when the truth wins), and the record's CPU-thread seconds.
struct Outcome {
    truth: usize,
    picked: Option<(usize, String)>,
    margin: f64,
    seconds: f64,
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
    let is_true = |c: &&jitterid::estimate::selection::Candidate| {
        c.converged && c.poles == TRUE_POLES && c.family == family
    };
    let true_bic = ranked
        .iter()
        .find(is_true)
        .map_or(f64::INFINITY, |c| c.criterion);
    let other = ranked
        .iter()
        .filter(|c| c.converged && !is_true(c))
        .map(|c| c.criterion)
        .fold(f64::INFINITY, f64::min);
    Ok(Outcome {
        truth: ti,
        picked: ranked
            .first()
            .filter(|c| c.converged)
            .map(|c| (c.poles, c.family.clone())),
        margin: other - true_bic,
        seconds: t.elapsed().as_secs_f64(),
    })
}

pub fn select_case(o: &Options) -> Result<(), String> {
    let runs = runs_range(o, RUNS);
    let t = Instant::now();
    let results = mc_run(o.seed, runs.clone(), one);
    let wall = t.elapsed().as_secs_f64();
    let results: Vec<Outcome> = results.into_iter().collect::<Result<_, _>>()?;
    let n = results.len();
    // Columns of the confusion table: every (poles, family) of the grid, then "failed".
    let mut columns: Vec<(usize, String)> = Vec::new();
    for p in POLES.0..=POLES.1 {
        for f in FAMILIES {
            columns.push((p, f.to_string()));
        }
    }
    let mut counts = vec![vec![0usize; columns.len() + 1]; TRUTHS.len()];
    let mut hits = 0;
    let mut per_truth = vec![(0usize, 0usize); TRUTHS.len()];
    for res in &results {
        let col = res
            .picked
            .as_ref()
            .and_then(|p| columns.iter().position(|c| c == p))
            .unwrap_or(columns.len());
        counts[res.truth][col] += 1;
        let ok = res.picked.as_ref() == Some(&(TRUE_POLES, TRUTHS[res.truth].0.to_string()));
        hits += usize::from(ok);
        per_truth[res.truth].0 += usize::from(ok);
        per_truth[res.truth].1 += 1;
    }
    let rate = hits as f64 / n.max(1) as f64;
    let cpu: f64 = results.iter().map(|r| r.seconds).sum();
    let mut margins: Vec<f64> = results.iter().map(|r| r.margin).collect();
    margins.sort_by(f64::total_cmp);
    let mut md = format!(
        "## Select: order × family selection, {n} records\n\n\
         G(s) = 5/((s + 1)² + 4), random binary input of mean dwell {MEAN_DWELL} s (levels 0, 1), \
         N = {SAMPLES}, T = 1 s, noise std {NOISE_STD}; the true jitter cycles over {} by record \
         index. Grid: {}–{} poles, no zeros, families {} (BCLS, BIC; `select` defaults). \
         Seed {}.\n\n\
         True order and family picked: **{hits} / {n} = {:.1} %**. Wall time {wall:.1} s \
         (summed per-record thread time {cpu:.1} s).\n\n",
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
        100.0 * rate
    );
    md += "Confusion table (rows: truth; columns: picked poles/family; only columns picked at least once):\n\n";
    let used: Vec<usize> = (0..=columns.len())
        .filter(|&c| counts.iter().any(|row| row[c] > 0))
        .collect();
    let name = |c: usize| {
        columns
            .get(c)
            .map_or("failed".to_string(), |(p, f)| format!("{p}/{f}"))
    };
    md += "| truth |";
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
    let _ = writeln!(
        md,
        "\nBIC margin of the true candidate over the best other one (positive: the truth wins): \
         smallest {:.2}, median {:.2}.",
        margins.first().copied().unwrap_or(f64::NAN),
        margins.get(margins.len() / 2).copied().unwrap_or(f64::NAN)
    );
    let value = json!({
        "case": "select",
        "records": n,
        "correct": hits,
        "rate": rate,
        "confusion": counts,
        "columns": columns.iter().map(|(p, f)| format!("{p}/{f}")).chain(["failed".to_string()]).collect::<Vec<_>>(),
        "truths": TRUTHS.iter().map(|(f, s)| json!({"family": f, "std": s})).collect::<Vec<_>>(),
        "smallest_margin": margins.first(),
        "seconds": wall,
        "thread_seconds": cpu,
    });
    write_outputs("select", o, &value, &md)
}
