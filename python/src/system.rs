//! Systems by kind through the library's `SignalRegistry`, with the export forms of
//! `jitterid_signal::forms` (transfer function, zeros/poles/gain, state space), the frequency
//! response and the step response on NumPy arrays.

use crate::arrays::{finite_complexes, finite_reals, map_reals};
use crate::errors::{json_text, spec_table, value_error};
use jitterid::num_complex::Complex64;
use jitterid::signal::forms::{TfForm, ZpkForm};
use jitterid::signal::greybox::{ExprModel, GreyBox};
use jitterid::signal::registry::{SignalRegistry, SpecTable, KIND_KEY};
use jitterid::signal::superposition::{self, SUPERPOSITION_KIND};
use jitterid::signal::{AnySignal, Input, PiecewiseConstant, Signal};
use jitterid_study::export::{delay_of, grey_box_of, tf_of};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn};
use pyo3::prelude::*;
use serde_json::{json, Value};

/// A float64 vector out.
type Reals<'py> = Bound<'py, PyArray1<f64>>;
/// A complex128 vector out.
type Complexes<'py> = Bound<'py, PyArray1<Complex64>>;
/// A float64 matrix out.
type Matrix<'py> = Bound<'py, PyArray2<f64>>;

/// A system (or signal) kind of the registry with its keys; rational kinds also hold their
/// transfer-function coefficients.
#[pyclass(module = "jitterid._jitterid", subclass, frozen, skip_from_py_object)]
#[derive(Debug, Clone)]
pub struct System {
    pub(crate) spec: SpecTable,
    /// The model built on a unit step at 0 (kinds that take no input ignore it).
    model: AnySignal,
    tf: Option<TfForm>,
}

impl System {
    /// The model of `spec`, checked by building it through the registry (a system with
    /// several inputs on a unit step in each).
    pub fn of(spec: SpecTable) -> PyResult<Self> {
        let step = unit_step(1.0)?;
        // A system with several inputs has one transfer function per input, not one.
        let (model, tf) = match input_names(&spec) {
            Some(names) => (build_several(&spec, &vec![step; names.len()])?, None),
            None => {
                let model = build(&spec, Some(&step))?;
                let tf = tf_of(&model).map_err(value_error)?;
                (model, tf)
            }
        };
        Ok(System { spec, model, tf })
    }

    /// The input names of a system with several inputs, `None` for one input or none.
    pub fn input_names(&self) -> Option<Vec<String>> {
        input_names(&self.spec)
    }

    /// The model driven by `inputs`: none for kinds that take none, one for a system with
    /// one input, one per input (in the order of [`input_names`]) for a system with several.
    pub fn driven_by(&self, inputs: &[Input]) -> PyResult<AnySignal> {
        match (input_names(&self.spec), inputs) {
            (Some(names), _) if names.len() != inputs.len() => Err(value_error(format!(
                "inputs: the system has {} inputs ({}), found {} input(s)",
                names.len(),
                names.join(", "),
                inputs.len()
            ))),
            (Some(_), _) => build_several(&self.spec, inputs),
            (None, []) => build(&self.spec, None),
            (None, [one]) => build(&self.spec, Some(one)),
            (None, more) => Err(value_error(format!(
                "inputs: the system has one input, found {}; a system with several inputs is System.several([...]) or a grey-box model whose b has a column per input",
                more.len()
            ))),
        }
    }

    fn rational(&self) -> PyResult<&TfForm> {
        if let Some(names) = self.input_names() {
            return Err(value_error(format!(
                "a system with several inputs ({}) has one transfer function per input: System.channels gives each input's system",
                names.join(", ")
            )));
        }
        self.tf.as_ref().ok_or_else(|| {
            value_error(format!(
                "a {} system is not rational: it has no transfer function",
                self.model.kind()
            ))
        })
    }
}

fn build(spec: &SpecTable, input: Option<&Input>) -> PyResult<AnySignal> {
    SignalRegistry::builtin()
        .build(spec, input)
        .map_err(value_error)
}

fn build_several(spec: &SpecTable, inputs: &[Input]) -> PyResult<AnySignal> {
    superposition::build(SignalRegistry::builtin(), spec, inputs).map_err(value_error)
}

/// The input names of a system with several inputs (a `superposition` spec table), `None`
/// for a system with one input or none.
fn input_names(spec: &SpecTable) -> Option<Vec<String>> {
    if spec.get(KIND_KEY).and_then(Value::as_str) != Some(SUPERPOSITION_KIND) {
        return None;
    }
    let names = spec.get("inputs").and_then(Value::as_array);
    Some(
        names
            .into_iter()
            .flatten()
            .map(|n| n.as_str().unwrap_or_default().to_string())
            .collect(),
    )
}

/// `u = 1` from 0 to `end`.
fn unit_step(end: f64) -> PyResult<Input> {
    PiecewiseConstant::new(vec![0.0, end], vec![1.0])
        .map(Input::from)
        .map_err(value_error)
}

/// Complex roots as a spec table writes them: a number for a real root, `[re, im]` once per
/// conjugate pair (the member with `im > 0`; ZpkForm has checked that every pair is whole).
fn roots_spec(roots: &[Complex64]) -> Value {
    roots
        .iter()
        .filter(|r| r.im >= 0.0)
        .map(|r| {
            if r.im == 0.0 {
                json!(r.re)
            } else {
                json!([r.re, r.im])
            }
        })
        .collect()
}

/// The roots in `x` (any array-like of finite real or complex numbers); `name` names the
/// argument in messages.
fn roots_in(x: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<Complex64>> {
    Ok(finite_complexes(x, name)?
        .as_array()
        .iter()
        .copied()
        .collect())
}

#[pymethods]
impl System {
    /// The model a spec table describes (JSON text with `"kind"` and the kind's keys).
    #[new]
    fn new(spec: &str) -> PyResult<Self> {
        System::of(spec_table(spec)?)
    }

    /// `k Π(s − z_i) / Π(s − p_i)` from complex (or real) zeros and poles, conjugate pairs
    /// listed in full.
    #[staticmethod]
    fn from_zpk(zeros: &Bound<'_, PyAny>, poles: &Bound<'_, PyAny>, gain: f64) -> PyResult<Self> {
        let form = ZpkForm::new(gain, roots_in(zeros, "zeros")?, roots_in(poles, "poles")?)
            .map_err(value_error)?;
        let mut spec = SpecTable::new();
        spec.insert("kind".into(), "zpk".into());
        spec.insert("gain".into(), json!(form.gain()));
        spec.insert("zeros".into(), roots_spec(form.zeros()));
        spec.insert("poles".into(), roots_spec(form.poles()));
        System::of(spec)
    }

    /// A system with several inputs: `systems[i]` the response to input `names[i]`, added
    /// (`y = Σ G_i u_i`). With `shared`, the systems are the columns of one grey-box model
    /// (the same parameters, a column of `B` and `D` each) and share their parameters.
    #[staticmethod]
    fn several(
        names: Vec<String>,
        systems: Vec<PyRef<'_, System>>,
        shared: bool,
    ) -> PyResult<Self> {
        if names.len() != systems.len() || names.len() < 2 {
            return Err(value_error(format!(
                "systems: expected one system per input and at least two inputs, found {} system(s) for {} name(s)",
                systems.len(),
                names.len()
            )));
        }
        for (i, s) in systems.iter().enumerate() {
            if input_names(&s.spec).is_some() {
                return Err(value_error(format!(
                    "systems[{i}]: already a system with several inputs; expected one system per input"
                )));
            }
        }
        let channels = names
            .into_iter()
            .zip(&systems)
            .map(|(n, s)| (n, s.model.spec(), true))
            .collect();
        System::of(superposition::spec_table(channels, shared))
    }

    /// The input names of a system with several inputs, `None` for one input.
    #[getter]
    fn inputs(&self) -> Option<Vec<String>> {
        input_names(&self.spec)
    }

    /// A system with several inputs: the response to each input, in input order, as the
    /// systems of one input each (a shared grey-box model's columns each hold the whole
    /// parameter set); `None` for a system with one input.
    #[getter]
    fn channels(&self) -> PyResult<Option<Vec<System>>> {
        if input_names(&self.spec).is_none() {
            return Ok(None);
        }
        let spec = self.model.spec();
        let tables = spec.get("channels").and_then(Value::as_array);
        tables
            .into_iter()
            .flatten()
            .map(|t| {
                let t = t.as_object().cloned().unwrap_or_default();
                System::of(t)
            })
            .collect::<PyResult<Vec<_>>>()
            .map(Some)
    }

    /// The registry name of the kind.
    #[getter]
    fn kind(&self) -> String {
        self.model.kind().to_string()
    }

    /// The spec table that rebuilds this system, as JSON text.
    #[getter]
    fn spec_json(&self) -> PyResult<String> {
        json_text(&self.model.spec())
    }

    /// Names of the parameters, in the estimator's order.
    #[getter]
    fn param_names(&self) -> Vec<String> {
        self.model.param_names()
    }

    /// Values of the parameters, in the order of `param_names`.
    #[getter]
    fn param_values(&self) -> Vec<f64> {
        self.model.params()
    }

    /// The transfer-function coefficients `(num, den)`, highest power first, `den` monic.
    fn tf_coefficients<'py>(&self, py: Python<'py>) -> PyResult<(Reals<'py>, Reals<'py>)> {
        let tf = self.rational()?;
        Ok((
            tf.num().to_vec().into_pyarray(py),
            tf.den().to_vec().into_pyarray(py),
        ))
    }

    /// Zeros, poles (complex, conjugate pairs in full) and gain.
    fn zpk_form<'py>(&self, py: Python<'py>) -> PyResult<(Complexes<'py>, Complexes<'py>, f64)> {
        let zpk = self.rational()?.to_zpk().map_err(value_error)?;
        Ok((
            zpk.zeros().to_vec().into_pyarray(py),
            zpk.poles().to_vec().into_pyarray(py),
            zpk.gain(),
        ))
    }

    /// A state-space realisation `(A, B, C, D)`: `A` n×n, `B` n×1, `C` 1×n, `D` 1×1; a
    /// grey-box model's own matrices at its parameters, the controllable canonical form of
    /// other rational systems.
    fn state_space<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Matrix<'py>, Matrix<'py>, Matrix<'py>, Matrix<'py>)> {
        let grey = grey_box_of(&self.model).map_err(value_error)?;
        let ss = match grey
            .as_ref()
            .and_then(|g| g.downcast::<GreyBox<ExprModel>>())
        {
            Some(g) => g.state_space(),
            None => self.rational()?.to_state_space(),
        };
        let n = ss.order();
        let a = Array2::from_shape_fn((n, n), |(i, j)| ss.a()[i][j]);
        let b = Array2::from_shape_fn((n, 1), |(i, _)| ss.b()[i]);
        let c = Array2::from_shape_fn((1, n), |(_, j)| ss.c()[j]);
        let d = Array2::from_elem((1, 1), ss.d());
        Ok((
            a.into_pyarray(py),
            b.into_pyarray(py),
            c.into_pyarray(py),
            d.into_pyarray(py),
        ))
    }

    /// The input delay `D` (s) of a delayed system, `None` without one.
    #[getter]
    fn delay(&self) -> Option<f64> {
        delay_of(&self.model)
    }

    /// `G(i2πf) e^{−i2πfD}` at frequencies `f` (Hz): the rational part times the input
    /// delay's phase (`D = 0` without a delay), the response the step response is of; `f`
    /// real and finite.
    fn frequency_response<'py>(
        &self,
        py: Python<'py>,
        f: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<Complex64>>> {
        let f = finite_reals(f, "f")?;
        let tf = self.rational()?;
        let d = delay_of(&self.model).unwrap_or(0.0);
        Ok(map_reals(py, &f, |f| {
            let w = std::f64::consts::TAU * f;
            tf.response(Complex64::new(0.0, w)) * Complex64::from_polar(1.0, -w * d)
        }))
    }

    /// The response to a unit step at `t = 0` at times `t` (s, real and finite), exact; 0
    /// before the step.
    fn step<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let t = finite_reals(t, "t")?;
        self.rational()?;
        let last = t.as_array().iter().copied().fold(0.0_f64, f64::max);
        let signal = build(&self.spec, Some(&unit_step(last + 1.0)?))?;
        Ok(map_reals(py, &t, |t| signal.value(t)))
    }

    fn __repr__(&self) -> String {
        let keys: Vec<String> = self
            .model
            .spec()
            .iter()
            .filter(|(k, _)| k.as_str() != "kind")
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        format!("System({:?}, {})", self.model.kind(), keys.join(", "))
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<System>()
            .is_ok_and(|o| o.get().model.spec() == self.model.spec())
    }
}

/// The registry's system kinds with their keys, as JSON text.
#[pyfunction]
pub fn system_kinds() -> PyResult<String> {
    let entries: Vec<Value> = SignalRegistry::builtin()
        .kinds()
        .map(|k| {
            json!({
                "name": k.name(),
                "summary": k.summary(),
                "params": k.params(),
                "needs_input": k.needs_input(),
            })
        })
        .collect();
    json_text(&entries)
}
