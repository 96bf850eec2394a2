//! Known inputs: piecewise constant (from edges and levels, from samples by zero-order hold,
//! or a seeded random binary realisation) and sums of tones, as the library's `Input`.

use crate::arrays::{finite_reals, finite_samples, map_reals};
use crate::errors::{json_text, value_error};
use jitterid::rand::rngs::StdRng;
use jitterid::rand::SeedableRng;
use jitterid::signal::{Input as LibInput, Multisine, PiecewiseConstant, RandomBinary, Tone};
use numpy::{IntoPyArray, PyArray1, PyArrayDyn};
use pyo3::prelude::*;
use serde_json::{json, Value};

/// A known input `u(t)` that drives a system.
#[pyclass(
    module = "jitterid._jitterid",
    subclass,
    frozen,
    eq,
    skip_from_py_object
)]
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    pub(crate) input: LibInput,
}

fn piecewise(p: Result<PiecewiseConstant, impl std::fmt::Display>) -> PyResult<Input> {
    p.map(|p| Input { input: p.into() }).map_err(value_error)
}

fn optional(
    x: Option<&Bound<'_, PyAny>>,
    name: &str,
    len: usize,
    default: f64,
) -> PyResult<Vec<f64>> {
    let Some(x) = x else {
        return Ok(vec![default; len]);
    };
    let v = finite_samples(x, name)?;
    if v.len() != len {
        return Err(value_error(format!(
            "{name}: expected {len} values (one per frequency), found {}",
            v.len()
        )));
    }
    Ok(v)
}

#[pymethods]
impl Input {
    /// The input in the library's JSON form (as `to_json` writes it).
    #[new]
    fn new(json: &str) -> PyResult<Self> {
        serde_json::from_str(json)
            .map(|input| Input { input })
            .map_err(|e| value_error(format!("not an input: {e}")))
    }

    /// `u = levels[j]` on `[edges[j], edges[j+1])`, zero outside (one more edge than levels).
    #[staticmethod]
    fn piecewise(edges: &Bound<'_, PyAny>, levels: &Bound<'_, PyAny>) -> PyResult<Self> {
        let edges = finite_samples(edges, "edges")?;
        let levels = finite_samples(levels, "levels")?;
        piecewise(PiecewiseConstant::new(edges, levels))
    }

    /// Zero-order hold of `values`: `u = values[k]` on `[start + kT, start + (k+1)T)`.
    #[staticmethod]
    fn zero_order_hold(values: &Bound<'_, PyAny>, interval: f64, start: f64) -> PyResult<Self> {
        let values = finite_samples(values, "values")?;
        piecewise(PiecewiseConstant::zero_order_hold(start, interval, &values))
    }

    /// One realisation on `[start, end)` of the random binary input (levels `low`, `high`,
    /// exponential dwell times of mean `mean_dwell`) from a generator seeded with `seed`.
    #[staticmethod]
    fn random_binary(
        start: f64,
        end: f64,
        seed: u64,
        mean_dwell: f64,
        low: f64,
        high: f64,
    ) -> PyResult<Self> {
        let rb = RandomBinary::new(mean_dwell, low, high).map_err(value_error)?;
        piecewise(rb.generate(start, end, &mut StdRng::seed_from_u64(seed)))
    }

    /// `u = Σ A_l sin(2πf_l t + φ_l)` (amplitudes 1 and phases 0 by default).
    #[staticmethod]
    #[pyo3(signature = (frequencies, amplitudes = None, phases = None))]
    fn multisine(
        frequencies: &Bound<'_, PyAny>,
        amplitudes: Option<&Bound<'_, PyAny>>,
        phases: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let f = finite_samples(frequencies, "frequencies")?;
        let a = optional(amplitudes, "amplitudes", f.len(), 1.0)?;
        let p = optional(phases, "phases", f.len(), 0.0)?;
        let tones = (0..f.len())
            .map(|l| Tone {
                frequency: f[l],
                amplitude: a[l],
                phase: p[l],
            })
            .collect();
        Multisine::new(tones)
            .map(|m| Input { input: m.into() })
            .map_err(value_error)
    }

    /// `"piecewise"` or `"tones"`.
    #[getter]
    fn kind(&self) -> &'static str {
        match &self.input {
            LibInput::Piecewise(_) => "piecewise",
            LibInput::Tones(_) => "tones",
        }
    }

    /// The edges of a piecewise-constant input (`None` for tones).
    #[getter]
    fn edges<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        match &self.input {
            LibInput::Piecewise(p) => Some(p.edges().to_vec().into_pyarray(py)),
            LibInput::Tones(_) => None,
        }
    }

    /// The levels of a piecewise-constant input (`None` for tones).
    #[getter]
    fn levels<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        match &self.input {
            LibInput::Piecewise(p) => Some(p.levels().to_vec().into_pyarray(py)),
            LibInput::Tones(_) => None,
        }
    }

    /// The tones `(frequency, amplitude, phase)` of a multisine (empty for piecewise inputs).
    #[getter]
    fn tones(&self) -> Vec<(f64, f64, f64)> {
        match &self.input {
            LibInput::Tones(m) => m
                .tones()
                .iter()
                .map(|t| (t.frequency, t.amplitude, t.phase))
                .collect(),
            LibInput::Piecewise(_) => Vec::new(),
        }
    }

    /// `u(t)` at times `t` (s, real and finite).
    fn value<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let t = finite_reals(t, "t")?;
        Ok(map_reals(py, &t, |t| self.input.value(t)))
    }

    /// The library's JSON form (what `Input(json)` reads back).
    fn to_json(&self) -> PyResult<String> {
        json_text(&self.input)
    }

    /// The experiment file's `[input]` table for this input, as JSON text.
    fn section_json(&self) -> PyResult<String> {
        let table: Value = match &self.input {
            LibInput::Piecewise(p) => {
                json!({"kind": "piecewise", "times": p.edges(), "values": p.levels()})
            }
            LibInput::Tones(m) => {
                let col = |f: fn(&Tone) -> f64| m.tones().iter().map(f).collect::<Vec<f64>>();
                json!({
                    "kind": "multisine",
                    "frequencies": col(|t| t.frequency),
                    "amplitudes": col(|t| t.amplitude),
                    "phases": col(|t| t.phase),
                })
            }
        };
        json_text(&table)
    }

    fn __getnewargs__(&self) -> PyResult<(String,)> {
        Ok((self.to_json()?,))
    }

    fn __repr__(&self) -> String {
        match &self.input {
            LibInput::Piecewise(p) => format!(
                "Input.piecewise({} levels from {} to {} s)",
                p.levels().len(),
                p.edges()[0],
                p.edges()[p.edges().len() - 1]
            ),
            LibInput::Tones(m) => format!("Input.multisine({} tones)", m.tones().len()),
        }
    }
}
