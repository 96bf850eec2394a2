//! `jitterid validate`: fit percent, residual whiteness and input cross-correlation, flatness,
//! the frequency-response CSV of a fitted model (given as `fit --json` or fitted here), and
//! its figures.

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
use crate::plots::{self, RecordPlot, ValidatePlots};
use crate::whiten;
use jitterid::estimate::validation::{self, BodePoint, CorrelationTest, StepPoint};
use jitterid::estimate::{residual_flatness, NoiseModel};
use jitterid::signal::{Input, SampleGrid, Signal};
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
    /// Write the SVG figures into this directory.
    pub plot: Option<PathBuf>,
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
    /// A validation record's own initial state (`initial.*`, re-estimated on it with the system
    /// held); absent for the estimation record and for a model without a free response.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<Vec<f64>>,
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

/// The validation checks of `y` on `grid` under `s`, and the expected samples `m_k`.
fn check_record(
    s: &Structure,
    grid: &SampleGrid,
    y: &[f64],
    noise_std: f64,
    input: Option<&Input>,
    name: &str,
) -> CliResult<(RecordReport, Vec<f64>)> {
    let e = |e: jitterid::estimate::EstimateError| cli_err!("{name}: validation: {e}");
    let cmp = validation::compare(s, grid, y).map_err(e)?;
    let r = validation::standardized_residuals(s, grid, y, noise_std).map_err(e)?;
    let raw: Vec<f64> = y.iter().zip(&cmp.expected).map(|(y, m)| y - m).collect();
    let tested = tested_residuals(s, grid, noise_std, &raw, r.standardized, name)?;
    let m = validation::default_max_lag(y.len());
    let whiteness = validation::whiteness(&tested, m).map_err(e)?;
    let cross = match input {
        Some(input) => {
            let u: Vec<f64> = grid.times().map(|t| input.value(t)).collect();
            validation::cross_correlation(&tested, &u, m).ok()
        }
        None => None,
    };
    let flatness = transform(grid, &DirichletWindow, &raw, &FrequencySet::dft(grid))
        .ok()
        .and_then(|v| residual_flatness(&v.iter().flat_map(|z| [z.re, z.im]).collect::<Vec<_>>()));
    let report = RecordReport {
        record: name.to_string(),
        samples: y.len(),
        fit_percent: cmp.fit_percent,
        whiteness,
        cross_correlation: cross,
        flatness,
        initial_state: None,
    };
    Ok((report, cmp.expected))
}

/// The residuals the correlation tests see: the standardised residuals for white noise; for a
/// coloured noise model the raw residuals whitened by the fitted residual spectrum, the noise
/// model's shape plus the jitter's floor `ρ = λ̄/σ_e²` at this record's model
/// ([`whiten::whitened`]).
fn tested_residuals(
    s: &Structure,
    grid: &SampleGrid,
    noise_std: f64,
    raw: &[f64],
    standardized: Vec<f64>,
    name: &str,
) -> CliResult<Vec<f64>> {
    if s.noise.is_white() {
        return Ok(standardized);
    }
    // `None` when the shape has its floor already, or the jitter adds no variance.
    let floor = s.jitter_floor_start(grid, Some(noise_std)).unwrap_or(0.0);
    whiten::whitened(raw, grid.interval(), |f| {
        s.noise.shape(f, grid.interval()) + floor
    })
    .ok_or_else(|| {
        cli_err!("{name}: validation: the noise model's spectrum is not positive and finite")
    })
}

/// The fitted model on a validation record: driven by the record's input and, for a model with
/// a free response, started from the record's own state, re-estimated on the record with the
/// system held ([`validation::on_record`]): the state the estimation record started from says
/// nothing about another record's.
fn for_validation_record(
    fitted: &Structure,
    grid: &SampleGrid,
    y: &[f64],
    input: Option<&Input>,
    name: &str,
) -> CliResult<Structure> {
    validation::on_record(fitted, grid, y, input)
        .map_err(|e| cli_err!("{name}: the model on the validation record: {e}"))
}

/// The free response's coefficients of a signal that has them.
fn initial_state(signal: &jitterid::signal::AnySignal) -> Option<Vec<f64>> {
    let names = signal.param_names();
    let params = signal.params();
    let q: Vec<f64> = names
        .iter()
        .zip(params)
        .filter(|(n, _)| n.starts_with(validation::INITIAL_PREFIX))
        .map(|(_, v)| v)
        .collect();
    (!q.is_empty()).then_some(q)
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

/// The system's part of a signal's parameter covariance, `G`'s parameters then the delay: its
/// leading block, since a signal lists the system's own parameters first (then `delay`, then
/// the `initial.*` coefficients of a free response, on which `G e^{−sD}` does not depend).
/// `None` without a covariance.
fn system_covariance(s: &Structure, cov: Option<&[Vec<f64>]>) -> Option<Vec<Vec<f64>>> {
    let names = s.signal.param_names();
    let p = names
        .iter()
        .take_while(|n| !n.starts_with(validation::INITIAL_PREFIX))
        .count();
    let cov = cov?;
    (cov.len() >= p && cov.iter().take(p).all(|r| r.len() >= p))
        .then(|| cov[..p].iter().map(|r| r[..p].to_vec()).collect())
}

/// The frequency response on 200 frequencies log-spaced from `1/(NT)` to the Nyquist
/// frequency `1/(2T)`, with the delay's phase for a delayed system; `None` for a system that
/// is not rational. `flag` names the option.
fn frequency_response(
    s: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
    flag: &str,
) -> CliResult<Option<Vec<BodePoint>>> {
    let cov = system_covariance(s, cov);
    let freqs = validation::log_spaced(1.0 / grid.duration(), 0.5 / grid.interval(), 200)
        .map_err(|e| cli_err!("{flag}: {e}"))?;
    export::bode_of(&s.signal, &freqs, cov.as_deref())
        .transpose()
        .map_err(|e| cli_err!("{flag}: {e}"))
}

/// The unit-step response on 200 times from the step to 8 time constants of the slowest pole
/// (where its mode has decayed to e⁻⁸), at most the record's duration, plus the input delay of
/// a delayed system (its response is zero until then); `None` for a system that is not
/// rational.
fn step(
    s: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
) -> CliResult<Option<Vec<StepPoint>>> {
    let cov = system_covariance(s, cov);
    let slowest = export::tf_of(&s.signal)
        .and_then(|tf| tf.to_zpk().ok())
        .map(|z| {
            z.poles()
                .iter()
                .map(|p| -p.re)
                .fold(f64::INFINITY, f64::min)
        });
    let horizon = match slowest {
        Some(r) if r > 0.0 && r.is_finite() => (8.0 / r).min(grid.duration()),
        _ => grid.duration(),
    };
    let horizon = horizon + export::delay_of(&s.signal).unwrap_or(0.0);
    let times: Vec<f64> = (0..200).map(|i| horizon * i as f64 / 199.0).collect();
    export::step_of(&s.signal, &times, cov.as_deref())
        .transpose()
        .map_err(|e| cli_err!("--plot: step response: {e}"))
}

/// The frequency-response CSV of `points`.
fn bode_csv(points: &[BodePoint]) -> String {
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
    out
}

/// What the figures draw of one record.
fn record_plot<'a>(
    role: &'a str,
    r: &'a RecordReport,
    grid: &'a SampleGrid,
    y: &'a [f64],
    expected: &'a [f64],
) -> RecordPlot<'a> {
    RecordPlot {
        role,
        name: &r.record,
        grid,
        y,
        expected,
        fit_percent: r.fit_percent,
        whiteness: &r.whiteness,
        cross: r.cross_correlation.as_ref(),
    }
}

/// Adds the figures of `--plot DIR` to the outputs (the Bode diagram on the `--bode` CSV's
/// frequencies; it and the step response only for a rational system).
fn stage_figures(
    dir: &Path,
    outputs: &mut OutputSet,
    exp: &Experiment,
    fitted: &Structure,
    cov: Option<&[Vec<f64>]>,
    estimation: RecordPlot<'_>,
    validation: Option<RecordPlot<'_>>,
) -> CliResult<()> {
    let bode = frequency_response(fitted, &exp.grid, cov, "--plot")?;
    let step = step(fitted, &exp.grid, cov)?;
    let figs = plots::validate_figures(&ValidatePlots {
        title: exp.title.clone().unwrap_or_else(|| exp.file.clone()),
        estimation,
        validation,
        bode: bode.as_deref(),
        step: step.as_deref(),
    });
    outputs.dir(dir);
    for (name, svg) in figs {
        outputs.file(&dir.join(name), svg);
    }
    Ok(())
}

/// `jitterid validate`: the JSON, printed or written to `--out` with the CSV and the figures,
/// all at once.
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
    let (estimation, expected) = check_record(
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
            let u = record_input(&exp, path, &grid)?;
            let s = for_validation_record(&fitted, &grid, &yv, u.as_ref(), &name)?;
            let (mut report, expected) =
                check_record(&s, &grid, &yv, noise_std, u.as_ref(), &name)?;
            report.initial_state = initial_state(&s.signal);
            Some((report, expected, grid, yv))
        }
        None => None,
    };
    let mut outputs = OutputSet::new();
    if let Some(path) = &o.bode {
        let points = frequency_response(&fitted, &exp.grid, cov.as_deref(), "--bode")?
            .ok_or_else(|| cli_err!("--bode: the system is not a rational transfer function"))?;
        outputs.file(path, bode_csv(&points));
    }
    if let Some(dir) = &o.plot {
        let validation = validation
            .as_ref()
            .map(|(r, e, g, yv)| record_plot("validation", r, g, yv, e));
        let estimation = record_plot("estimation", &estimation, &exp.grid, &y, &expected);
        stage_figures(
            dir,
            &mut outputs,
            &exp,
            &fitted,
            cov.as_deref(),
            estimation,
            validation,
        )?;
    }
    let validation = validation.map(|v| v.0);
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
