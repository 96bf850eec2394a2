//! Validation, selection and the fitted system's responses with their bands, by the study
//! layer's functions (`jitterid_study::validate`, `jitterid_study::select`), so that the
//! numbers are those of `jitterid validate --json`, `validate --bode` and `select --json`.

use crate::arrays::finite_samples;
use crate::errors::{json_text, study_error, value_error};
use crate::experiment::{record_input, Experiment, Fit};
use jitterid::estimate::validation::{BodePoint, StepPoint, DEFAULT_LEVEL};
use jitterid::signal::SampleGrid;
use jitterid_study::fit::Structure;
use jitterid_study::select::select as run_selection;
use jitterid_study::validate::{
    check_level, frequency_response, step_response, validate_records, validation_grid, FitText,
    RecordSamples, Validation,
};
use jitterid_study::Watch;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// A named column of points: its name in the dict, and its value at a point (`None` where it has
/// none).
type Column<P> = (&'static str, fn(&P) -> Option<f64>);

/// A dict of float64 arrays, one per column of `points` (NaN where a column has no value).
fn columns_dict<'py, P>(
    py: Python<'py>,
    points: &[P],
    columns: &[Column<P>],
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    for (name, column) in columns {
        let v: Vec<f64> = points
            .iter()
            .map(|p| column(p).unwrap_or(f64::NAN))
            .collect();
        out.set_item(*name, v.into_pyarray(py))?;
    }
    Ok(out)
}

/// The Bode diagram of a fitted structure on the study layer's 200 frequencies (log-spaced
/// from `1/(NT)` to the Nyquist frequency of `grid`), as a dict of float64 arrays: `f` (Hz),
/// `omega` (rad/s), `magnitude_db`, `phase_deg` and the ±2σ bands `magnitude_db_lo`, `_hi`,
/// `phase_deg_lo`, `_hi` (NaN without a covariance); `None` for a system that is not rational.
pub fn bode_dict<'py>(
    py: Python<'py>,
    fitted: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let Some(points) = frequency_response(fitted, grid, cov, "bode").map_err(value_error)? else {
        return Ok(None);
    };
    let columns: [Column<BodePoint>; 8] = [
        ("f", |p| Some(p.f_hz)),
        ("omega", |p| Some(p.omega_rad_s)),
        ("magnitude_db", |p| Some(p.magnitude_db)),
        ("phase_deg", |p| Some(p.phase_deg)),
        ("magnitude_db_lo", |p| p.magnitude_db_lo),
        ("magnitude_db_hi", |p| p.magnitude_db_hi),
        ("phase_deg_lo", |p| p.phase_deg_lo),
        ("phase_deg_hi", |p| p.phase_deg_hi),
    ];
    columns_dict(py, &points, &columns).map(Some)
}

/// The unit-step response of a fitted structure on the study layer's 200 times (to 8 time
/// constants of the slowest pole, at most the record's duration, plus an input delay), as a
/// dict of float64 arrays `t`, `value` and the ±2σ band `lo`, `hi` (NaN without a
/// covariance); `None` for a system that is not rational.
pub fn step_dict<'py>(
    py: Python<'py>,
    fitted: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let Some(points) = step_response(fitted, grid, cov, "step").map_err(value_error)? else {
        return Ok(None);
    };
    let columns: [Column<StepPoint>; 4] = [
        ("t", |p| Some(p.t)),
        ("value", |p| Some(p.value)),
        ("lo", |p| p.lo),
        ("hi", |p| p.hi),
    ];
    columns_dict(py, &points, &columns).map(Some)
}

/// A validated model, as `jitterid validate` computes it.
#[pyclass(module = "jitterid._jitterid", frozen, skip_from_py_object)]
pub struct Validated {
    validation: Validation,
}

#[pymethods]
impl Validated {
    /// The JSON of `jitterid validate --json`, as text.
    fn json(&self) -> PyResult<String> {
        json_text(&self.validation.json())
    }

    /// The Bode diagram with its bands ([`bode_dict`]), as `validate --bode` writes it.
    fn bode<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let v = &self.validation;
        bode_dict(py, &v.fitted, &v.estimation.grid, v.covariance.as_deref())
    }

    /// The step response with its band ([`step_dict`]), as `validate --plot` draws it.
    fn step<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let v = &self.validation;
        step_dict(py, &v.fitted, &v.estimation.grid, v.covariance.as_deref())
    }

    /// The model's expected samples `m_k` on each record: a dict with `estimation` and, when
    /// one was validated, `validation`, each a dict of arrays `t`, `y`, `expected`.
    fn records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        let v = &self.validation;
        for (role, r) in [
            ("estimation", Some(&v.estimation)),
            ("validation", v.validation.as_ref()),
        ] {
            let Some(r) = r else { continue };
            let d = PyDict::new(py);
            d.set_item("t", r.grid.times().collect::<Vec<f64>>().into_pyarray(py))?;
            d.set_item("y", r.y.clone().into_pyarray(py))?;
            d.set_item("expected", r.expected.clone().into_pyarray(py))?;
            out.set_item(role, d)?;
        }
        Ok(out)
    }

    /// The fitted system's spec table, as JSON text.
    #[getter]
    fn system_spec_json(&self) -> PyResult<String> {
        json_text(&self.validation.fitted.signal.spec())
    }

    /// The fitted measurement-noise standard deviation.
    #[getter]
    fn noise_std(&self) -> f64 {
        self.validation.noise_std
    }
}

/// A record's samples and grid: `y` on the experiment's grid (`t`, when given, checked on
/// it) for the estimation record; for a validation record its own grid from `t` (its
/// `validation_grid`). `prefix` names the record's arguments in messages.
fn samples_on(
    exp: &jitterid_study::experiment::Experiment,
    y: &Bound<'_, PyAny>,
    t: Option<&Bound<'_, PyAny>>,
    validation: bool,
) -> PyResult<(Vec<f64>, SampleGrid)> {
    let prefix = if validation { "validation " } else { "" };
    let y = finite_samples(y, &format!("{prefix}y"))?;
    let t = t
        .map(|t| finite_samples(t, &format!("{prefix}t")))
        .transpose()?;
    if !validation {
        if y.len() != exp.grid.len() {
            return Err(value_error(format!(
                "y: has {} samples, expected {} (the experiment's [sampling] samples)",
                y.len(),
                exp.grid.len()
            )));
        }
        if let Some(t) = &t {
            crate::experiment::on_grid(t, &exp.grid)?;
        }
        return Ok((y, exp.grid));
    }
    let grid = validation_grid(exp, y.len(), t.as_deref(), "validation", "validation")
        .map_err(value_error)?;
    Ok((y, grid))
}

/// Validates the experiment's model (fitted here with `method`, or the model in `fit_json`,
/// the JSON of `jitterid fit --json`) on the record `y` (its input realisation `input_t`,
/// `input_u` for a random-binary experiment; `t`, when given, on the experiment's grid) and,
/// when `validation_y` is given, on that validation record, with the correlation tests'
/// verdicts at `level`: `jitterid validate [--validation] [--model] --level`.
#[pyfunction]
#[pyo3(signature = (experiment, y, input_t = None, input_u = None, t = None, validation_y = None, validation_t = None, validation_input_t = None, validation_input_u = None, fit_json = None, level = DEFAULT_LEVEL, method = None))]
#[allow(clippy::too_many_arguments)]
pub fn validate(
    py: Python<'_>,
    experiment: &Experiment,
    y: &Bound<'_, PyAny>,
    input_t: Option<&Bound<'_, PyAny>>,
    input_u: Option<&Bound<'_, PyAny>>,
    t: Option<&Bound<'_, PyAny>>,
    validation_y: Option<&Bound<'_, PyAny>>,
    validation_t: Option<&Bound<'_, PyAny>>,
    validation_input_t: Option<&Bound<'_, PyAny>>,
    validation_input_u: Option<&Bound<'_, PyAny>>,
    fit_json: Option<&str>,
    level: f64,
    method: Option<&str>,
) -> PyResult<Validated> {
    let level = check_level(level, "level").map_err(value_error)?;
    let exp = experiment.for_method(method)?;
    let (y, grid) = samples_on(&exp, y, t, false)?;
    let inputs = record_input(&exp, input_t, input_u, &grid, "")?;
    let estimation = RecordSamples {
        name: "record".into(),
        grid,
        y,
        inputs,
    };
    let validation = match validation_y {
        Some(vy) => {
            let (y, grid) = samples_on(&exp, vy, validation_t, true)?;
            let inputs = record_input(
                &exp,
                validation_input_t,
                validation_input_u,
                &grid,
                "validation ",
            )?;
            Some(RecordSamples {
                name: "validation".into(),
                grid,
                y,
                inputs,
            })
        }
        None => None,
    };
    let model = fit_json.map(|text| FitText { text, name: "fit" });
    let validation = py
        .detach(|| validate_records(&exp, estimation, validation, model, level, &Watch::none()))
        .map_err(study_error)?;
    Ok(Validated { validation })
}

/// Selects among the experiment's `[select]` grid on the record in the data file `data` (and
/// its side file), with each candidate's fit percent on the record in `validation` when given,
/// within `time_limit` seconds (the experiment's `[estimate] max_seconds`, else the study
/// layer's default): the JSON of `jitterid select --json`, as text. The Python side writes the
/// records it is given into these files, since the study layer's selection reads records from
/// files.
#[pyfunction]
#[pyo3(signature = (experiment, data, validation = None, time_limit = None))]
pub fn select(
    py: Python<'_>,
    experiment: &Experiment,
    data: PathBuf,
    validation: Option<PathBuf>,
    time_limit: Option<f64>,
) -> PyResult<String> {
    let mut exp = experiment.exp.clone();
    if let Some(t) = time_limit {
        if !(t.is_finite() && t >= 0.0) {
            return Err(value_error(format!(
                "time_limit: expected a number of seconds >= 0, found {t}"
            )));
        }
        exp.estimate.max_seconds = Some(t);
    }
    exp.selectable().map_err(study_error)?;
    let selection = py
        .detach(|| run_selection(&exp, &data, validation.as_deref()))
        .map_err(study_error)?;
    json_text(&selection.to_json())
}

/// The responses of a fit, on its record's grid.
impl Fit {
    /// The Bode diagram with its bands ([`bode_dict`]).
    pub fn bode_of<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let cov = jitterid_study::validate::signal_covariance(&self.fit);
        bode_dict(py, &self.fit.fitted, &self.grid, cov.as_deref())
    }

    /// The step response with its band ([`step_dict`]).
    pub fn step_of<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let cov = jitterid_study::validate::signal_covariance(&self.fit);
        step_dict(py, &self.fit.fitted, &self.grid, cov.as_deref())
    }
}
