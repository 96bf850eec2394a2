//! Monte Carlo studies of an experiment: realisation `r` of master seed `s` is simulated and
//! fitted from its own random stream, so a study is bit-identical across thread counts and
//! shards (`--shard i/n` runs `[runs·i/n, runs·(i+1)/n)`), and shards carry every
//! realisation's estimates so that [`merge`](crate::merge) can combine them.

use crate::error::{StudyError, StudyResult};
use crate::experiment::{Experiment, Method};
use crate::fingerprint::experiment_fingerprint;
use crate::fit::{self, Fit, Structure};
use crate::simulate::{realize_inputs, seen_inputs, simulate_record};
use crate::study_err;
use crate::{RunsDone, Watch};
use jitterid::budget::Budget;
use jitterid::estimate::montecarlo::{realization_rng, realization_seed, run as mc_run, Summary};
use jitterid::signal::AnySignal;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Largest number of Monte Carlo realisations: the library's limit
/// ([`jitterid::limits::MAX_RUNS`]).
pub const MAX_RUNS: u64 = jitterid::limits::MAX_RUNS;

/// The default master seed (that of `cargo xtask reproduce`).
pub const DEFAULT_SEED: u64 = 20_051_205;

/// A shard `i/n` of the runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Index, `0 ≤ index < count`.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
}

impl Shard {
    /// The whole study, one shard.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// The runs `[first, end)` of this shard of a study of `runs` runs:
    /// `[runs·i/n, runs·(i+1)/n)`.
    pub fn runs(&self, runs: u64) -> (u64, u64) {
        (
            runs * self.index / self.count,
            runs * (self.index + 1) / self.count,
        )
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        s.split_once('/')
            .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)))
            .filter(|&(i, n): &(u64, u64)| n > 0 && i < n)
            .map(|(index, count)| Shard { index, count })
            .ok_or_else(|| format!("expected i/n with 0 <= i < n, found `{s}`"))
    }
}

/// One parameter's Monte Carlo summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamSummary {
    /// Name.
    pub name: String,
    /// True value (null where unknown).
    #[serde(rename = "true")]
    pub truth: Option<f64>,
    /// Mean over converged runs.
    pub mean: Option<f64>,
    /// Sample standard deviation.
    pub std: Option<f64>,
    /// Standard error of the mean.
    pub se: Option<f64>,
    /// Root mean square error against the truth.
    pub rmse: Option<f64>,
}

/// One realisation, as kept in shard files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Realization {
    /// Index.
    pub run: u64,
    /// Whether the fit converged.
    pub converged: bool,
    /// Why the fit stopped (or `failed: …` with the error when there was no fit).
    #[serde(default)]
    pub termination: String,
    /// Reported estimates (null where not finite).
    pub values: Vec<Option<f64>>,
}

/// Which part of a study a file covers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardInfo {
    /// Shard index.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
    /// Runs of the whole study.
    pub runs_total: u64,
    /// First run of the shard.
    pub first: u64,
    /// One past the last run.
    pub end: u64,
}

/// The JSON of `montecarlo --json` (and of `merge`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct McJson {
    /// Method.
    pub method: String,
    /// Runs in this file.
    pub runs: u64,
    /// Runs that converged.
    pub converged: u64,
    /// How many runs ended for each reason (the solver's termination, or `failed: …`).
    #[serde(default)]
    pub terminations: BTreeMap<String, u64>,
    /// Wall time in seconds (summed over shards after a merge); the one field that differs
    /// between two runs of the same study. `None` (the key left out) where the command line was
    /// given `--no-timing`, so that identical studies' files are equal byte for byte, or after
    /// merging a shard without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seconds: Option<f64>,
    /// Master seed.
    pub seed: u64,
    /// Experiment file, as given (for people; the fingerprint identifies it).
    pub experiment: String,
    /// The experiment's fingerprint by content.
    #[serde(default)]
    pub fingerprint: String,
    /// The program and version that wrote the file.
    #[serde(default)]
    pub program: String,
    /// Per parameter.
    pub parameters: Vec<ParamSummary>,
    /// Present in shard files: which runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<ShardInfo>,
    /// Present in shard files: every realisation's estimates, for `jitterid merge`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub realizations: Option<Vec<Realization>>,
}

/// The program and version written into every result (`jitterid 0.1.0`).
pub fn program() -> String {
    format!("jitterid {}", env!("CARGO_PKG_VERSION"))
}

/// How many runs ended for each reason.
pub fn terminations(runs: &[Realization]) -> BTreeMap<String, u64> {
    let mut h = BTreeMap::new();
    for r in runs {
        *h.entry(r.termination.clone()).or_insert(0) += 1;
    }
    h
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// Summaries over the converged realisations, in run order.
pub fn summarize(
    names: &[String],
    truth: &[Option<f64>],
    runs: &[Realization],
) -> Vec<ParamSummary> {
    names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let vals: Vec<f64> = runs
                .iter()
                .filter(|r| r.converged)
                .map(|r| r.values.get(i).copied().flatten().unwrap_or(f64::NAN))
                .collect();
            let s: Summary = vals.iter().copied().collect();
            let t = truth.get(i).copied().flatten();
            let rmse = t.and_then(|t| {
                (!vals.is_empty()).then(|| {
                    (vals.iter().map(|x| (x - t).powi(2)).sum::<f64>() / vals.len() as f64).sqrt()
                })
            });
            ParamSummary {
                name: name.clone(),
                truth: t,
                mean: finite(s.mean).filter(|_| s.count > 0),
                std: finite(s.std()),
                se: finite(s.se()),
                rmse: rmse.and_then(finite),
            }
        })
        .collect()
}

/// One realisation's outcome.
#[derive(Debug, Clone)]
pub struct RunOut {
    /// What a shard file keeps of it.
    pub realization: Realization,
    /// The standard error the fit reported for each estimate (`None` where undefined).
    pub stderr: Vec<Option<f64>>,
    /// The fitted model, when kept ([`Keep::fitted`]).
    pub fitted: Option<Structure>,
}

/// Realisations whose fitted models are kept for the figures.
pub const KEEP_FITTED: u64 = 32;

/// What a study keeps of each fit besides its estimates.
#[derive(Debug, Clone, Copy, Default)]
pub struct Keep {
    /// The fitted models of the first [`KEEP_FITTED`] runs (for the figures).
    pub fitted: bool,
    /// Every fit's standard errors (the covariance is computed for every fit).
    pub stderr: bool,
}

fn one_run(
    exp: &Experiment,
    method: Method,
    seed: u64,
    n: usize,
    r: u64,
    rng: &mut jitterid::rand::rngs::StdRng,
    keep: Keep,
) -> RunOut {
    let mut go = || -> Result<Fit, String> {
        let text = |e: StudyError| e.to_string();
        let truth = realize_inputs(exp, rng).map_err(text)?;
        let signal = fit::signal_of(exp, &truth).map_err(text)?;
        // Only the samples are fitted: the drawn jitter and noise go at once, and so does the
        // true signal, so that a long record's fit holds no copy of what made it.
        let y = simulate_record(exp, &signal, rng).map_err(text)?.y;
        drop(signal);
        // The model sees the input from t0 on only, as a fit of measured data would.
        let seen = seen_inputs(exp, &truth).map_err(text)?;
        drop(truth);
        let model = fit::signal_of(exp, &seen).map_err(text)?;
        drop(seen);
        let s = fit::structure(exp, model, method).map_err(text)?;
        let start = fit::perturb(&s.params(), exp.estimate.perturb, rng);
        let s0 = s.with_params(&start).map_err(|e| e.to_string())?;
        drop(s);
        let record = fit::record(&exp.grid, y).map_err(|e| e.to_string())?;
        fit::fit(
            exp,
            &s0,
            &record,
            method,
            realization_seed(seed, r) ^ 0x6d73,
            exp.noise.estimate || keep.stderr,
            &Watch::none(),
        )
    };
    match go() {
        Ok(f) => RunOut {
            stderr: f.params.iter().map(|p| p.stderr.and_then(finite)).collect(),
            realization: Realization {
                run: r,
                converged: f.converged,
                termination: f.termination.clone(),
                values: f.params.iter().map(|p| finite(p.estimate)).collect(),
            },
            fitted: keep.fitted.then_some(f.fitted),
        },
        Err(e) => RunOut {
            stderr: vec![None; n],
            realization: Realization {
                run: r,
                converged: false,
                termination: format!("failed: {e}"),
                values: vec![None; n],
            },
            fitted: None,
        },
    }
}

/// A finished study: its JSON and what the figures need.
#[derive(Debug, Clone)]
pub struct StudyRun {
    /// The summary (`montecarlo --json`).
    pub json: McJson,
    /// Every realisation of the study (or of its shard), in run order.
    pub outs: Vec<RunOut>,
    /// Names of the reported parameters, in order.
    pub names: Vec<String>,
    /// Their true values (`None` where a parameter has no single truth).
    pub truth: Vec<Option<f64>>,
    /// The true signal of realisation 0, driven by its input as a fit sees it.
    pub signal0: AnySignal,
}

/// Runs `runs` realisations (or shard `shard` of them) of the experiment with its method on
/// `threads` worker threads (rayon's default if `None`), keeping the fitted models of the first
/// runs when `keep.fitted`, and every fit's standard errors when `keep.stderr`; `watch.runs` is
/// called as each realisation finishes, and a set `watch.cancel` stops the study before its
/// next realisations (an error: an interrupted study has no result).
pub fn run_study(
    exp: &Experiment,
    runs: u64,
    seed: u64,
    shard: Option<Shard>,
    threads: Option<usize>,
    keep: Keep,
    watch: &Watch,
) -> StudyResult<StudyRun> {
    let method = exp.estimate.method;
    if runs == 0 || runs > MAX_RUNS {
        return Err(study_err!(
            "--runs: expected a number of realisations in [1, {MAX_RUNS}], found {runs}"
        ));
    }
    // The names and truths, from realisation 0's setup (they do not depend on the input).
    let mut rng0 = realization_rng(seed, 0);
    // Only the signal is kept (for the figures): the inputs it was built from go at once, not
    // at the end of the study.
    let signal0 = {
        let truth0 = realize_inputs(exp, &mut rng0)?;
        let input0 = seen_inputs(exp, &truth0)?;
        fit::signal_of(exp, &input0)?
    };
    let names = fit::param_names(exp, &signal0, method)?;
    let truth = fit::truth_values(exp, &signal0, method)?;
    let part = shard.unwrap_or(Shard::WHOLE);
    let (first, end) = part.runs(runs);
    let n = names.len();
    let pool = {
        let mut b = rayon::ThreadPoolBuilder::new();
        if let Some(k) = threads {
            if !(1..=1024).contains(&k) {
                return Err(study_err!(
                    "--threads: expected 1 to 1024 threads, found {k}"
                ));
            }
            b = b.num_threads(k);
        }
        b.build()
            .map_err(|e| study_err!("--threads: cannot start the worker threads: {e}"))?
    };
    let t0 = Instant::now();
    let finished = AtomicU64::new(0);
    let outs: Vec<Option<RunOut>> = pool.install(|| {
        mc_run(seed, first..end, |r, rng| {
            // Asked to stop: the realisations not yet started are skipped.
            if watch.cancelled() {
                return None;
            }
            // The realisation under the front end's cancel flag (its simulation stops on it);
            // its fit runs under the fit's own time limit, so that a spent limit is the fit's
            // reported reason, not a failed realisation.
            let budget = Budget::new(None, watch.cancel.clone());
            let out = budget.run(|| {
                one_run(
                    exp,
                    method,
                    seed,
                    n,
                    r,
                    rng,
                    Keep {
                        fitted: keep.fitted && r < first + KEEP_FITTED,
                        stderr: keep.stderr,
                    },
                )
            });
            let done = finished.fetch_add(1, Ordering::Relaxed) + 1;
            watch.run_done(RunsDone {
                done,
                total: end - first,
            });
            Some(out)
        })
    });
    // A cancel during the last realisations stops their fits (reported as stopped) without
    // skipping any: the study is interrupted all the same.
    let outs = outs
        .into_iter()
        .collect::<Option<Vec<RunOut>>>()
        .filter(|_| !watch.cancelled());
    let Some(outs) = outs else {
        return Err(study_err!(
            "interrupted: the study was stopped after {} of {} realisations",
            finished.load(Ordering::Relaxed),
            end - first
        ));
    };
    let seconds = t0.elapsed().as_secs_f64();
    let realizations: Vec<Realization> = outs.iter().map(|o| o.realization.clone()).collect();
    let parameters = summarize(&names, &truth, &realizations);
    let converged = realizations.iter().filter(|r| r.converged).count() as u64;
    let sharded = shard.is_some_and(|s| s.count > 1);
    let json = McJson {
        method: method.as_str().to_string(),
        runs: end - first,
        converged,
        terminations: terminations(&realizations),
        seconds: Some(seconds),
        seed,
        experiment: exp.file.clone(),
        fingerprint: experiment_fingerprint(exp),
        program: program(),
        parameters,
        shard: sharded.then_some(ShardInfo {
            index: part.index,
            count: part.count,
            runs_total: runs,
            first,
            end,
        }),
        realizations: sharded.then_some(realizations),
    };
    Ok(StudyRun {
        json,
        outs,
        names,
        truth,
        signal0,
    })
}

/// Every realisation of a study, with the reported parameters' names and true values.
#[derive(Debug, Clone)]
pub struct Realizations {
    /// Names of the reported parameters, in order.
    pub names: Vec<String>,
    /// Their true values (`None` where a parameter has no single truth, such as the free
    /// response's coefficients after an input with a history).
    pub truth: Vec<Option<f64>>,
    /// Every run, in run order.
    pub runs: Vec<Realization>,
    /// The standard errors each run's fit reported (`None` where undefined or for a failed
    /// run), in the order of `runs` and `names`.
    pub stderr: Vec<Vec<Option<f64>>>,
}

/// Every realisation of a study of `runs` runs: the estimates of runs that
/// [`montecarlo_values`] leaves out of its summary too, such as fits whose residual spectrum
/// is not flat, for studies of a model's bias.
pub fn montecarlo_realizations(
    exp: &Experiment,
    runs: u64,
    seed: u64,
    threads: Option<usize>,
) -> StudyResult<Realizations> {
    let keep = Keep {
        fitted: false,
        stderr: true,
    };
    let s = run_study(exp, runs, seed, None, threads, keep, &Watch::none())?;
    let (runs, stderr) = s
        .outs
        .into_iter()
        .map(|o| (o.realization, o.stderr))
        .unzip();
    Ok(Realizations {
        names: s.names,
        truth: s.truth,
        runs,
        stderr,
    })
}

/// The result of `jitterid montecarlo --json` (with `--shard` when `shard` is given) for an
/// experiment already read, as values.
pub fn montecarlo_values(
    exp: &Experiment,
    runs: u64,
    seed: u64,
    shard: Option<Shard>,
    threads: Option<usize>,
) -> StudyResult<McJson> {
    run_study(
        exp,
        runs,
        seed,
        shard,
        threads,
        Keep::default(),
        &Watch::none(),
    )
    .map(|s| s.json)
}
