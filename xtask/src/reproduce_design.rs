//! `cargo xtask reproduce design`: the evidence of issue 29 for experiment design under
//! jitter, on the paper's Table 2 system (mean dwell free in `[1, 40]` s) and on a lightly
//! damped resonance with wide jitter (`examples/experiments/design-resonant.toml`), and a
//! multisine's tones on the Table 2 system (`examples/experiments/design-multisine.toml`:
//! eight harmonics of `1/(N T)` in a band, the file's power held, the baseline the file's own
//! four-tone multisine), for BCLS and exact ML:
//!
//! * the predicted standard deviation of every parameter at the optimal design against a
//!   Monte Carlo of `--runs` realisations there (the prediction averaged over the same input
//!   draws the runs see);
//! * the D-criterion of the optimal design against the paper's input (mean dwell 8 s, the same
//!   `N`, `T` and levels), predicted and by Monte Carlo;
//! * the jitter-blind design (the same search with `γ ≡ 1` and no jitter noise) against the
//!   jitter-aware one, both by Monte Carlo on jittered data.
//!
//! Every case writes `{"case", "estimator", "predicted_std", "monte_carlo_std", "names",
//! "criterion_optimal", "criterion_baseline", "criterion_jitter_blind"}` (the last three by
//! Monte Carlo on jittered data) with the designs, the predicted criteria and the Monte
//! Carlo's standard errors beside them.

use crate::outputs::write_outputs;
use crate::Options;
use jitterid_study::design::{
    criterion_difference, evaluate, jitter_blind, monte_carlo, optimise, Design, MonteCarloCheck,
    Plan,
};
use jitterid_study::experiment::{Override, ReadOptions};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Realisations per Monte Carlo (issue 29's 256).
const RUNS: u64 = 256;

/// The cases: name, example file, edits, what it shows.
const CASES: [(&str, &str, &[&str], &str); 3] = [
    (
        "table2",
        "table2.toml",
        &["design.mean_dwell=[1.0, 40.0]"],
        "the paper's Table 2 system and jitter, mean dwell free in [1, 40] s",
    ),
    (
        "resonant",
        "design-resonant.toml",
        &[],
        "a lightly damped resonance (0.32 Hz, ζ ≈ 0.025) with wide uniform jitter (a = 0.4 s), mean dwell free in [0.5, 40] s",
    ),
    (
        "table2-multisine",
        "design-multisine.toml",
        &[],
        "the Table 2 system and jitter driven by a multisine: up to eight tones in [0.005, 0.45] Hz at the file's power 0.125, against the file's four tones with zero phases",
    ),
];

/// One case and estimator, as the JSON names it, with what explains the numbers.
#[derive(Debug, Clone, Serialize)]
struct Case {
    case: String,
    estimator: String,
    names: Vec<String>,
    predicted_std: Vec<f64>,
    monte_carlo_std: Vec<f64>,
    /// Monte Carlo standard error of each standard deviation.
    monte_carlo_std_se: Vec<f64>,
    /// The three criteria by Monte Carlo on jittered data, and their jackknife errors.
    criterion_optimal: f64,
    criterion_baseline: f64,
    criterion_jitter_blind: f64,
    criterion_optimal_se: f64,
    criterion_baseline_se: f64,
    criterion_jitter_blind_se: f64,
    /// The baseline's and the jitter-blind design's criterion minus the optimum's, over the
    /// runs converged at both, with the paired jackknife's standard error (run `r` of every
    /// design shares its jitter and noise streams); `null` with too few common runs.
    paired_baseline: Option<PairedDifference>,
    paired_jitter_blind: Option<PairedDifference>,
    /// The same criteria predicted (under the true prior).
    predicted_criterion_optimal: f64,
    predicted_criterion_baseline: f64,
    predicted_criterion_jitter_blind: f64,
    criterion: String,
    design_optimal: Design,
    design_baseline: Design,
    design_jitter_blind: Design,
    runs: u64,
    /// Realisations summarised (converged) at the optimal, baseline and jitter-blind designs.
    used: [usize; 3],
    /// Input draws each search's prediction averaged over.
    search_draws: usize,
    /// Wall time of the case: both searches, three predictions and three Monte Carlos (s).
    seconds: f64,
}

/// A criterion's difference between two designs by Monte Carlo, paired by run.
#[derive(Debug, Clone, Serialize)]
struct PairedDifference {
    difference: f64,
    se: f64,
    /// Runs converged at both designs.
    runs: usize,
}

impl PairedDifference {
    fn of(
        optimal: &MonteCarloCheck,
        other: &MonteCarloCheck,
        criterion: &jitterid_study::experiment::DesignCriterion,
    ) -> Result<Option<Self>, jitterid_study::StudyError> {
        Ok(
            criterion_difference(optimal, other, criterion)?.map(|(difference, se, runs)| {
                PairedDifference {
                    difference,
                    se,
                    runs,
                }
            }),
        )
    }
}

fn study(
    case: &str,
    file: &str,
    edits: &[&str],
    estimator: &str,
    runs: u64,
    seed: u64,
) -> Result<Case, String> {
    let t = Instant::now();
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/experiments")
        .join(file);
    let text = |e: jitterid_study::StudyError| format!("{case} ({estimator}): {e}");
    let mut overrides = edits
        .iter()
        .map(|e| Override::parse(e))
        .collect::<Result<Vec<_>, _>>()
        .map_err(text)?;
    overrides.push(Override::parse(&format!("design.estimator={estimator}")).map_err(text)?);
    let read = ReadOptions {
        overrides,
        ..ReadOptions::default()
    };
    let plan = Plan::read(&path, &read).map_err(text)?;
    let criterion = plan.spec.criterion.clone();
    let optimal = optimise(&plan, &criterion).map_err(text)?.design;
    let blind = jitter_blind(&plan, &criterion).map_err(text)?.design;
    let baseline = plan.baseline_design();
    // Predictions on the Monte Carlo's own input draws (draw r is run r's input), the first
    // MAX_DRAWS of them for a longer study.
    let draws = (runs as usize).min(jitterid_study::experiment::MAX_DRAWS);
    let matched = plan.with_draws(draws, seed).map_err(text)?;
    let mut predicted = Vec::new();
    let mut checks: Vec<MonteCarloCheck> = Vec::new();
    for d in [&optimal, &baseline, &blind] {
        predicted.push(evaluate(&matched, d, &criterion).map_err(text)?);
        checks.push(monte_carlo(&plan, d, &criterion, runs, seed).map_err(text)?);
    }
    let (p_opt, _) = &predicted[0];
    let paired_baseline = PairedDifference::of(&checks[0], &checks[1], &criterion).map_err(text)?;
    let paired_jitter_blind =
        PairedDifference::of(&checks[0], &checks[2], &criterion).map_err(text)?;
    Ok(Case {
        paired_baseline,
        paired_jitter_blind,
        case: case.into(),
        estimator: estimator.into(),
        names: p_opt.names.clone(),
        predicted_std: p_opt.std.clone(),
        monte_carlo_std: checks[0].std.clone(),
        monte_carlo_std_se: checks[0].std_se.clone(),
        criterion_optimal: checks[0].criterion,
        criterion_baseline: checks[1].criterion,
        criterion_jitter_blind: checks[2].criterion,
        criterion_optimal_se: checks[0].criterion_se,
        criterion_baseline_se: checks[1].criterion_se,
        criterion_jitter_blind_se: checks[2].criterion_se,
        predicted_criterion_optimal: predicted[0].1,
        predicted_criterion_baseline: predicted[1].1,
        predicted_criterion_jitter_blind: predicted[2].1,
        criterion: criterion.to_string(),
        design_optimal: optimal,
        design_baseline: baseline,
        design_jitter_blind: blind,
        runs,
        used: [checks[0].used, checks[1].used, checks[2].used],
        search_draws: plan.spec.draws,
        seconds: t.elapsed().as_secs_f64(),
    })
}

fn dwell(d: &Design) -> String {
    if let Some(m) = &d.multisine {
        let tones: Vec<String> = m
            .frequencies
            .iter()
            .zip(&m.amplitudes)
            .map(|(f, a)| format!("{f:.3} Hz: {a:.3}"))
            .collect();
        return format!(
            "{} tones ({}), power {:.4}, crest factor {:.3}",
            tones.len(),
            tones.join(", "),
            m.power,
            m.crest_factor
        );
    }
    d.mean_dwell.map_or("–".into(), |m| format!("{m:.3} s"))
}

/// The Markdown of one case: the standard deviations, then the three designs' criteria and
/// the two margins in units of their Monte Carlo error.
fn table(c: &Case) -> String {
    let mut s = String::from(
        "| parameter | predicted std | Monte Carlo std | its se | MC/predicted − 1 |\n|---|---|---|---|---|\n",
    );
    for (i, name) in c.names.iter().enumerate() {
        let _ = writeln!(
            s,
            "| {name} | {:.6} | {:.6} | {:.6} | {:+.1} % |",
            c.predicted_std[i],
            c.monte_carlo_std[i],
            c.monte_carlo_std_se[i],
            100.0 * (c.monte_carlo_std[i] / c.predicted_std[i] - 1.0)
        );
    }
    let _ = write!(
        s,
        "\n| design | mean dwell or tones | predicted {0} | Monte Carlo {0} (jackknife se) | converged |\n|---|---|---|---|---|\n",
        c.criterion
    );
    // The baseline is the paper's input, or for a multisine design the file's own tones.
    let baseline_name = if c.design_baseline.multisine.is_some() {
        "file's multisine"
    } else {
        "paper's input"
    };
    let rows = [
        (
            "optimal (jitter-aware)",
            &c.design_optimal,
            c.predicted_criterion_optimal,
            c.criterion_optimal,
            c.criterion_optimal_se,
            c.used[0],
        ),
        (
            baseline_name,
            &c.design_baseline,
            c.predicted_criterion_baseline,
            c.criterion_baseline,
            c.criterion_baseline_se,
            c.used[1],
        ),
        (
            "jitter-blind",
            &c.design_jitter_blind,
            c.predicted_criterion_jitter_blind,
            c.criterion_jitter_blind,
            c.criterion_jitter_blind_se,
            c.used[2],
        ),
    ];
    for (name, d, p, m, se, used) in rows {
        let _ = writeln!(
            s,
            "| {name} | {} | {p:.3} | {m:.3} ({se:.3}) | {used} of {} |",
            dwell(d),
            c.runs
        );
    }
    let margin = |other: f64, other_se: f64| {
        let diff = other - c.criterion_optimal;
        let se = (other_se.powi(2) + c.criterion_optimal_se.powi(2)).sqrt();
        (diff, se)
    };
    let (db, sb) = margin(c.criterion_baseline, c.criterion_baseline_se);
    let (dj, sj) = margin(c.criterion_jitter_blind, c.criterion_jitter_blind_se);
    let paired = |p: &Option<PairedDifference>| match p {
        Some(p) => format!(
            "; paired by run, {:+.3} ± {:.3} ({:.1} se, {} runs)",
            p.difference,
            p.se,
            p.difference / p.se,
            p.runs
        ),
        None => String::new(),
    };
    let _ = write!(
        s,
        "\nBy Monte Carlo, the {baseline_name} minus the optimum: {db:+.3} ± {sb:.3} ({:.1} se{}; predicted {:+.3}, a factor {:.2} in det C); \
         the jitter-blind design minus the optimum: {dj:+.3} ± {sj:.3} ({:.1} se{}; predicted {:+.3}). Wall time {:.1} s.\n",
        db / sb,
        paired(&c.paired_baseline),
        c.predicted_criterion_baseline - c.predicted_criterion_optimal,
        db.exp(),
        dj / sj,
        paired(&c.paired_jitter_blind),
        c.predicted_criterion_jitter_blind - c.predicted_criterion_optimal,
        c.seconds
    );
    s
}

/// The case `design`: both estimators.
pub fn design(o: &Options) -> Result<(), String> {
    design_for(o, "design", &["bcls", "ml"], |_| true)
}

/// The case `design-multisine`: the multisine case alone, both estimators (minutes, where
/// `design` takes the better part of an hour).
pub fn design_multisine(o: &Options) -> Result<(), String> {
    design_for(o, "design-multisine", &["bcls", "ml"], |case| {
        case == "table2-multisine"
    })
}

/// The case `design-bcls`: BCLS alone, cheap enough for more runs (`--runs 1024`) where a
/// margin needs a smaller Monte Carlo error than 256 runs give.
pub fn design_bcls(o: &Options) -> Result<(), String> {
    design_for(o, "design-bcls", &["bcls"], |_| true)
}

fn design_for(
    o: &Options,
    name: &str,
    estimators: &[&str],
    wanted: impl Fn(&str) -> bool,
) -> Result<(), String> {
    if o.shard.1 > 1 {
        return Err("design: --shard is not offered".into());
    }
    let runs = o.runs.unwrap_or(RUNS);
    let mut md = format!(
        "## Experiment design — `cargo xtask reproduce {name}`\n\n\
         {runs} realisations per design (seed {}); statistics over the converged runs; the \
         criterion's standard error by the jackknife over the realisations, a standard \
         deviation's by the delta method with the sample kurtosis; a difference's `±` as if \
         the designs' studies were independent, and paired by run (the jackknife of the \
         difference, each run left out of both designs: run `r` of every design shares its \
         jitter and noise streams).{}\n",
        o.seed,
        if runs as usize > jitterid_study::experiment::MAX_DRAWS {
            format!(
                " A random input's prediction averages the first {} runs' input draws.",
                jitterid_study::experiment::MAX_DRAWS
            )
        } else {
            String::new()
        }
    );
    let mut cases = Vec::new();
    for (case, file, edits, what) in CASES.into_iter().filter(|c| wanted(c.0)) {
        for &estimator in estimators {
            let c = study(case, file, edits, estimator, runs, o.seed)?;
            let _ = write!(
                md,
                "\n### `{case}`, {estimator}: {what}\n\n`examples/experiments/{file}`{}: optimal {}; jitter-blind {}; the file's {}.\n\n",
                if edits.is_empty() { String::new() } else { format!(" with `--set '{}'`", edits.join("' --set '")) },
                dwell(&c.design_optimal),
                dwell(&c.design_jitter_blind),
                dwell(&c.design_baseline)
            );
            md += &table(&c);
            eprintln!("{case} {estimator}: {:.1} s", c.seconds);
            cases.push(c);
        }
    }
    let value = serde_json::to_value(&cases).map_err(|e| e.to_string())?;
    write_outputs(name, o, &value, &md)
}
