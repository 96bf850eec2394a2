//! Validation of a fitted model: fit percent, residual whiteness and input cross-correlation,
//! flatness of the residual spectrum, on the estimation record and on a validation record; the
//! frequency and step responses of the fitted system with their bands.

use crate::csvio;
use crate::error::StudyResult;
use crate::experiment::Experiment;
use crate::export;
use crate::fit::{self, Structure};
use crate::records::{read_data, read_input_on};
use crate::residual_tests::tested_residuals;
use crate::study_err;
use crate::Watch;
use jitterid::estimate::residual_flatness;
use jitterid::estimate::validation::{self, BodePoint, CorrelationTest, StepPoint};
use jitterid::signal::{Input, SampleGrid, Signal};
use jitterid::window::{transform, DirichletWindow, FrequencySet};
use serde::Serialize;
use std::path::Path;

/// Fewest samples of a validation record (enough for lags up to `N/4`).
pub const MIN_VALIDATION_SAMPLES: usize = 16;

/// The checks of one record.
#[derive(Debug, Clone, Serialize)]
pub struct RecordReport {
    /// The record's file.
    pub record: String,
    /// Samples.
    pub samples: usize,
    /// Normalised fit of the expected samples, in percent.
    pub fit_percent: f64,
    /// How many fitted parameters' directions were removed from the residuals before the
    /// correlation tests ([`crate::residual_tests`]).
    pub removed_directions: usize,
    /// Autocorrelation of the standardised residuals.
    pub whiteness: CorrelationTest,
    /// Cross-correlation of the standardised residuals with the input (`null` without input;
    /// the first input's for a system with several).
    pub cross_correlation: Option<CorrelationTest>,
    /// For a system with several inputs: the cross-correlation test with each input, by
    /// name (absent for one input, whose test is `cross_correlation`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub input_correlations: Vec<InputCorrelation>,
    /// Largest band power of the residual spectrum over the others (`null`: too few bins).
    pub flatness: Option<f64>,
    /// A validation record's own initial state (`initial.*`, re-estimated on it with the system
    /// held); absent for the estimation record and for a model without a free response.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<Vec<f64>>,
}

/// The cross-correlation test of the residuals with one input of a multi-input system.
#[derive(Debug, Clone, Serialize)]
pub struct InputCorrelation {
    /// The input's name.
    pub input: String,
    /// The test (`null` for an input that is constant on the record).
    pub test: Option<CorrelationTest>,
}

/// The JSON of `validate`, borrowed from a [`Validation`].
#[derive(Debug, Serialize)]
pub struct ValidateJson<'a> {
    /// The level of the tests' verdicts.
    level: f64,
    fit_percent: FitPercent,
    whiteness: &'a CorrelationTest,
    cross_correlation: Option<&'a CorrelationTest>,
    #[serde(skip_serializing_if = "<[InputCorrelation]>::is_empty")]
    input_correlations: &'a [InputCorrelation],
    flatness: Option<f64>,
    estimation: &'a RecordReport,
    validation: Option<&'a RecordReport>,
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

/// The fitted structure, its noise level and the covariance of its signal parameters.
type Model = (Structure, f64, Option<Vec<Vec<f64>>>);

/// The fitted model in `text`, the JSON of `jitterid fit --json` (`name` names it in
/// messages), checked against the experiment's structure `s`.
fn model_from_json(
    exp: &Experiment,
    mut s: Structure,
    text: &str,
    name: &str,
) -> StudyResult<Model> {
    let f: FitFile = serde_json::from_str(text)
        .map_err(|e| study_err!("{name}: not the JSON of `jitterid fit --json`: {e}"))?;
    let want = fit::param_names(exp, &s.signal, exp.estimate.method)?;
    let got: Vec<&str> = f.parameters.iter().map(|p| p.name.as_str()).collect();
    if want != got {
        return Err(study_err!(
            "{name}: parameters [{}] do not match the experiment's [{}] ({} with method {})",
            got.join(", "),
            want.join(", "),
            exp.file,
            exp.estimate.method.as_str()
        ));
    }
    // A covariance that is there must be whole: a ragged one is a damaged file, not a model
    // without bands.
    if let Some(c) = &f.covariance {
        let n = f.parameters.len();
        if c.len() != n {
            return Err(study_err!(
                "{name}: covariance: expected {n} rows (one per parameter), found {}",
                c.len()
            ));
        }
        if let Some((i, row)) = c.iter().enumerate().find(|(_, row)| row.len() != n) {
            return Err(study_err!(
                "{name}: covariance: row {} has {} entries, expected {n} (one per parameter)",
                i + 1,
                row.len()
            ));
        }
    }
    if let Some(p) = f.parameters.iter().find(|p| !p.estimate.is_finite()) {
        return Err(study_err!(
            "{name}: parameter {}: not a finite estimate",
            p.name
        ));
    }
    // A profiled uniform sum reports its order `jitter.n` and the derived `jitter.sigma` beside
    // its parameter `a`: the order chooses the family member, the derived value is not a
    // parameter of the structure.
    let profiled = fit::profiled(exp) && s.estimate_jitter;
    if profiled {
        let n = f
            .parameters
            .iter()
            .find(|p| p.name == "jitter.n")
            .map(|p| p.estimate)
            .filter(|n| *n >= 0.0 && n.fract() == 0.0 && *n <= f64::from(u32::MAX))
            .ok_or_else(|| {
                study_err!(
                    "{name}: parameter jitter.n: expected the profiled order, a whole number >= 0"
                )
            })?;
        s.jitter = fit::with_n(&s.jitter, n as u32)
            .map_err(|e| study_err!("{name}: parameter jitter.n: {e}"))?;
    }
    let theta: Vec<f64> = f
        .parameters
        .iter()
        .filter(|p| !(profiled && (p.name == "jitter.n" || p.name == "jitter.sigma")))
        .take(s.num_params())
        .map(|p| p.estimate)
        .collect();
    let ns = s.blocks().0;
    let fitted = s
        .with_params(&theta)
        .and_then(|s| s.with_noise_std(f.noise_std))
        .map_err(|e| study_err!("{name}: the model's parameters: {e}"))?;
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

/// The validation checks of `y` on `grid` under `s` (a fitted structure, noise level
/// `noise_std`, driven by `inputs`, named `input_names` when there are several), with the
/// correlation tests' verdicts at `level`, and the expected samples `m_k`. `name` names the
/// record in messages.
#[allow(clippy::too_many_arguments)]
pub fn check_record(
    s: &Structure,
    grid: &SampleGrid,
    y: &[f64],
    noise_std: f64,
    inputs: &[Input],
    input_names: &[String],
    level: f64,
    name: &str,
) -> StudyResult<(RecordReport, Vec<f64>)> {
    let e = |e: jitterid::estimate::EstimateError| study_err!("{name}: validation: {e}");
    let cmp = validation::compare(s, grid, y).map_err(e)?;
    let r = validation::standardized_residuals(s, grid, y, noise_std).map_err(e)?;
    let raw: Vec<f64> = y.iter().zip(&cmp.expected).map(|(y, m)| y - m).collect();
    let tested = tested_residuals(s, grid, noise_std, y, &raw, &r.variance, name)?;
    let m = validation::default_max_lag(y.len());
    let whiteness =
        validation::whiteness(&tested.residuals, m, tested.noise_params, level).map_err(e)?;
    let crosses: Vec<Option<CorrelationTest>> = inputs
        .iter()
        .map(|input| {
            let u: Vec<f64> = grid.times().map(|t| input.value(t)).collect();
            // A constant input has no cross-correlation to test.
            validation::cross_correlation(&tested.residuals, &u, m, &tested.basis, level).ok()
        })
        .collect();
    let cross = crosses.first().cloned().flatten();
    let input_correlations = if inputs.len() > 1 {
        input_names
            .iter()
            .zip(crosses)
            .map(|(n, test)| InputCorrelation {
                input: n.clone(),
                test,
            })
            .collect()
    } else {
        Vec::new()
    };
    let flatness = transform(grid, &DirichletWindow, &raw, &FrequencySet::dft(grid))
        .ok()
        .and_then(|v| residual_flatness(&v.iter().flat_map(|z| [z.re, z.im]).collect::<Vec<_>>()));
    let report = RecordReport {
        record: name.to_string(),
        samples: y.len(),
        fit_percent: cmp.fit_percent,
        removed_directions: tested.removed,
        whiteness,
        cross_correlation: cross,
        input_correlations,
        flatness,
        initial_state: None,
    };
    Ok((report, cmp.expected))
}

/// The fitted model on a validation record: driven by the record's input and, for a model with
/// a free response, started from the record's own state, re-estimated on the record with the
/// system held ([`validation::on_record`]): the state the estimation record started from says
/// nothing about another record's.
///
/// A multi-input model is driven by the record's inputs with its parameters as fitted; a free
/// response of one of its channels is not re-estimated on another record yet, and is refused.
fn for_validation_record(
    exp: &Experiment,
    fitted: &Structure,
    grid: &SampleGrid,
    y: &[f64],
    inputs: &[Input],
    name: &str,
) -> StudyResult<Structure> {
    let err =
        |e: &dyn std::fmt::Display| study_err!("{name}: the model on the validation record: {e}");
    if exp.multi_input() {
        if fitted
            .signal
            .param_names()
            .iter()
            .any(|n| n.contains(&format!(".{}", validation::INITIAL_PREFIX)))
        {
            return Err(err(&"a multi-input model's free response (initial = \"estimate\") is not re-estimated on a validation record; validate it on its estimation record"));
        }
        let mut s = fitted.clone();
        s.signal = fit::build_signal(exp, &fitted.signal.spec(), inputs).map_err(|e| err(&e))?;
        return Ok(s);
    }
    validation::on_record(fitted, grid, y, inputs.first()).map_err(|e| err(&e))
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
fn read_validation(exp: &Experiment, path: &Path) -> StudyResult<(SampleGrid, Vec<f64>, String)> {
    let table = csvio::read(path)?;
    let y = table.column("y")?.to_vec();
    let name = table.name.clone();
    let grid = validation_grid(exp, y.len(), table.optional("t"), &name, "--validation")?;
    Ok((grid, y, name))
}

/// The grid of a validation record of `samples` samples with sample times `t` where known:
/// the experiment's `T`, the record's own length and start (`t[0]`, else the experiment's
/// `t0`). `name` names the record in messages, `what` the option or argument that gave it.
///
/// # Errors
///
/// Fewer than [`MIN_VALIDATION_SAMPLES`] samples, or times whose interval is not the
/// experiment's.
pub fn validation_grid(
    exp: &Experiment,
    samples: usize,
    t: Option<&[f64]>,
    name: &str,
    what: &str,
) -> StudyResult<SampleGrid> {
    if samples < MIN_VALIDATION_SAMPLES {
        return Err(study_err!(
            "{name}: {what}: {samples} samples, too short: at least {MIN_VALIDATION_SAMPLES} are needed"
        ));
    }
    let interval = exp.grid.interval();
    let t0 = match t {
        Some(t) if t.len() >= 2 => {
            let tv = t[1] - t[0];
            if (tv - interval).abs() > 1e-6 * interval {
                return Err(study_err!(
                    "{name}: {what}: column `t` has interval T = {tv}, the experiment's [sampling] interval is {interval}"
                ));
            }
            t[0]
        }
        _ => exp.grid.time(0),
    };
    SampleGrid::new(t0, interval, samples).map_err(|e| study_err!("{name}: {e}"))
}

/// The system's part of a signal's parameter covariance, `G`'s parameters then the delay: its
/// leading block, since a signal lists the system's own parameters first (then `delay`, then
/// the `initial.*` coefficients of a free response and the output `offset`, on which
/// `G e^{−sD}` does not depend). `None` without a covariance.
fn system_covariance(s: &Structure, cov: Option<&[Vec<f64>]>) -> Option<Vec<Vec<f64>>> {
    system_block(&s.signal.param_names(), cov)
}

/// [`system_covariance`] of a signal whose parameters are `names`.
pub(crate) fn system_block(names: &[String], cov: Option<&[Vec<f64>]>) -> Option<Vec<Vec<f64>>> {
    let p = names
        .iter()
        .take_while(|n| {
            !n.starts_with(validation::INITIAL_PREFIX) && *n != jitterid::signal::OFFSET_PARAM
        })
        .count();
    let cov = cov?;
    (cov.len() >= p && cov.iter().take(p).all(|r| r.len() >= p))
        .then(|| cov[..p].iter().map(|r| r[..p].to_vec()).collect())
}

/// The frequency response on 200 frequencies log-spaced from `1/(NT)` to the Nyquist
/// frequency `1/(2T)`, with the delay's phase for a delayed system; `None` for a system that
/// is not rational. `flag` names the option.
pub fn frequency_response(
    s: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
    flag: &str,
) -> StudyResult<Option<Vec<BodePoint>>> {
    let cov = system_covariance(s, cov);
    let freqs = bode_frequencies(grid, flag)?;
    export::bode_of(&s.signal, &freqs, cov.as_deref())
        .transpose()
        .map_err(|e| study_err!("{flag}: {e}"))
}

/// The frequencies of a Bode diagram on `grid`: 200 log-spaced from `1/(NT)` to `1/(2T)`.
pub(crate) fn bode_frequencies(grid: &SampleGrid, flag: &str) -> StudyResult<Vec<f64>> {
    validation::log_spaced(1.0 / grid.duration(), 0.5 / grid.interval(), 200)
        .map_err(|e| study_err!("{flag}: {e}"))
}

/// The unit-step response on 200 times from the step to 8 time constants of the slowest pole
/// (where its mode has decayed to e⁻⁸), at most the record's duration, plus the input delay of
/// a delayed system (its response is zero until then); `None` for a system that is not
/// rational.
pub fn step(
    s: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
) -> StudyResult<Option<Vec<StepPoint>>> {
    step_response(s, grid, cov, "--plot")
}

/// [`step`], its errors naming `what` (the option or argument that asked for it).
pub fn step_response(
    s: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
    what: &str,
) -> StudyResult<Option<Vec<StepPoint>>> {
    let cov = system_covariance(s, cov);
    // An export error surfaces from `step_of` below; here it only loses the horizon.
    let slowest = export::tf_of(&s.signal)
        .ok()
        .flatten()
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
        .map_err(|e| study_err!("{what}: step response: {e}"))
}

/// The columns of the frequency-response CSV.
pub(crate) const BODE_COLUMNS: &str =
    "f_hz,omega_rad_s,magnitude_db,phase_deg,magnitude_db_lo,magnitude_db_hi,phase_deg_lo,phase_deg_hi";

/// One row of the frequency-response CSV, without its line end.
pub(crate) fn bode_row(p: &BodePoint) -> String {
    let o = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:e}"));
    format!(
        "{:e},{:e},{:e},{:e},{},{},{},{}",
        p.f_hz,
        p.omega_rad_s,
        p.magnitude_db,
        p.phase_deg,
        o(p.magnitude_db_lo),
        o(p.magnitude_db_hi),
        o(p.phase_deg_lo),
        o(p.phase_deg_hi)
    )
}

/// The frequency-response CSV of `points`.
pub fn bode_csv(points: &[BodePoint]) -> String {
    let mut out = format!("{BODE_COLUMNS}\n");
    for p in points {
        out.push_str(&bode_row(p));
        out.push('\n');
    }
    out
}

/// One record as validated: its checks, its grid and samples, and the model's expected
/// samples `m_k` on it.
#[derive(Debug, Clone)]
pub struct ValidatedRecord {
    /// The checks.
    pub report: RecordReport,
    /// The record's grid.
    pub grid: SampleGrid,
    /// Its samples.
    pub y: Vec<f64>,
    /// The model's expected samples.
    pub expected: Vec<f64>,
}

/// A validated model: the fitted structure and the checks of the estimation record and, when
/// given, of a validation record.
#[derive(Debug, Clone)]
pub struct Validation {
    /// The fitted structure (on the estimation record).
    pub fitted: Structure,
    /// Its measurement-noise standard deviation.
    pub noise_std: f64,
    /// The covariance of its signal parameters, where known.
    pub covariance: Option<Vec<Vec<f64>>>,
    /// The estimation record's checks.
    pub estimation: ValidatedRecord,
    /// The validation record's checks.
    pub validation: Option<ValidatedRecord>,
    /// The level of the tests' verdicts.
    pub level: f64,
}

impl Validation {
    /// The JSON of `jitterid validate`.
    pub fn json(&self) -> ValidateJson<'_> {
        let e = &self.estimation.report;
        let v = self.validation.as_ref().map(|v| &v.report);
        ValidateJson {
            level: self.level,
            fit_percent: FitPercent {
                estimation: e.fit_percent,
                validation: v.map(|v| v.fit_percent),
            },
            whiteness: &e.whiteness,
            cross_correlation: e.cross_correlation.as_ref(),
            input_correlations: &e.input_correlations,
            flatness: e.flatness,
            estimation: e,
            validation: v,
        }
    }
}

/// What `validate` checks besides the estimation record.
#[derive(Debug, Clone, Copy)]
pub struct ValidateOptions<'a> {
    /// A validation record (same `T`, its own input side file).
    pub validation: Option<&'a Path>,
    /// A `fit --json` output to validate instead of fitting.
    pub model: Option<&'a Path>,
    /// The estimation record's input realisation (a random-binary experiment), default
    /// `<data stem>.input.csv`.
    pub input: Option<&'a Path>,
    /// The level of the correlation tests' verdicts, in `(0, 1)`.
    pub level: f64,
}

impl Default for ValidateOptions<'_> {
    fn default() -> Self {
        ValidateOptions {
            validation: None,
            model: None,
            input: None,
            level: validation::DEFAULT_LEVEL,
        }
    }
}

/// `level` if it lies in `(0, 1)`; otherwise an error naming `flag` and the value.
pub fn check_level(level: f64, flag: &str) -> StudyResult<f64> {
    validation::check_level(level).map_err(|_| {
        study_err!("{flag}: expected a test level strictly between 0 and 1, found {level}")
    })
}

/// The covariance of a fit's signal parameters (the block the frequency and step responses'
/// bands need), `None` where the fit has none.
pub fn signal_covariance(f: &fit::Fit) -> Option<Vec<Vec<f64>>> {
    signal_block(f.covariance.as_deref(), f.fitted.blocks().0)
}

/// A record held in memory: its samples on its grid, its input, and its name for messages.
#[derive(Debug, Clone)]
pub struct RecordSamples {
    /// The record's name (its file, or the argument that gave it).
    pub name: String,
    /// Its grid: the experiment's for the estimation record, [`validation_grid`] for a
    /// validation record.
    pub grid: SampleGrid,
    /// Its samples.
    pub y: Vec<f64>,
    /// Its inputs, in order (the experiment's known inputs, or the record's realisations).
    pub inputs: Vec<Input>,
}

/// A fitted model given as the JSON of `jitterid fit --json`, instead of fitted here.
#[derive(Debug, Clone, Copy)]
pub struct FitText<'a> {
    /// The JSON text.
    pub text: &'a str,
    /// What holds it (a file's name), for messages.
    pub name: &'a str,
}

/// Validates the experiment's model on the record in `data` and, when given, on the record in
/// `o.validation`: the model is read from `o.model` (a `fit --json` output) or fitted here.
pub fn validate(
    exp: &Experiment,
    data: &Path,
    o: &ValidateOptions<'_>,
    watch: &Watch,
) -> StudyResult<Validation> {
    let level = check_level(o.level, "--level")?;
    let table = read_data(exp, data)?;
    let inputs = read_input_on(exp, data, o.input, &exp.grid)?;
    let estimation = RecordSamples {
        name: table.name,
        grid: exp.grid,
        y: table.y,
        inputs,
    };
    let validation = match o.validation {
        Some(path) => {
            let (grid, y, name) = read_validation(exp, path)?;
            let inputs = read_input_on(exp, path, None, &grid)?;
            Some(RecordSamples {
                name,
                grid,
                y,
                inputs,
            })
        }
        None => None,
    };
    let text = match o.model {
        Some(path) => {
            let name = path.display().to_string();
            let text = csvio::read_text(path, &name, "the JSON of `jitterid fit --json`")?;
            Some((name, text))
        }
        None => None,
    };
    let model = text.as_ref().map(|(name, text)| FitText { text, name });
    validate_records(exp, estimation, validation, model, level, watch)
}

/// [`validate`] on records held in memory: the estimation record (on the experiment's grid)
/// and, when given, a validation record (on its own grid, [`validation_grid`]); the model is
/// read from `model` or fitted here. `level` is the correlation tests' level, in `(0, 1)`.
pub fn validate_records(
    exp: &Experiment,
    estimation: RecordSamples,
    validation: Option<RecordSamples>,
    model: Option<FitText<'_>>,
    level: f64,
    watch: &Watch,
) -> StudyResult<Validation> {
    let level = check_level(level, "level")?;
    let RecordSamples {
        name, y, inputs, ..
    } = estimation;
    let signal = fit::signal_of(exp, &inputs)?;
    let names: Vec<String> = exp.inputs.iter().map(|c| c.name.clone()).collect();
    let (fitted, noise_std, covariance) = match model {
        Some(m) => {
            let s = fit::structure(exp, signal, exp.estimate.method)?;
            model_from_json(exp, s, m.text, m.name)?
        }
        None => {
            let f = fit::fit_values(exp, signal, y.clone(), &name, watch)?;
            let cov = signal_covariance(&f);
            (f.fitted, f.noise_std, cov)
        }
    };
    let (report, expected) = check_record(
        &fitted, &exp.grid, &y, noise_std, &inputs, &names, level, &name,
    )?;
    let estimation = ValidatedRecord {
        report,
        grid: exp.grid,
        y,
        expected,
    };
    let validation = match validation {
        Some(r) => {
            let s = for_validation_record(exp, &fitted, &r.grid, &r.y, &r.inputs, &r.name)?;
            let (mut report, expected) = check_record(
                &s, &r.grid, &r.y, noise_std, &r.inputs, &names, level, &r.name,
            )?;
            report.initial_state = initial_state(&s.signal);
            Some(ValidatedRecord {
                report,
                grid: r.grid,
                y: r.y,
                expected,
            })
        }
        None => None,
    };
    Ok(Validation {
        fitted,
        noise_std,
        covariance,
        estimation,
        validation,
        level,
    })
}
