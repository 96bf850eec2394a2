//! `jitterid validate`: fit percent, residual whiteness and input cross-correlation, flatness,
//! and the frequency-response CSV of a fitted model (given as `fit --json` or fitted here).

use crate::cli_err;
use crate::commands::{self, input_side_file, read_data};
use crate::csvio;
use crate::error::CliResult;
use crate::exit::Outcome;
use crate::experiment::{self, Experiment, InputSpec, Purpose};
use crate::export;
use crate::fitting::{self, Structure};
use crate::inputs;
use crate::output::OutputSet;
use jitterid::estimate::residual_flatness;
use jitterid::estimate::validation::{self, CorrelationTest};
use jitterid::signal::{Input, SampleGrid};
use jitterid::window::{transform, DirichletWindow, FrequencySet};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Fewest samples of a validation record (enough for lags up to `N/4`).
pub const MIN_VALIDATION_SAMPLES: usize = 16;

/// Options of `validate`.
#[derive(Debug, Clone)]
pub struct ValidateOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// The estimation record.
    pub data: PathBuf,
    /// A validation record (same `T`, its own input side file).
    pub validation: Option<PathBuf>,
    /// A `fit --json` output to validate instead of fitting.
    pub model: Option<PathBuf>,
    /// Write the frequency-response CSV here.
    pub bode: Option<PathBuf>,
    /// Write the JSON here instead of standard output.
    pub out: Option<PathBuf>,
}

/// The checks of one record.
#[derive(Debug, Serialize)]
pub struct RecordReport {
    /// The record's file.
    pub record: String,
    /// Samples.
    pub samples: usize,
    /// Normalised fit of the expected samples, in percent.
    pub fit_percent: f64,
    /// Autocorrelation of the standardised residuals.
    pub whiteness: CorrelationTest,
    /// Cross-correlation of the standardised residuals with the input (`null` without input).
    pub cross_correlation: Option<CorrelationTest>,
    /// Largest band power of the residual spectrum over the others (`null`: too few bins).
    pub flatness: Option<f64>,
}

/// The JSON of `validate`.
#[derive(Debug, Serialize)]
struct ValidateJson {
    fit_percent: FitPercent,
    whiteness: CorrelationTest,
    cross_correlation: Option<CorrelationTest>,
    flatness: Option<f64>,
    estimation: RecordReport,
    validation: Option<RecordReport>,
}

#[derive(Debug, Serialize)]
struct FitPercent {
    estimation: f64,
    validation: Option<f64>,
}

/// The parts of `fit --json` that `validate --model` reads.
#[derive(Debug, serde::Deserialize)]
struct FitFile {
    noise_std: f64,
    parameters: Vec<FitParam>,
    #[serde(default)]
    covariance: Option<Vec<Vec<Option<f64>>>>,
}

#[derive(Debug, serde::Deserialize)]
struct FitParam {
    name: String,
    estimate: f64,
}

/// The input of a record: the experiment's, or a random-binary realisation's side file.
fn record_input(exp: &Experiment, data: &Path, grid: &SampleGrid) -> CliResult<Option<Input>> {
    Ok(match &exp.input {
        InputSpec::None => None,
        InputSpec::Known(i) => Some(i.clone()),
        InputSpec::RandomBinary(_) => {
            let side = input_side_file(data);
            let t = csvio::read(&side)?;
            Some(Input::Piecewise(inputs::piecewise_from_table(
                &t, "t", "u", grid,
            )?))
        }
    })
}

/// The fitted structure, its noise level and the covariance of its signal parameters.
type Model = (Structure, f64, Option<Vec<Vec<f64>>>);

fn model_from_file(exp: &Experiment, s: Structure, path: &Path) -> CliResult<Model> {
    let name = path.display();
    csvio::check_regular_file(path, &name.to_string())?;
    let text = std::fs::read_to_string(path).map_err(|e| cli_err!("{name}: cannot read: {e}"))?;
    let f: FitFile = serde_json::from_str(&text)
        .map_err(|e| cli_err!("{name}: not the JSON of `jitterid fit --json`: {e}"))?;
    if exp.jitter.estimate && exp.jitter.n_range.is_some() {
        return Err(cli_err!(
            "{name}: --model: a profiled jitter (`[jitter] n_range`) is not supported; validate without --model"
        ));
    }
    let want = fitting::param_names(exp, &s.signal, exp.estimate.method)?;
    let got: Vec<&str> = f.parameters.iter().map(|p| p.name.as_str()).collect();
    if want != got {
        return Err(cli_err!(
            "{name}: parameters [{}] do not match the experiment's [{}] ({} with method {})",
            got.join(", "),
            want.join(", "),
            exp.file,
            exp.estimate.method.as_str()
        ));
    }
    if let Some(p) = f.parameters.iter().find(|p| !p.estimate.is_finite()) {
        return Err(cli_err!(
            "{name}: parameter {}: not a finite estimate",
            p.name
        ));
    }
    let theta: Vec<f64> = f.parameters[..s.num_params()]
        .iter()
        .map(|p| p.estimate)
        .collect();
    let ns = s.blocks().0;
    let fitted = s
        .with_params(&theta)
        .and_then(|s| s.with_noise_std(f.noise_std))
        .map_err(|e| cli_err!("{name}: the model's parameters: {e}"))?;
    Ok((
        fitted,
        f.noise_std,
        signal_block(f.covariance.as_deref(), ns),
    ))
}

/// The signal block (the first `ns` rows and columns) of a reported covariance.
fn signal_block(c: Option<&[Vec<Option<f64>>]>, ns: usize) -> Option<Vec<Vec<f64>>> {
    let c = c?;
    (c.len() >= ns)
        .then(|| {
            c[..ns]
                .iter()
                .map(|row| row.get(..ns)?.iter().copied().collect::<Option<Vec<f64>>>())
                .collect::<Option<Vec<_>>>()
        })
        .flatten()
}

/// The validation checks of `y` on `grid` under `s`.
fn check_record(
    s: &Structure,
    grid: &SampleGrid,
    y: &[f64],
    noise_std: f64,
    input: Option<&Input>,
    name: &str,
) -> CliResult<RecordReport> {
    let e = |e: jitterid::estimate::EstimateError| cli_err!("{name}: validation: {e}");
    let cmp = validation::compare(s, grid, y).map_err(e)?;
    let r = validation::standardized_residuals(s, grid, y, noise_std).map_err(e)?;
    let m = validation::default_max_lag(y.len());
    let whiteness = validation::whiteness(&r.standardized, m).map_err(e)?;
    let cross = match input {
        Some(input) => {
            let u: Vec<f64> = grid.times().map(|t| input.value(t)).collect();
            validation::cross_correlation(&r.standardized, &u, m).ok()
        }
        None => None,
    };
    let raw: Vec<f64> = y.iter().zip(&cmp.expected).map(|(y, m)| y - m).collect();
    let flatness = transform(grid, &DirichletWindow, &raw, &FrequencySet::dft(grid))
        .ok()
        .and_then(|v| residual_flatness(&v.iter().flat_map(|z| [z.re, z.im]).collect::<Vec<_>>()));
    Ok(RecordReport {
        record: name.to_string(),
        samples: y.len(),
        fit_percent: cmp.fit_percent,
        whiteness,
        cross_correlation: cross,
        flatness,
    })
}

/// A validation record: its grid (the experiment's `T`, its own length and start) and samples.
fn read_validation(exp: &Experiment, path: &Path) -> CliResult<(SampleGrid, Vec<f64>, String)> {
    let table = csvio::read(path)?;
    let y = table.column("y")?.to_vec();
    let name = table.name.clone();
    if y.len() < MIN_VALIDATION_SAMPLES {
        return Err(cli_err!(
            "{name}: --validation: {} samples, too short: at least {MIN_VALIDATION_SAMPLES} are needed",
            y.len()
        ));
    }
    let interval = exp.grid.interval();
    let t0 = match table.optional("t") {
        Some(t) => {
            let tv = t[1] - t[0];
            if (tv - interval).abs() > 1e-6 * interval {
                return Err(cli_err!(
                    "{name}: --validation: column `t` has interval T = {tv}, the experiment's [sampling] interval is {interval}"
                ));
            }
            t[0]
        }
        None => exp.grid.time(0),
    };
    let grid = SampleGrid::new(t0, interval, y.len()).map_err(|e| cli_err!("{name}: {e}"))?;
    Ok((grid, y, name))
}

/// The frequency-response CSV: log-spaced from `1/(NT)` to the Nyquist frequency `1/(2T)`.
fn bode_csv(s: &Structure, grid: &SampleGrid, cov: Option<&[Vec<f64>]>) -> CliResult<String> {
    let freqs = validation::log_spaced(1.0 / grid.duration(), 0.5 / grid.interval(), 200)
        .map_err(|e| cli_err!("--bode: {e}"))?;
    let points = export::bode_of(&s.signal, &freqs, cov)
        .ok_or_else(|| cli_err!("--bode: the system is not a rational transfer function"))?
        .map_err(|e| cli_err!("--bode: {e}"))?;
    let o = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:e}"));
    let mut out = String::from(
        "f_hz,omega_rad_s,magnitude_db,phase_deg,magnitude_db_lo,magnitude_db_hi,phase_deg_lo,phase_deg_hi\n",
    );
    for p in points {
        out.push_str(&format!(
            "{:e},{:e},{:e},{:e},{},{},{},{}\n",
            p.f_hz,
            p.omega_rad_s,
            p.magnitude_db,
            p.phase_deg,
            o(p.magnitude_db_lo),
            o(p.magnitude_db_hi),
            o(p.phase_deg_lo),
            o(p.phase_deg_hi)
        ));
    }
    Ok(out)
}

/// `jitterid validate`: the JSON, printed or written to `--out` with the CSV, atomically.
pub fn validate(o: &ValidateOptions) -> CliResult<Outcome> {
    let exp = experiment::read(&o.experiment, Purpose::Estimate(None))?;
    let table = read_data(&exp, &o.data)?;
    let y = table.column("y")?.to_vec();
    let input = record_input(&exp, &o.data, &exp.grid)?;
    let signal = fitting::signal_of(&exp.system.kind, input.as_ref())?;
    let (fitted, noise_std, cov) = match &o.model {
        Some(path) => {
            let s = fitting::structure(&exp, signal, exp.estimate.method)?;
            model_from_file(&exp, s, path)?
        }
        None => {
            let f = commands::fit_values(&exp, signal, y.clone(), &table.name)?;
            let ns = f.fitted.blocks().0;
            let cov = signal_block(f.covariance.as_deref(), ns);
            (f.fitted, f.noise_std, cov)
        }
    };
    let estimation = check_record(
        &fitted,
        &exp.grid,
        &y,
        noise_std,
        input.as_ref(),
        &table.name,
    )?;
    let validation = match &o.validation {
        Some(path) => {
            let (grid, yv, name) = read_validation(&exp, path)?;
            let mut s = fitted.clone();
            let u = record_input(&exp, path, &grid)?;
            if let Some(u) = &u {
                s.signal = fitted
                    .signal
                    .with_input(u)
                    .map_err(|e| cli_err!("{name}: the validation input: {e}"))?;
            }
            Some(check_record(&s, &grid, &yv, noise_std, u.as_ref(), &name)?)
        }
        None => None,
    };
    let mut outputs = OutputSet::new();
    if let Some(path) = &o.bode {
        outputs.file(path, bode_csv(&fitted, &exp.grid, cov.as_deref())?);
    }
    let j = ValidateJson {
        fit_percent: FitPercent {
            estimation: estimation.fit_percent,
            validation: validation.as_ref().map(|v| v.fit_percent),
        },
        whiteness: estimation.whiteness.clone(),
        cross_correlation: estimation.cross_correlation.clone(),
        flatness: estimation.flatness,
        estimation,
        validation,
    };
    let text = serde_json::to_string_pretty(&j).map_err(|e| cli_err!("JSON: {e}"))? + "\n";
    let printed = match &o.out {
        Some(path) => {
            outputs.file(path, text);
            String::new()
        }
        None => text,
    };
    outputs.commit()?;
    Ok(Outcome::success(printed))
}
