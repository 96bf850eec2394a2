//! Experiments from the command line's TOML files: one record simulated as `jitterid simulate`
//! writes it, and a record fitted as `jitterid fit --json` reports it.

use crate::arrays::finite_samples;
use crate::errors::{json_text, spec_table, study_error, value_error};
use crate::toml_text;
use crate::watching::{run_watched, Reporter, Stopped};
use jitterid::estimate::solver::{ProgressHook, Termination};
use jitterid::signal::Input;
use jitterid::signal::{PiecewiseConstant, SampleGrid};
use jitterid_study::csvio;
use jitterid_study::experiment::{self, InputSpec, Method, Paths, Purpose};
use jitterid_study::fingerprint::experiment_fingerprint;
use jitterid_study::inputs;
use jitterid_study::montecarlo::DEFAULT_SEED;
use jitterid_study::select::InitChoice;
use jitterid_study::{fit as fitting, records, simulate, Registries};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};
use serde::Serialize;
use std::borrow::Cow;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// An experiment file, read and validated once, with its text kept for pickling.
#[pyclass(module = "jitterid._jitterid", subclass, frozen, skip_from_py_object)]
#[derive(Debug, Clone)]
pub struct Experiment {
    text: String,
    dir: PathBuf,
    /// Where the files the text names may be (`allow_paths_outside`).
    paths: Paths,
    pub(crate) exp: experiment::Experiment,
    /// The experiment read for estimation with its own method, once (re-reading it per fit
    /// cost about half a Table 2 fit); the message when the file cannot be fitted as it is.
    for_own_method: Result<experiment::Experiment, String>,
}

impl Experiment {
    /// Where the files the experiment names may be.
    pub fn paths(&self) -> Paths {
        self.paths
    }

    /// The experiment's file name (as messages name it), its text and the directory its
    /// relative paths are resolved from.
    pub fn source(&self) -> (&str, &str, &std::path::Path) {
        (&self.exp.file, &self.text, &self.dir)
    }

    /// The experiment read for estimation with `method` (the file's own if `None`): the
    /// method is checked against what the file marks as estimated.
    pub fn for_method(&self, method: Option<&str>) -> PyResult<Cow<'_, experiment::Experiment>> {
        if method.is_none() {
            return self
                .for_own_method
                .as_ref()
                .map(Cow::Borrowed)
                .map_err(study_error);
        }
        let chosen = method
            .map(|m| {
                Method::parse(m).ok_or_else(|| {
                    value_error(format!(
                        "method: expected one of {}, found {m:?}",
                        Method::names()
                    ))
                })
            })
            .transpose()?;
        experiment::parse_with(
            &Registries::builtin(),
            &self.exp.file,
            &self.text,
            &self.dir,
            Purpose::Estimate(chosen),
            self.paths,
        )
        .map(Cow::Owned)
        .map_err(study_error)
    }
}

#[pymethods]
impl Experiment {
    /// The experiment in TOML `text`; `file` names it in messages and results, `dir` resolves
    /// its relative paths (the current directory by default). The files the text names must
    /// be inside `dir` (no absolute path, no `..`, no symbolic link leading out) unless
    /// `allow_paths_outside`.
    #[new]
    #[pyo3(signature = (text, file = "<string>".to_string(), dir = ".".to_string(), *, allow_paths_outside = false))]
    fn new(text: String, file: String, dir: String, allow_paths_outside: bool) -> PyResult<Self> {
        let dir = PathBuf::from(dir);
        let paths = if allow_paths_outside {
            Paths::Anywhere
        } else {
            Paths::Inside
        };
        let registries = Registries::builtin();
        let parse =
            |purpose| experiment::parse_with(&registries, &file, &text, &dir, purpose, paths);
        let exp = parse(Purpose::Simulate).map_err(value_error)?;
        let for_own_method = parse(Purpose::Estimate(None)).map_err(|e| e.to_string());
        Ok(Experiment {
            text,
            dir,
            paths,
            exp,
            for_own_method,
        })
    }

    /// The experiment file at `path` (the command line's TOML format), read as the command
    /// line reads it (a regular file of at most `csvio::MAX_FILE_BYTES`, UTF-8); the files it
    /// names must be inside its directory unless `allow_paths_outside`.
    #[classmethod]
    #[pyo3(signature = (path, *, allow_paths_outside = false))]
    fn from_toml<'py>(
        cls: &Bound<'py, PyType>,
        path: PathBuf,
        allow_paths_outside: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let file = path.display().to_string();
        let text = experiment::read_text(&path).map_err(|e| PyOSError::new_err(e.to_string()))?;
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.display().to_string(),
            _ => ".".to_string(),
        };
        let kwargs = PyDict::new(cls.py());
        kwargs.set_item("allow_paths_outside", allow_paths_outside)?;
        cls.call((text, file, dir), Some(&kwargs))
    }

    /// The experiment whose sections are the tables of `sections` (JSON text: `{"sampling":
    /// {...}, "system": {...}, ...}`), read as the experiment file it spells; `file` names it in
    /// messages.
    #[classmethod]
    fn from_sections<'py>(
        cls: &Bound<'py, PyType>,
        sections: &str,
        file: String,
    ) -> PyResult<Bound<'py, PyAny>> {
        let text = toml_text::experiment_text(&spec_table(sections)?)?;
        cls.call1((text, file, ".".to_string()))
    }

    /// The file name, as given.
    #[getter]
    fn file(&self) -> &str {
        &self.exp.file
    }

    /// The title, if the file has one.
    #[getter]
    fn title(&self) -> Option<&str> {
        self.exp.title.as_deref()
    }

    /// The TOML text.
    #[getter]
    fn text(&self) -> &str {
        &self.text
    }

    /// The file's estimation method.
    #[getter]
    fn method(&self) -> &str {
        self.exp.estimate.method.as_str()
    }

    /// Number of samples `N`.
    #[getter]
    fn samples(&self) -> usize {
        self.exp.grid.len()
    }

    /// Sampling interval `T` (s).
    #[getter]
    fn interval(&self) -> f64 {
        self.exp.grid.interval()
    }

    /// Requested time of the first sample, `t0` (s).
    #[getter]
    fn start(&self) -> f64 {
        self.exp.grid.start()
    }

    /// The experiment's fingerprint by content (as in Monte Carlo results).
    #[getter]
    fn fingerprint(&self) -> String {
        experiment_fingerprint(&self.exp)
    }

    /// Whether the input is a random binary signal drawn per record (so fits need the record's
    /// input realisation).
    #[getter]
    fn random_input(&self) -> bool {
        self.exp.random_input()
    }

    /// Record `run` of the experiment's truth under master `seed`, as `jitterid simulate`
    /// writes it: a dict of arrays `t`, `y`, `u` (when there is an input), the random input's
    /// switch times and levels `input_t`, `input_u` (its side file), and with `truth` the drawn
    /// `tau` and `v`. With several inputs, `u` and `input_u` are dicts by input name (the
    /// random-binary inputs' levels at the switch times `input_t` of all of them).
    #[pyo3(signature = (seed = DEFAULT_SEED, run = 0, truth = false))]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        seed: u64,
        run: u64,
        truth: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let data = py
            .detach(|| simulate::simulate_data(&self.exp, seed, run))
            .map_err(value_error)?;
        let out = PyDict::new(py);
        out.set_item("t", data.t.into_pyarray(py))?;
        out.set_item("y", data.y.into_pyarray(py))?;
        let drawn: Vec<(&str, &PiecewiseConstant)> = self
            .exp
            .inputs
            .iter()
            .zip(&data.inputs)
            .filter_map(|(c, u)| match (&c.spec, u) {
                (InputSpec::RandomBinary(_), Input::Piecewise(p)) => Some((c.name.as_str(), p)),
                _ => None,
            })
            .collect();
        if let ([u], [_]) = (data.u.as_slice(), self.exp.inputs.as_slice()) {
            out.set_item("u", u.clone().into_pyarray(py))?;
            if let [(_, p)] = drawn.as_slice() {
                // The side file's columns: the switch times, and the levels with a closing 0.
                let mut levels = p.levels().to_vec();
                levels.push(0.0);
                out.set_item("input_t", p.edges().to_vec().into_pyarray(py))?;
                out.set_item("input_u", levels.into_pyarray(py))?;
            }
        } else if !data.u.is_empty() {
            let u = PyDict::new(py);
            for (c, v) in self.exp.inputs.iter().zip(data.u) {
                u.set_item(&c.name, v.into_pyarray(py))?;
            }
            out.set_item("u", u)?;
            if !drawn.is_empty() {
                // One time column for all (the side file's), each input's level from then on.
                let mut t: Vec<f64> = drawn.iter().flat_map(|(_, p)| p.edges().to_vec()).collect();
                t.sort_by(f64::total_cmp);
                t.dedup();
                let levels = PyDict::new(py);
                for (name, p) in &drawn {
                    let l: Vec<f64> = t.iter().map(|&t| p.value(t)).collect();
                    levels.set_item(name, l.into_pyarray(py))?;
                }
                out.set_item("input_t", t.into_pyarray(py))?;
                out.set_item("input_u", levels)?;
            }
        }
        if truth {
            out.set_item("tau", data.tau.into_pyarray(py))?;
            out.set_item("v", data.v.into_pyarray(py))?;
        }
        Ok(out)
    }

    /// Fits the samples `y` (with the record's input switch times and levels `input_t`,
    /// `input_u` for a random-binary experiment) with `method` (the file's if `None`), as
    /// `jitterid fit` does; `t`, when given, holds the samples' times and must be the
    /// experiment's grid, as a data file's `t` column must.
    ///
    /// The fit runs on a worker thread without the GIL while this thread looks for Python
    /// signals every [`SIGNAL_POLL`](crate::watching::SIGNAL_POLL) and calls `progress(iteration,
    /// cost)` after the solver's start and each of its iterations. Ctrl-C, or an exception
    /// raised by `progress`, stops the solver before its next iteration (the
    /// Levenberg–Marquardt and BFGS solvers; the others run to their end) and is raised then; a
    /// `KeyboardInterrupt`'s `__cause__` says where the fit stopped.
    ///
    /// `init` is where the search starts: `"experiment"` (the file's values, the default),
    /// `"auto"` (the data-driven initializer's model, as `jitterid fit --init auto`) or
    /// `"experiment-only"`.
    #[pyo3(signature = (y, input_t = None, input_u = None, method = None, t = None, progress = None, init = None))]
    #[allow(clippy::too_many_arguments)]
    fn fit_record(
        &self,
        py: Python<'_>,
        y: &Bound<'_, PyAny>,
        input_t: Option<&Bound<'_, PyAny>>,
        input_u: Option<&Bound<'_, PyAny>>,
        method: Option<&str>,
        t: Option<&Bound<'_, PyAny>>,
        progress: Option<Bound<'_, PyAny>>,
        init: Option<&str>,
    ) -> PyResult<Fit> {
        let mut exp = self.for_method(method)?;
        let init = match init {
            None => InitChoice::default(),
            Some(s) => InitChoice::parse(s).map_err(|e| value_error(format!("init: {e}")))?,
        };
        exp.to_mut().estimate.likelihood_start = init.likelihood_start();
        let y = finite_samples(y, "y")?;
        if y.len() != exp.grid.len() {
            return Err(value_error(format!(
                "y: has {} samples, expected {} (the experiment's [sampling] samples)",
                y.len(),
                exp.grid.len()
            )));
        }
        if let Some(t) = t {
            on_grid(&finite_samples(t, "t")?, &exp.grid)?;
        }
        let input = record_input(&exp, input_t, input_u, &exp.grid, "")?;
        if let Some(p) = &progress {
            if !p.is_callable() {
                return Err(PyTypeError::new_err(format!(
                    "progress: expected a callable progress(iteration, cost) or None, found {}",
                    p.get_type().name()?
                )));
            }
        }
        let cancel = Arc::new(AtomicBool::new(false));
        let watched = progress.is_some();
        let work = |reporter: Reporter<(u64, f64)>| {
            let report = move |p: &jitterid::estimate::solver::Progress| {
                reporter.report((p.iteration, p.cost));
            };
            // The stop flag is the fit's cancel flag: its budget stops any solver at its next
            // iteration and skips the covariance of a stopped search.
            let watch = jitterid_study::Watch {
                iterations: watched.then(|| ProgressHook::new(report)),
                cancel: Some(Arc::clone(&cancel)),
                ..jitterid_study::Watch::none()
            };
            let mut signal = fitting::signal_of(&exp, &input)?;
            if init == InitChoice::Auto {
                signal = fitting::data_start(&exp, &signal, &input, &y, "y")?;
            }
            fitting::fit_values(&exp, signal, y, "y", &watch)
        };
        let on_event = |(iteration, cost): (u64, f64)| -> PyResult<()> {
            if let Some(p) = &progress {
                p.call1((iteration, cost))?;
            }
            Ok(())
        };
        match run_watched(py, &cancel, work, on_event) {
            Ok(Some(fit)) => fit
                .map(|fit| Fit {
                    fit,
                    grid: exp.grid,
                })
                .map_err(study_error),
            Ok(None) => Err(PyRuntimeError::new_err("the fit's thread panicked")),
            Err(Stopped { error, outcome }) => {
                let report = match outcome {
                    Some(Ok(fit)) if fit.termination == Termination::Stopped.to_string() => {
                        format!(
                            "interrupted: the fit was stopped after {} iterations ({})",
                            fit.iterations, fit.termination
                        )
                    }
                    Some(Ok(fit)) => format!(
                        "interrupted: the fit ended ({}) before it could be stopped; its result was discarded",
                        fit.termination
                    ),
                    Some(Err(e)) => format!("interrupted: {e}"),
                    None => "interrupted: the fit's thread panicked".to_string(),
                };
                if error.cause(py).is_none() {
                    error.set_cause(py, Some(PyRuntimeError::new_err(report)));
                }
                Err(error)
            }
        }
    }

    /// Pickling: the text, the file name, the directory and whether paths outside it are
    /// allowed.
    #[allow(clippy::type_complexity)]
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<((String, String, String), Bound<'py, PyDict>)> {
        let kwargs = PyDict::new(py);
        kwargs.set_item("allow_paths_outside", self.paths == Paths::Anywhere)?;
        Ok((
            (
                self.text.clone(),
                self.exp.file.clone(),
                self.dir.display().to_string(),
            ),
            kwargs,
        ))
    }

    fn __repr__(&self) -> String {
        format!("Experiment.from_toml({:?})", self.exp.file)
    }
}

/// The inputs of a record on `grid`, in order: the experiment's known inputs, and for a
/// random-binary input the record's realisation (`input_t`, `input_u`; with several inputs,
/// `input_u` is a dict of levels by input name). `prefix` names the record's arguments in
/// messages (`""` for the fitted record, `"validation "` for a validation record).
pub fn record_input(
    exp: &experiment::Experiment,
    input_t: Option<&Bound<'_, PyAny>>,
    input_u: Option<&Bound<'_, PyAny>>,
    grid: &SampleGrid,
    prefix: &str,
) -> PyResult<Vec<Input>> {
    let several = exp.inputs.len() > 1;
    exp.inputs
        .iter()
        .map(|c| {
            Ok(match &c.spec {
                InputSpec::Known(i) => i.clone(),
                InputSpec::RandomBinary(_) => {
                    let (Some(t), Some(u)) = (input_t, input_u) else {
                        return Err(value_error(format!(
                            "{prefix}input: the experiment's input is random-binary, so the {prefix}record needs its input realisation (input_t and input_u, as simulate returns them)",
                        )));
                    };
                    if several {
                        let levels = u
                            .cast::<PyDict>()
                            .map_err(|_| value_error(format!(
                                "{prefix}input_u: the experiment has several inputs; expected a dict of levels by input name, found {}",
                                u.get_type().name().map(|n| n.to_string()).unwrap_or_default()
                            )))?
                            .get_item(&c.name)?
                            .ok_or_else(|| value_error(format!(
                                "{prefix}input_u: no levels for the input \"{}\"",
                                c.name
                            )))?;
                        Input::Piecewise(realisation(t, &levels, grid, prefix)?)
                    } else {
                        Input::Piecewise(realisation(t, u, grid, prefix)?)
                    }
                }
            })
        })
        .collect()
}

/// The random input's realisation from its switch times `t` and levels `u` (the side file's
/// columns, levels closed by a 0), checked as `jitterid fit` checks the side file.
fn realisation(
    t: &Bound<'_, PyAny>,
    u: &Bound<'_, PyAny>,
    grid: &SampleGrid,
    prefix: &str,
) -> PyResult<PiecewiseConstant> {
    let (tn, un) = (format!("{prefix}input_t"), format!("{prefix}input_u"));
    let values = vec![finite_samples(t, &tn)?, finite_samples(u, &un)?];
    if values[0].len() != values[1].len() {
        return Err(value_error(format!(
            "{tn} and {un}: expected equal lengths, found {} and {}",
            values[0].len(),
            values[1].len()
        )));
    }
    let table = csvio::Table {
        name: "input".into(),
        header_line: 1,
        columns: vec!["t".into(), "u".into()],
        lines: (2..2 + values[0].len()).collect(),
        values,
    };
    inputs::piecewise_from_table(&table, "t", "u", grid).map_err(value_error)
}

/// Refuses sample times `t` that are not the grid's `t0 + kT`, with the tolerance of
/// `jitterid fit` for a data file's `t` column (`records::read_data`: `1e-6·T` plus
/// `1e-12·|t|` for the rounding of large times).
pub(crate) fn on_grid(t: &[f64], grid: &SampleGrid) -> PyResult<()> {
    if t.len() != grid.len() {
        return Err(value_error(format!(
            "t: has {} times, expected {} (one per sample of y)",
            t.len(),
            grid.len()
        )));
    }
    let tol = 1e-6 * grid.interval();
    match (0..t.len()).find(|&k| (t[k] - grid.time(k)).abs() > tol + 1e-12 * t[k].abs()) {
        Some(k) => Err(value_error(format!(
            "t: element {k} is {}, expected {} (start + k·interval: the samples must be on a uniform grid)",
            t[k],
            grid.time(k)
        ))),
        None => Ok(()),
    }
}

/// One fit as the library returns it. `FitResult` takes its numbers from [`Fit::fields`] and
/// asks for the command line's JSON ([`Fit::json`]) only when it is wanted (`to_dict`,
/// `model`, pickling): forming it costs more than the rest of the result.
#[pyclass(module = "jitterid._jitterid", frozen, skip_from_py_object)]
pub struct Fit {
    pub(crate) fit: fitting::Fit,
    /// The fitted record's grid: the frequency and step responses' ranges are taken from it.
    pub(crate) grid: SampleGrid,
}

#[pymethods]
impl Fit {
    /// `(method, converged, cost, iterations, termination, noise_std, names, params,
    /// std_errors, covariance_names, covariance)`: the reported parameters' names, estimates
    /// and standard errors (NaN where undefined), and the estimator's covariance (`None` where
    /// undefined) of the estimated parameters `covariance_names`, in the estimator's order.
    #[allow(clippy::type_complexity)]
    fn fields<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        &'static str,
        bool,
        f64,
        u64,
        &str,
        f64,
        Vec<String>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Vec<String>,
        Option<Bound<'py, PyArray2<f64>>>,
    )> {
        let f = &self.fit;
        let names = f.params.iter().map(|p| p.name.clone()).collect();
        let params: Vec<f64> = f.params.iter().map(|p| p.estimate).collect();
        let std_errors: Vec<f64> = f
            .params
            .iter()
            .map(|p| p.stderr.unwrap_or(f64::NAN))
            .collect();
        let covariance = f
            .estimator_covariance
            .as_ref()
            .map(|c| PyArray2::from_vec2(py, c))
            .transpose()
            .map_err(|e| value_error(format!("covariance: {e}")))?;
        Ok((
            f.method.as_str(),
            f.converged,
            f.cost,
            f.iterations,
            &f.termination,
            f.noise_std,
            names,
            params.into_pyarray(py),
            std_errors.into_pyarray(py),
            f.estimated.clone(),
            covariance,
        ))
    }

    /// The fitted system's Bode diagram with its ±2σ bands, on `validate --bode`'s
    /// frequencies for the fitted record's grid (a dict of arrays; `None` for a system that is
    /// not rational).
    fn bode<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.bode_of(py)
    }

    /// The fitted system's unit-step response with its ±2σ band, on `validate --plot`'s times
    /// (a dict of arrays; `None` for a system that is not rational).
    fn step_response<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.step_of(py)
    }

    /// The fitted system's spec table (the fitted signal's kind and keys), as JSON text.
    #[getter]
    fn system_spec_json(&self) -> PyResult<String> {
        json_text(&self.fit.fitted.signal.spec())
    }

    /// The result as `jitterid fit --json` prints it, with the fitted model's parts as spec
    /// tables (`fitted_model`), and `estimated` and `estimator_covariance`, as JSON text.
    fn json(&self) -> PyResult<String> {
        let fit = &self.fit;
        json_text(&FitOut {
            cli: fitting::fit_json(fit),
            fitted_model: Model::of(&fit.fitted),
            estimated: &fit.estimated,
            estimator_covariance: fit.estimator_covariance.as_deref(),
        })
    }
}

/// A fit as the Python side reads it: the command line's JSON and the fitted model.
#[derive(Serialize)]
struct FitOut<'a> {
    #[serde(flatten)]
    cli: fitting::FitJson<'a>,
    /// The fitted parts as spec tables (the command line's `model` holds its export forms).
    fitted_model: Model,
    estimated: &'a [String],
    /// In the estimator's order (the command line's `covariance` is in the reported order).
    estimator_covariance: Option<&'a [Vec<f64>]>,
}

/// The fitted model's parts as spec tables.
#[derive(Serialize)]
struct Model {
    signal: serde_json::Map<String, serde_json::Value>,
    jitter: serde_json::Map<String, serde_json::Value>,
    noise: Vec<(String, f64)>,
    noise_std: Option<f64>,
}

impl Model {
    fn of(s: &fitting::Structure) -> Self {
        use jitterid::estimate::NoiseModel;
        Model {
            signal: s.signal.spec(),
            jitter: s.jitter.spec(),
            noise: s
                .noise
                .param_names()
                .into_iter()
                .zip(s.noise.params())
                .collect(),
            noise_std: s.noise_std,
        }
    }
}

/// The columns of a CSV file that `jitterid simulate` wrote, and, when its side file
/// `<name>.input.csv` is there (or `input` is given), the input's `input_t` and `input_u`.
#[pyfunction]
#[pyo3(signature = (path, input = None))]
pub fn read_record<'py>(
    py: Python<'py>,
    path: PathBuf,
    input: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    if !path.exists() {
        return Err(PyOSError::new_err(format!(
            "{}: cannot read: file does not exist",
            path.display()
        )));
    }
    let table = csvio::read(&path).map_err(value_error)?;
    let out = PyDict::new(py);
    for (name, values) in table.columns.iter().zip(table.values) {
        out.set_item(name, values.into_pyarray(py))?;
    }
    let side = input.unwrap_or_else(|| records::input_side_file(&path));
    if side.exists() {
        let t = csvio::read(&side).map_err(value_error)?;
        out.set_item(
            "input_t",
            t.column("t")
                .map_err(value_error)?
                .to_vec()
                .into_pyarray(py),
        )?;
        out.set_item(
            "input_u",
            t.column("u")
                .map_err(value_error)?
                .to_vec()
                .into_pyarray(py),
        )?;
    }
    Ok(out)
}
