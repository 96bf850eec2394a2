//! The subcommands: `simulate`, `fit`, `montecarlo`, `merge`.

use crate::cli_err;
use crate::csvio::{self, Column};
use crate::error::{CliError, CliResult};
use crate::exit::{Outcome, Status};
use crate::experiment::{self, Experiment, InputSpec, Method, Purpose};
use crate::export;
use crate::fingerprint::experiment_fingerprint;
use crate::fitting::{self, Fit, Structure};
use crate::inputs;
use crate::output::{self, OutputSet};
use crate::plots;
use crate::progress::{Progress, Ticker};
use jitterid::estimate::montecarlo::{realization_rng, realization_seed, run as mc_run, Summary};
use jitterid::signal::{AnySignal, Input};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Largest number of Monte Carlo realisations.
pub const MAX_RUNS: u64 = 10_000_000;

/// The default master seed (that of `cargo xtask reproduce`).
pub const DEFAULT_SEED: u64 = 20_051_205;

/// The side file holding the input of a simulated record: `data.csv` → `data.input.csv`.
pub fn input_side_file(data: &Path) -> PathBuf {
    jitterid::estimate::csv::input_side_file(data)
}

// ---------------------------------------------------------------------------------------------
// simulate

/// Options of `simulate`.
#[derive(Debug, Clone)]
pub struct SimulateOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// Master seed.
    pub seed: u64,
    /// Realisation index (the same record as Monte Carlo run `run`).
    pub run: u64,
    /// The data file to write.
    pub out: PathBuf,
    /// Whether to write the drawn jitter and noise.
    pub truth: bool,
}

/// One simulated record of an experiment, as values (what `jitterid simulate` writes).
#[derive(Debug, Clone)]
pub struct SimulatedData {
    /// Requested sampling times `t_k = t0 + kT`.
    pub t: Vec<f64>,
    /// Samples.
    pub y: Vec<f64>,
    /// The input at `t_k`, when the experiment has one.
    pub u: Option<Vec<f64>>,
    /// Jitter of each sample.
    pub tau: Vec<f64>,
    /// Measurement noise of each sample.
    pub v: Vec<f64>,
    /// The input realisation (a random binary input's switch times and levels among others).
    pub input: Option<Input>,
}

/// Realisation `run` of the experiment's truth under master seed `seed`: the record of Monte
/// Carlo run `run`.
pub fn simulate_data(exp: &Experiment, seed: u64, run: u64) -> CliResult<SimulatedData> {
    let mut rng = realization_rng(seed, run);
    let truth = fitting::realize_input(exp, &mut rng)?;
    let signal = fitting::signal_of(&exp.system.kind, truth.as_ref())?;
    let sim = fitting::simulate_record(exp, &signal, &mut rng)?;
    // What a measurement records, and what the side file holds: the input from t0 on.
    let input = fitting::seen_input(exp, truth.as_ref())?;
    if let Some(k) = sim.y.iter().position(|y| !y.is_finite()) {
        return Err(cli_err!(
            "{}: the simulated sample {k} is {} (not a finite number): the experiment's values are outside the range that can be simulated; nothing was written",
            exp.file,
            sim.y[k]
        ));
    }
    let t: Vec<f64> = exp.grid.times().collect();
    let u = input
        .as_ref()
        .map(|i| t.iter().map(|&t| i.value(t)).collect());
    Ok(SimulatedData {
        t,
        y: sim.y,
        u,
        tau: sim.tau,
        v: sim.v,
        input,
    })
}

/// `jitterid simulate`: one record of the experiment's truth. Returns the report line.
pub fn simulate(o: &SimulateOptions) -> CliResult<String> {
    let exp = experiment::read(&o.experiment, Purpose::Simulate)?;
    let SimulatedData {
        t,
        y,
        u,
        tau,
        v,
        input,
    } = simulate_data(&exp, o.seed, o.run)?;
    let n = exp.grid.len();
    let k: Vec<usize> = (0..n).collect();
    let mut cols = vec![
        Column::Index("k", &k),
        Column::Real("t", &t),
        Column::Real("y", &y),
    ];
    if let Some(u) = &u {
        cols.push(Column::Real("u", u));
    }
    if o.truth {
        cols.push(Column::Real("tau", &tau));
        cols.push(Column::Real("v", &v));
    }
    let mut outputs = OutputSet::new();
    outputs.file(&o.out, csvio::format(&cols));
    let mut report = format!(
        "wrote {}: {n} samples ({})",
        o.out.display(),
        cols.iter()
            .map(|c| match c {
                Column::Index(n, _) | Column::Real(n, _) => *n,
            })
            .collect::<Vec<_>>()
            .join(", ")
    );
    if let (InputSpec::RandomBinary(_), Some(Input::Piecewise(p))) = (&exp.input, &input) {
        if output::writes_through(&o.out) {
            report.push_str(
                "; the input realisation is not written (a device or FIFO has no side file)",
            );
        } else {
            let side = input_side_file(&o.out);
            let edges = p.edges();
            outputs.file(&side, jitterid::estimate::csv::input_to_csv(p));
            let _ = write!(
                report,
                "; {}: the input's {} switch times and levels",
                side.display(),
                edges.len()
            );
        }
    }
    outputs.commit()?;
    Ok(report)
}

// ---------------------------------------------------------------------------------------------
// fit

/// Options of `fit`.
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// The data file.
    pub data: PathBuf,
    /// The input file (for a random-binary experiment), default `<data>.input.csv`.
    pub input: Option<PathBuf>,
    /// Method override.
    pub method: Option<Method>,
    /// JSON output.
    pub json: bool,
    /// Plot directory.
    pub plot: Option<PathBuf>,
    /// The start: the experiment's values or the data-driven initializer's.
    pub init: crate::select::InitChoice,
    /// Exit 0 even when the fit did not converge.
    pub accept_unconverged: bool,
    /// Iteration limit (overrides `[estimate] max_iterations`).
    pub max_iterations: Option<u64>,
    /// Wall-clock budget of the fit in seconds.
    pub time_limit: Option<f64>,
}

/// The JSON of `jitterid fit --json`, borrowed from a [`Fit`].
#[derive(Debug, Serialize)]
pub struct FitJson<'a> {
    method: &'a str,
    converged: bool,
    cost: f64,
    iterations: u64,
    termination: &'a str,
    noise_std: f64,
    parameters: &'a [fitting::Param],
    /// Covariance of `parameters`, in their order (`null` where undefined).
    covariance: Option<&'a [Vec<Option<f64>>]>,
    /// The fitted system in zpk, tf and state-space form (rational systems only).
    #[serde(skip_serializing_if = "Option::is_none")]
    model: Option<export::ModelForms>,
}

/// The samples of a data file, checked against the experiment's grid.
pub fn read_data(exp: &Experiment, path: &Path) -> CliResult<csvio::Table> {
    let table = csvio::read(path)?;
    let y = table.column("y")?;
    let n = exp.grid.len();
    if y.len() != n {
        return Err(cli_err!(
            "{}: has {} data rows, expected {n} (the experiment's [sampling] samples)",
            table.name,
            y.len()
        ));
    }
    if let Some(k) = table.optional("k") {
        if let Some(i) = (0..n).find(|&i| k[i] != i as f64) {
            return Err(cli_err!(
                "{}:{}: column `k`: expected {i} (rows in order from 0), found {}",
                table.name,
                table.lines[i],
                k[i]
            ));
        }
    }
    if let Some(t) = table.optional("t") {
        let tol = 1e-6 * exp.grid.interval();
        if let Some(i) =
            (0..n).find(|&i| (t[i] - exp.grid.time(i)).abs() > tol + 1e-12 * t[i].abs())
        {
            return Err(cli_err!(
                "{}:{}: column `t`: expected {} (t0 + kT of the experiment's [sampling]), found {}",
                table.name,
                table.lines[i],
                exp.grid.time(i),
                t[i]
            ));
        }
    }
    Ok(table)
}

fn fmt_num(x: f64) -> String {
    if !x.is_finite() {
        return "–".into();
    }
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{x:.4e}")
    } else {
        format!("{x:.6}")
    }
}

/// The experiment of `path` with the command line's iteration and wall-clock budgets, where
/// given.
pub fn read_experiment(
    path: &Path,
    purpose: Purpose,
    max_iterations: Option<u64>,
    time_limit: Option<f64>,
) -> CliResult<Experiment> {
    let mut exp = experiment::read(path, purpose)?;
    if let Some(t) = time_limit {
        if !(t.is_finite() && t >= 0.0) {
            return Err(cli_err!(
                "--time-limit: expected a number of seconds >= 0, found {t}"
            ));
        }
        exp.estimate.max_seconds = Some(t);
    }
    if let Some(n) = max_iterations {
        if n == 0 {
            return Err(cli_err!(
                "--max-iterations: expected at least 1 iteration, found 0"
            ));
        }
        exp.estimate.max_iterations = Some(n);
    }
    Ok(exp)
}

/// Fits the experiment's model with its method to the samples `y` of a record whose input
/// `signal` holds; `data` names the record in messages.
pub fn fit_values(exp: &Experiment, signal: AnySignal, y: Vec<f64>, data: &str) -> CliResult<Fit> {
    let method = exp.estimate.method;
    let record = fitting::record(&exp.grid, y).map_err(|e| cli_err!("{data}: {e}"))?;
    let s = fitting::structure(exp, signal, method)?;
    fitting::fit(exp, &s, &record, method, 0, true).map_err(|e| {
        cli_err!(
            "{}: fit with method {} failed: {e}",
            exp.file,
            method.as_str()
        )
    })
}

/// The JSON of `jitterid fit --json`.
pub fn fit_json(f: &Fit) -> FitJson<'_> {
    FitJson {
        method: f.method.as_str(),
        converged: f.converged,
        cost: f.cost,
        iterations: f.iterations,
        termination: &f.termination,
        noise_std: f.noise_std,
        parameters: &f.params,
        covariance: f.covariance.as_deref(),
        model: export::model_forms(&f.fitted.signal),
    }
}

/// The input of the record in `data`: the experiment's known input, or for a random-binary
/// experiment the realisation in `input` (default: the side file of `data`).
pub fn read_input(exp: &Experiment, data: &Path, input: Option<&Path>) -> CliResult<Option<Input>> {
    Ok(match &exp.input {
        InputSpec::None => None,
        InputSpec::Known(i) => Some(i.clone()),
        InputSpec::RandomBinary(_) => {
            let side = input.map_or_else(|| input_side_file(data), Path::to_path_buf);
            if !side.exists() {
                return Err(cli_err!(
                    "{}: cannot read: file does not exist; the experiment's input is random-binary, so fit reads the input realisation written by `jitterid simulate` (or give --input FILE with columns t,u)",
                    side.display()
                ));
            }
            let t = csvio::read(&side)?;
            Some(Input::Piecewise(inputs::piecewise_from_table(
                &t, "t", "u", &exp.grid,
            )?))
        }
    })
}

/// `jitterid fit`: the text to print, and exit status [`Status::NotConverged`] when the fit did
/// not converge (unless `accept_unconverged`).
pub fn fit(o: &FitOptions) -> CliResult<Outcome> {
    let exp = read_experiment(
        &o.experiment,
        Purpose::Estimate(o.method),
        o.max_iterations,
        o.time_limit,
    )?;
    let method = exp.estimate.method;
    let table = read_data(&exp, &o.data)?;
    let y = table.column("y")?.to_vec();
    let input = read_input(&exp, &o.data, o.input.as_deref())?;
    let mut signal = fitting::signal_of(&exp.system.kind, input.as_ref())?;
    if o.init == crate::select::InitChoice::Auto {
        signal = crate::select::auto_start(&exp, &signal, input.as_ref(), &y, &table.name)?;
    }
    let ticker = Ticker::start(&format!("fitting with {}", method.as_str()));
    let f = fit_values(&exp, signal.clone(), y.clone(), &table.name)?;
    drop(ticker);

    let status = Status::of_convergence(f.converged, o.accept_unconverged);
    if let Some(dir) = &o.plot {
        write_fit_figures(dir, &exp, &f, &signal, input.as_ref(), &y, &table)?;
    }

    if o.json {
        return serde_json::to_string_pretty(&fit_json(&f))
            .map(|text| Outcome {
                text: text + "\n",
                status,
            })
            .map_err(|e| cli_err!("JSON: {e}"));
    }
    let out = fit_text(&exp, &f, &table.name, o.plot.as_deref());
    Ok(Outcome { text: out, status })
}

/// The figures of `fit --plot DIR`, written as one set (the naive LS fit beside the method's).
fn write_fit_figures(
    dir: &Path,
    exp: &Experiment,
    f: &Fit,
    signal: &AnySignal,
    input: Option<&Input>,
    y: &[f64],
    table: &csvio::Table,
) -> CliResult<()> {
    let method = exp.estimate.method;
    // The naive LS fit of the system for comparison (when the system is estimated).
    let ls = if exp.system.estimate && method != Method::LS {
        let record =
            fitting::record(&exp.grid, y.to_vec()).map_err(|e| cli_err!("{}: {e}", table.name))?;
        let mut ls_exp = exp.clone();
        ls_exp.jitter.estimate = false;
        ls_exp.noise.estimate = false;
        fitting::structure(&ls_exp, signal.clone(), Method::LS)
            .ok()
            .and_then(|ls_s| fitting::fit(&ls_exp, &ls_s, &record, Method::LS, 0, false).ok())
            .map(|f| f.fitted)
    } else if method == Method::LS {
        Some(f.fitted.clone())
    } else {
        None
    };
    let main_label = if method == Method::LS {
        "naive LS"
    } else {
        method.as_str()
    };
    let figs = plots::fit_figures(&plots::FitPlots {
        exp,
        y,
        input,
        file_model: signal,
        ls: if method == Method::LS {
            None
        } else {
            ls.as_ref()
        },
        main: (main_label, &f.fitted),
        tau: table.optional("tau"),
    })?;
    let mut outputs = OutputSet::new();
    outputs.dir(dir);
    for (name, svg) in figs {
        outputs.file(&dir.join(name), svg);
    }
    outputs.commit()?;
    Ok(())
}

/// The human-readable report of `fit`.
fn fit_text(exp: &Experiment, f: &Fit, name: &str, plot: Option<&Path>) -> String {
    let method = exp.estimate.method;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "fit of {} with {} ({})",
        name,
        method.as_str(),
        exp.file
    );
    let _ = writeln!(
        out,
        "{} ({}) after {} iterations, cost {:.6e}, noise std {} ({})",
        if f.converged {
            "converged"
        } else {
            "NOT converged"
        },
        f.termination,
        f.iterations,
        f.cost,
        fmt_num(f.noise_std),
        if exp.noise.estimate {
            "estimated"
        } else {
            "known"
        }
    );
    let w = f
        .params
        .iter()
        .map(|p| p.name.len())
        .max()
        .unwrap_or(9)
        .max(9);
    let _ = writeln!(
        out,
        "{:<w$}  {:>14}  {:>14}",
        "parameter", "estimate", "std error"
    );
    for p in &f.params {
        let _ = writeln!(
            out,
            "{:<w$}  {:>14}  {:>14}",
            p.name,
            fmt_num(p.estimate),
            p.stderr.map_or("–".into(), fmt_num)
        );
    }
    // The exported model of a delayed system is two pieces: say how they combine.
    if let (Some(d), Some(_)) = (
        export::delay_of(&f.fitted.signal),
        export::tf_of(&f.fitted.signal),
    ) {
        let _ = writeln!(
            out,
            "model: G(s) e^(-sD) with input delay D = {} s (the parameter delay; --json: model.zpk, model.tf, model.ss give G, model.delay gives D)",
            fmt_num(d)
        );
    }
    if let Some(dir) = plot {
        let _ = writeln!(
            out,
            "figures in {}: bode.svg (rational systems), spectrum.svg, moment.svg, jitter-pdf.svg",
            dir.display()
        );
    }
    out
}

// ---------------------------------------------------------------------------------------------
// montecarlo

/// A shard `i/n` of the runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Index, `0 ≤ index < count`.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
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

/// Options of `montecarlo`.
#[derive(Debug, Clone)]
pub struct MonteCarloOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// Total number of realisations.
    pub runs: u64,
    /// Master seed.
    pub seed: u64,
    /// Worker threads (rayon's default if `None`).
    pub threads: Option<usize>,
    /// JSON output.
    pub json: bool,
    /// Plot directory.
    pub plot: Option<PathBuf>,
    /// Which shard of the runs.
    pub shard: Option<Shard>,
    /// Method override.
    pub method: Option<Method>,
    /// Write the JSON to this file (atomically) instead of stdout.
    pub out: Option<PathBuf>,
    /// Exit 0 even when no fit converged.
    pub accept_unconverged: bool,
    /// Iteration limit of every fit (overrides `[estimate] max_iterations`).
    pub max_iterations: Option<u64>,
    /// Wall-clock budget of every fit in seconds.
    pub time_limit: Option<f64>,
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
    /// Wall time in seconds (summed over shards after a merge).
    pub seconds: f64,
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

struct RunOut {
    realization: Realization,
    /// The standard error the fit reported for each estimate (`None` where undefined).
    stderr: Vec<Option<f64>>,
    fitted: Option<Structure>,
}

/// Realisations whose fitted models are kept for the figures.
const KEEP_FITTED: u64 = 32;

/// What a study keeps of each fit besides its estimates.
#[derive(Debug, Clone, Copy, Default)]
struct Keep {
    /// The fitted models of the first [`KEEP_FITTED`] runs (for the figures).
    fitted: bool,
    /// Every fit's standard errors (the covariance is computed for every fit).
    stderr: bool,
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
        let text = |e: CliError| e.to_string();
        let truth = fitting::realize_input(exp, rng).map_err(text)?;
        let signal = fitting::signal_of(&exp.system.kind, truth.as_ref()).map_err(text)?;
        let sim = fitting::simulate_record(exp, &signal, rng).map_err(text)?;
        // The model sees the input from t0 on only, as a fit of measured data would.
        let seen = fitting::seen_input(exp, truth.as_ref()).map_err(text)?;
        let model = fitting::signal_of(&exp.system.kind, seen.as_ref()).map_err(text)?;
        let s = fitting::structure(exp, model, method).map_err(text)?;
        let start = fitting::perturb(&s.params(), exp.estimate.perturb, rng);
        let s0 = s.with_params(&start).map_err(|e| e.to_string())?;
        let record = fitting::record(&exp.grid, sim.y).map_err(|e| e.to_string())?;
        fitting::fit(
            exp,
            &s0,
            &record,
            method,
            realization_seed(seed, r) ^ 0x6d73,
            exp.noise.estimate || keep.stderr,
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

fn mc_table(j: &McJson) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Monte Carlo of {} with {}: {} runs (seed {}), {} converged, {:.2} s",
        j.experiment, j.method, j.runs, j.seed, j.converged, j.seconds
    );
    let reasons: Vec<String> = j
        .terminations
        .iter()
        .map(|(reason, count)| format!("{count} × {reason}"))
        .collect();
    let _ = writeln!(out, "terminations: {}", reasons.join("; "));
    if let Some(s) = &j.shard {
        let _ = writeln!(
            out,
            "shard {}/{}: runs {}..{} of {}",
            s.index, s.count, s.first, s.end, s.runs_total
        );
    }
    let w = j
        .parameters
        .iter()
        .map(|p| p.name.len())
        .max()
        .unwrap_or(9)
        .max(9);
    let _ = writeln!(
        out,
        "{:<w$}  {:>12}  {:>12}  {:>12}  {:>12}  {:>12}",
        "parameter", "true", "mean", "std", "se", "rmse"
    );
    let f = |x: Option<f64>| x.map_or("–".into(), fmt_num);
    for p in &j.parameters {
        let _ = writeln!(
            out,
            "{:<w$}  {:>12}  {:>12}  {:>12}  {:>12}  {:>12}",
            p.name,
            f(p.truth),
            f(p.mean),
            f(p.std),
            f(p.se),
            f(p.rmse)
        );
    }
    out
}

/// A finished study: its JSON and what the figures need.
struct StudyRun {
    json: McJson,
    outs: Vec<RunOut>,
    names: Vec<String>,
    truth: Vec<Option<f64>>,
    signal0: AnySignal,
}

/// Runs `runs` realisations (or shard `shard` of them) of the experiment with its method on
/// `threads` worker threads (rayon's default if `None`), keeping the fitted models of the first
/// runs when `keep.fitted`, and every fit's standard errors when `keep.stderr`.
fn run_study(
    exp: &Experiment,
    runs: u64,
    seed: u64,
    shard: Option<Shard>,
    threads: Option<usize>,
    keep: Keep,
) -> CliResult<StudyRun> {
    let method = exp.estimate.method;
    if runs == 0 || runs > MAX_RUNS {
        return Err(cli_err!(
            "--runs: expected a number of realisations in [1, {MAX_RUNS}], found {runs}"
        ));
    }
    // The names and truths, from realisation 0's setup (they do not depend on the input).
    let mut rng0 = realization_rng(seed, 0);
    let truth0 = fitting::realize_input(exp, &mut rng0)?;
    let input0 = fitting::seen_input(exp, truth0.as_ref())?;
    let signal0 = fitting::signal_of(&exp.system.kind, input0.as_ref())?;
    let names = fitting::param_names(exp, &signal0, method)?;
    let truth = fitting::truth_values(exp, &signal0, method)?;
    let part = shard.unwrap_or(Shard { index: 0, count: 1 });
    let first = runs * part.index / part.count;
    let end = runs * (part.index + 1) / part.count;
    let n = names.len();
    let pool = {
        let mut b = rayon::ThreadPoolBuilder::new();
        if let Some(k) = threads {
            if !(1..=1024).contains(&k) {
                return Err(cli_err!("--threads: expected 1 to 1024 threads, found {k}"));
            }
            b = b.num_threads(k);
        }
        b.build()
            .map_err(|e| cli_err!("--threads: cannot start the worker threads: {e}"))?
    };
    let progress = Progress::new(end - first);
    let t0 = Instant::now();
    let outs: Vec<RunOut> = pool.install(|| {
        mc_run(seed, first..end, |r, rng| {
            let out = one_run(
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
            );
            progress.tick();
            out
        })
    });
    progress.finish();
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
        seconds,
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
) -> CliResult<Realizations> {
    let keep = Keep {
        fitted: false,
        stderr: true,
    };
    let s = run_study(exp, runs, seed, None, threads, keep)?;
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
) -> CliResult<McJson> {
    run_study(exp, runs, seed, shard, threads, Keep::default()).map(|s| s.json)
}

/// `jitterid montecarlo`: the text to print (empty if the JSON is written to `--out`), and exit
/// status [`Status::NotConverged`] when no fit converged (unless `accept_unconverged`).
pub fn montecarlo(o: &MonteCarloOptions) -> CliResult<Outcome> {
    let exp = read_experiment(
        &o.experiment,
        Purpose::Estimate(o.method),
        o.max_iterations,
        o.time_limit,
    )?;
    let keep = Keep {
        fitted: o.plot.is_some(),
        stderr: false,
    };
    let study = run_study(&exp, o.runs, o.seed, o.shard, o.threads, keep)?;
    let j = &study.json;
    let mut outputs = OutputSet::new();
    if let Some(dir) = &o.plot {
        let conv: Vec<Vec<f64>> = study
            .outs
            .iter()
            .map(|o| &o.realization)
            .filter(|r| r.converged)
            .map(|r| r.values.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
            .collect();
        let fitted: Vec<&Structure> = study
            .outs
            .iter()
            .filter(|o| o.realization.converged)
            .filter_map(|o| o.fitted.as_ref())
            .collect();
        let figs = plots::montecarlo_figures(&plots::McPlots {
            exp: &exp,
            method: &j.method,
            names: &study.names,
            truth: &study.truth,
            values: conv.iter().map(Vec::as_slice).collect(),
            true_signal: &study.signal0,
            fitted,
        });
        outputs.dir(dir);
        for (name, svg) in figs {
            outputs.file(&dir.join(name), svg);
        }
    }
    let text = emit(j, o.json, o.out.as_deref(), outputs)?;
    Ok(Outcome {
        text,
        status: Status::of_convergence(j.converged > 0, o.accept_unconverged),
    })
}

/// Writes the JSON to `out` together with the other `outputs`; returns what to print.
pub fn emit(
    j: &McJson,
    json: bool,
    out: Option<&Path>,
    mut outputs: OutputSet,
) -> CliResult<String> {
    let text = serde_json::to_string_pretty(j).map_err(|e| cli_err!("JSON: {e}"))? + "\n";
    let printed = match out {
        Some(path) => {
            outputs.file(path, text);
            if json {
                String::new()
            } else {
                mc_table(j)
            }
        }
        None if json => text,
        None => mc_table(j),
    };
    outputs.commit()?;
    Ok(printed)
}

/// Converts a [`CliError`] from a command into the reported line.
pub fn report(e: &CliError) -> String {
    format!("error: {e}")
}
