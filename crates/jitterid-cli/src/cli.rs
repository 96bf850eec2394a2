//! Command-line arguments (clap) and dispatch.

// The doc comments here are clap's help texts, written for a terminal (`<stem>`,
// `[estimate]`), not rustdoc markup.
#![allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]

use crate::commands::{self, FitRequest, MonteCarloOptions, SimulateOptions};
use crate::exit::{Outcome, BAD_INPUT};
use clap::{Args, Parser, Subcommand};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{Method, Override, Paths, ReadOptions};
use jitterid_study::montecarlo::{Shard, DEFAULT_SEED};
use jitterid_study::select::InitChoice;
use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// System identification from jittered samples: simulate, fit and Monte Carlo studies of
/// experiments described in TOML files (see docs/experiments.md).
#[derive(Debug, Parser)]
#[command(name = "jitterid", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate one record of an experiment (its values are the truth) and write it as CSV.
    Simulate(SimulateArgs),
    /// Fit an experiment's model to a data file (the experiment's values are the start).
    Fit(FitArgs),
    /// Run a Monte Carlo study: simulate and fit many seeded realisations.
    Montecarlo(MonteCarloArgs),
    /// Fit the [select] grid of model orders × jitter families and rank them (BIC).
    Select(SelectArgs),
    /// Merge the shard files of `montecarlo --shard i/n --json` into the unsharded result.
    Merge(MergeArgs),
    /// Validate a fitted model on its record (and a validation record): fit percent, residual
    /// whiteness and input cross-correlation, flatness, frequency response with bands.
    Validate(ValidateArgs),
    /// Design the experiment: the [design] variables (input dwell, sampling interval) that
    /// minimise the estimate's predicted covariance under jitter, beside the file's own design.
    Design(DesignArgs),
}

/// Arguments of `design`.
#[derive(Debug, Args)]
pub struct DesignArgs {
    /// The experiment file (TOML) with a [design] section.
    pub experiment: PathBuf,
    /// What the design minimises: d (log det of the covariance), a (its trace) or param:NAME
    /// (one parameter's variance) [default: [design] criterion, else d].
    #[arg(long, value_name = "CRITERION")]
    pub criterion: Option<String>,
    /// The record every design has: duration=SECONDS (N T held, N = round(duration / T)) or
    /// samples=N (N held), replacing the file's own N [default: [design] duration or samples,
    /// else the file's N].
    #[arg(long, value_name = "duration=SECONDS|samples=N")]
    pub budget: Option<String>,
    /// Write the designed experiment's input (a random binary input's realisation 0 of the
    /// [design] seed, columns t,u) to FILE.csv and the experiment file that reads it, with the
    /// designed sampling, to FILE.toml, ready for simulate and fit; for a designed multisine,
    /// the experiment with its tones to FILE.toml and its sample sequence at --dac-rate to
    /// FILE.csv.
    #[arg(long, value_name = "FILE.csv")]
    pub write_input: Option<PathBuf>,
    /// The derived quantities whose predicted standard deviations are reported, comma-separated:
    /// static_gain, pole_frequency (every pole's |p|/2π), poleK.frequency, gain@F (|G| at F Hz),
    /// jitter.sigma [default: [design] derived, else static_gain and an estimated jitter's σ].
    #[arg(long, value_name = "QUANTITY,...", value_delimiter = ',')]
    pub derived: Option<Vec<String>>,
    /// The DAC rate (Hz) of a designed multisine's sample sequence, which --write-input
    /// writes to FILE.csv (columns t,u, one record) [default: [design] dac_rate].
    #[arg(long, value_name = "HZ")]
    pub dac_rate: Option<f64>,
    /// Also design with the jitter ignored (γ ≡ 1, no jitter noise) and report that design's
    /// precision under the true, jittered prior beside the jitter-aware one.
    #[arg(long)]
    pub jitter_blind: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write the JSON to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub experiment_args: ExperimentArgs,
}

/// Arguments of `validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// The experiment file (TOML).
    pub experiment: PathBuf,
    /// The estimation record (CSV as for `fit`; a random-binary input from <stem>.input.csv).
    #[arg(long)]
    pub data: PathBuf,
    /// The estimation record's input realisation (CSV with columns t,u) for a random-binary
    /// experiment [default: <data stem>.input.csv].
    #[arg(long, value_name = "FILE")]
    pub input: Option<PathBuf>,
    /// Level of the residual tests' verdicts: a true model fails each test in this fraction of
    /// records; strictly between 0 and 1.
    #[arg(long, default_value_t = jitterid::estimate::validation::DEFAULT_LEVEL, allow_negative_numbers = true)]
    pub level: f64,
    /// A validation record of the same system (same T, its own length and input side file).
    #[arg(long, value_name = "FILE")]
    pub validation: Option<PathBuf>,
    /// The model to validate, as written by `jitterid fit --json` [default: fit it here].
    #[arg(long, value_name = "FIT.json")]
    pub model: Option<PathBuf>,
    /// Print JSON instead of the table (the --out file is JSON either way).
    #[arg(long)]
    pub json: bool,
    /// Write the frequency response with ±2σ bands as CSV to this file.
    #[arg(long, value_name = "FILE.csv")]
    pub bode: Option<PathBuf>,
    /// Write the JSON to this file (atomically, with --bode and --plot) instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Write SVG figures into this directory: time.svg, correlations.svg, bode.svg, step.svg.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub experiment_args: ExperimentArgs,
}

fn parse_method(s: &str) -> Result<Method, String> {
    Method::parse(s).ok_or_else(|| format!("expected {}, found `{s}`", Method::names()))
}

/// Arguments of `simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// The experiment file (TOML).
    pub experiment: PathBuf,
    /// Master seed; the record is realisation `--run` of a Monte Carlo study with this seed.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// Realisation index.
    #[arg(long, default_value_t = 0)]
    pub run: u64,
    /// The CSV file to write (columns k, t, y and u; a random-binary input also goes to
    /// <stem>.input.csv). Both appear together or neither does; a device or FIFO (/dev/null) is
    /// written through, a symbolic link is followed, a directory is refused.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the drawn jitter `tau` and measurement noise `v`.
    #[arg(long)]
    pub truth: bool,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub experiment_args: ExperimentArgs,
}

/// How the experiment file is read: shared by every subcommand that reads one.
#[derive(Debug, Args)]
pub struct ExperimentArgs {
    /// Let the experiment file name files outside its own directory (absolute paths, `..`,
    /// symbolic links leading out); by default such a path is refused before it is read.
    #[arg(long)]
    pub allow_paths_outside: bool,
    /// Override one key of the experiment file (repeatable): a dotted path and a TOML value,
    /// e.g. `--set jitter.family=gaussian --set jitter.sigma=0.1`, `--set system.den=[1,2,5]`,
    /// `--set jitter.terms.1.d=0.05`; checked as if written in the file.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl ExperimentArgs {
    /// How to read the experiment: for a record in `data`, whose `t` column gives the
    /// `[sampling]` keys the file leaves out.
    fn read_options(&self, data: Option<&Path>) -> StudyResult<ReadOptions> {
        Ok(ReadOptions {
            paths: if self.allow_paths_outside {
                Paths::Anywhere
            } else {
                Paths::Inside
            },
            overrides: self
                .set
                .iter()
                .map(|a| Override::parse(a))
                .collect::<StudyResult<_>>()?,
            data: data.map(Path::to_path_buf),
        })
    }
}

/// Exit-status and budget options shared by `fit` and `montecarlo`.
#[derive(Debug, Args)]
pub struct BudgetArgs {
    /// Iteration limit of every fit (overrides [estimate] max_iterations).
    #[arg(long, value_name = "N")]
    pub max_iterations: Option<u64>,
    /// Wall-clock budget of every fit in seconds [default: 600], covering its search and its
    /// covariance; a fit that spends it stops, not converged, with the reason.
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,
    /// Exit 0 even when the fit did not converge (montecarlo, merge: when no fit converged);
    /// by default that exits 1.
    #[arg(long)]
    pub accept_unconverged: bool,
}

/// Arguments of `fit`.
#[derive(Debug, Args)]
pub struct FitArgs {
    /// The experiment file (TOML); its values are the starting point.
    pub experiment: PathBuf,
    /// The data file (CSV with a column `y`; optional `k`, `t` are checked). Repeat it to fit
    /// several records of one system jointly (each with its own input side file, length and
    /// start; a first-moment method).
    #[arg(long, required = true)]
    pub data: Vec<PathBuf>,
    /// The input realisation (CSV with columns t,u) for a random-binary experiment
    /// [default: <data stem>.input.csv].
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Estimation method (overrides [estimate] method): ls, bcls, bj, ml, quasi-ml.
    #[arg(long, value_parser = parse_method)]
    pub method: Option<Method>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write SVG figures into this directory.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// The start: `experiment` (the experiment's values; a likelihood fit of an estimated
    /// system then starts at the BCLS estimate fitted from them), `auto` (the system from the
    /// data-driven initializer, as `select` starts each candidate) or `experiment-only` (the
    /// experiment's values as a likelihood fit's only start, checked against the BCLS route).
    #[arg(long, value_name = "START", default_value = "experiment", value_parser = InitChoice::parse)]
    pub init: InitChoice,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub budget: BudgetArgs,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub experiment_args: ExperimentArgs,
}

/// Arguments of `montecarlo`.
#[derive(Debug, Args)]
pub struct MonteCarloArgs {
    /// The experiment file (TOML); its values are the truth.
    pub experiment: PathBuf,
    /// Number of realisations.
    #[arg(long, default_value_t = 128)]
    pub runs: u64,
    /// Master seed (realisation r uses a generator derived from the seed and r).
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// Worker threads [default: one per core]; results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write SVG figures into this directory.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Run only shard i of n (runs R·i/n .. R·(i+1)/n); merge shard JSON files with `merge`.
    #[arg(long, value_name = "i/n")]
    pub shard: Option<Shard>,
    /// Estimation method (overrides [estimate] method): ls, bcls, bj, ml, quasi-ml.
    #[arg(long, value_parser = parse_method)]
    pub method: Option<Method>,
    /// Write the JSON to this file (atomically, together with the figures) instead of standard
    /// output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Leave the study's wall time out (the JSON's `seconds` key and the table's time), so that
    /// two runs of the same study give the same bytes.
    #[arg(long)]
    pub no_timing: bool,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub budget: BudgetArgs,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub experiment_args: ExperimentArgs,
}

/// Arguments of `select`.
#[derive(Debug, Args)]
pub struct SelectArgs {
    /// The experiment file (TOML) with a [select] section.
    pub experiment: PathBuf,
    /// The data file (CSV with a column `y`); a random-binary input is read from its side file.
    #[arg(long)]
    pub data: PathBuf,
    /// A validation record: each candidate's fit percent on it is reported beside the BIC.
    #[arg(long, value_name = "FILE")]
    pub validation: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write the JSON to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Wall-clock budget of the whole selection in seconds [default: 600]; a selection that
    /// spends it stops with the reason (status 1).
    #[arg(long, value_name = "SECONDS")]
    pub time_limit: Option<f64>,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub experiment_args: ExperimentArgs,
}

/// Arguments of `merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shard files.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write the JSON to this file (atomically) instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Exit 0 even when no fit of the study converged; by default that exits 1.
    #[arg(long)]
    pub accept_unconverged: bool,
    /// Leave the summed wall time out (the JSON's `seconds` key and the table's time).
    #[arg(long)]
    pub no_timing: bool,
}

fn dispatch(cli: Cli) -> StudyResult<Outcome> {
    match cli.command {
        Command::Simulate(a) => commands::simulate(&SimulateOptions {
            read: a.experiment_args.read_options(None)?,
            experiment: a.experiment,
            seed: a.seed,
            run: a.run,
            out: a.out,
            truth: a.truth,
        })
        .map(|s| Outcome::success(s + "\n")),
        Command::Fit(a) => commands::fit(&FitRequest {
            read: a
                .experiment_args
                .read_options(a.data.first().map(PathBuf::as_path))?,
            experiment: a.experiment,
            data: a.data,
            input: a.input,
            method: a.method,
            json: a.json,
            plot: a.plot,
            init: a.init,
            accept_unconverged: a.budget.accept_unconverged,
            max_iterations: a.budget.max_iterations,
            time_limit: a.budget.time_limit,
        }),
        Command::Montecarlo(a) => commands::montecarlo(&MonteCarloOptions {
            read: a.experiment_args.read_options(None)?,
            experiment: a.experiment,
            runs: a.runs,
            seed: a.seed,
            threads: a.threads,
            json: a.json,
            plot: a.plot,
            shard: a.shard,
            method: a.method,
            out: a.out,
            accept_unconverged: a.budget.accept_unconverged,
            max_iterations: a.budget.max_iterations,
            time_limit: a.budget.time_limit,
            timing: !a.no_timing,
        }),
        Command::Validate(a) => commands::validate(&commands::ValidateOptions {
            read: a.experiment_args.read_options(Some(&a.data))?,
            experiment: a.experiment,
            data: a.data,
            input: a.input,
            level: a.level,
            validation: a.validation,
            model: a.model,
            bode: a.bode,
            out: a.out,
            plot: a.plot,
            json: a.json,
        }),
        Command::Select(a) => commands::select(&commands::SelectOptions {
            read: a.experiment_args.read_options(Some(&a.data))?,
            experiment: a.experiment,
            data: a.data,
            validation: a.validation,
            json: a.json,
            out: a.out,
            time_limit: a.time_limit,
        }),
        Command::Design(a) => commands::design(&commands::DesignOptions {
            read: a.experiment_args.read_options(None)?,
            experiment: a.experiment,
            criterion: a.criterion,
            budget: a.budget,
            derived: a.derived,
            jitter_blind: a.jitter_blind,
            write_input: a.write_input,
            dac_rate: a.dac_rate,
            json: a.json,
            out: a.out,
        }),
        Command::Merge(a) => commands::merge(
            &a.shards,
            a.json,
            a.out.as_deref(),
            a.accept_unconverged,
            !a.no_timing,
        ),
    }
}

/// Runs the command line; returns the exit status: 0, 1 when a fit did not converge (see
/// [`Status`](crate::exit::Status)), or 2 after a one-line error on stderr.
pub fn run<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::from(BAD_INPUT)
                } else {
                    ExitCode::SUCCESS
                };
            }
            let text = e.render().to_string();
            // clap's message runs until the usage line; fold it into one line.
            let first = text
                .lines()
                .map(str::trim)
                .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
                .filter(|l| !l.is_empty())
                .collect::<Vec<_>>()
                .join(" ");
            let first = first.strip_prefix("error: ").unwrap_or(&first).to_string();
            eprintln!(
                "{}",
                commands::report(&jitterid_study::error::StudyError::new(format!(
                    "{first} (see jitterid --help)"
                )))
            );
            return ExitCode::from(BAD_INPUT);
        }
    };
    match dispatch(cli) {
        Ok(outcome) => {
            let mut out = std::io::stdout().lock();
            let _ = out.write_all(outcome.text.as_bytes());
            let _ = out.flush();
            outcome.status.code()
        }
        Err(e) => {
            eprintln!("{}", commands::report(&e));
            ExitCode::from(BAD_INPUT)
        }
    }
}
