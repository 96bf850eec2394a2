//! Jitter models by name through the library's `JitterRegistry`: characteristic function,
//! moment generating function, density and draws on NumPy arrays.

use crate::arrays::{finite_complexes, finite_reals, map_reals};
use crate::errors::{json_text, spec_table, value_error};
use jitterid::jitter::registry::JitterRegistry;
use jitterid::jitter::AnyJitter;
use jitterid::num_complex::Complex64;
use jitterid::rand::rngs::StdRng;
use jitterid::rand::SeedableRng;
use numpy::{IntoPyArray, PyArray1, PyArrayDyn};
use pyo3::prelude::*;
use serde::Serialize;

/// A jitter model: the pdf of the sampling-time error `τ`.
#[pyclass(
    module = "jitterid._jitterid",
    subclass,
    frozen,
    eq,
    skip_from_py_object
)]
#[derive(Debug, Clone, PartialEq)]
pub struct Jitter {
    pub(crate) model: AnyJitter,
}

impl Jitter {
    /// The Python object of a library model.
    pub fn of(model: AnyJitter) -> Self {
        Jitter { model }
    }
}

#[pymethods]
impl Jitter {
    /// The model a spec table describes (JSON text with `"family"` and the family's keys).
    #[new]
    fn new(spec: &str) -> PyResult<Self> {
        let table = spec_table(spec)?;
        JitterRegistry::builtin()
            .build(&table)
            .map(Jitter::of)
            .map_err(value_error)
    }

    /// The member of family `name` with standard deviation `sigma` (s); `spec` (JSON text)
    /// holds the family's structural keys.
    #[staticmethod]
    fn from_std_dev(name: &str, sigma: f64, spec: &str) -> PyResult<Self> {
        let table = spec_table(spec)?;
        JitterRegistry::builtin()
            .from_std_dev(name, sigma, &table)
            .map(Jitter::of)
            .map_err(value_error)
    }

    /// The registry name of the family.
    #[getter]
    fn family(&self) -> String {
        self.model.family().to_string()
    }

    /// The spec table that rebuilds this model, as JSON text.
    #[getter]
    fn spec_json(&self) -> PyResult<String> {
        json_text(&self.model.spec())
    }

    /// Names of the continuous parameters, in order.
    #[getter]
    fn param_names(&self) -> Vec<String> {
        self.model.model().param_names()
    }

    /// Values of the continuous parameters, in the order of `param_names`.
    #[getter]
    fn param_values(&self) -> Vec<f64> {
        self.model.model().params()
    }

    /// Standard deviation of `τ` (s).
    #[getter]
    fn std(&self) -> f64 {
        self.model.model().std_dev()
    }

    /// Mean of `τ` (s).
    #[getter]
    fn mean(&self) -> f64 {
        self.model.model().mean()
    }

    /// Variance of `τ` (s²).
    #[getter]
    fn variance(&self) -> f64 {
        self.model.model().variance()
    }

    /// Characteristic function `γ(f) = E[exp(-i2πfτ)]` at frequencies `f` (Hz): a number or
    /// an array-like of real, finite numbers (any shape, kept).
    fn cf<'py>(
        &self,
        py: Python<'py>,
        f: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<Complex64>>> {
        let f = finite_reals(f, "f")?;
        Ok(map_reals(py, &f, |f| self.model.model().cf(f)))
    }

    /// Moment generating function `E[exp(zτ)]` at complex `z` (finite real and imaginary
    /// parts); NaN where it does not exist.
    fn mgf<'py>(
        &self,
        py: Python<'py>,
        z: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<Complex64>>> {
        let z = finite_complexes(z, "z")?;
        let nan = Complex64::new(f64::NAN, f64::NAN);
        Ok(z.as_array()
            .map(|&z| self.model.model().mgf(z).unwrap_or(nan))
            .into_pyarray(py))
    }

    /// Density of `τ` at `t` (1/s), `t` real and finite; atoms are not included.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let t = finite_reals(t, "t")?;
        Ok(map_reals(py, &t, |t| self.model.model().pdf(t)))
    }

    /// `size` independent draws of `τ` from a generator seeded with `seed`.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        size: usize,
        seed: u64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let mut rng = StdRng::seed_from_u64(seed);
        let draws =
            jitterid::jitter::sample_n(self.model.model(), size, &mut rng).map_err(value_error)?;
        Ok(draws.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        let spec = self.model.spec();
        let keys: Vec<String> = spec
            .iter()
            .filter(|(k, _)| k.as_str() != "family")
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        format!("Jitter({:?}, {})", self.model.family(), keys.join(", "))
    }
}

/// One family's registry entry, as the Python side lists it.
#[derive(Serialize)]
struct FamilyEntry<'a> {
    name: &'a str,
    summary: &'a str,
    params: &'a [jitterid::jitter::registry::ParamSpec],
    takes_terms: bool,
    has_std_dev_form: bool,
}

/// The registry's families with their keys, as JSON text.
#[pyfunction]
pub fn jitter_families() -> PyResult<String> {
    let entries: Vec<FamilyEntry<'_>> = JitterRegistry::builtin()
        .families()
        .map(|f| FamilyEntry {
            name: f.name(),
            summary: f.summary(),
            params: f.params(),
            takes_terms: f.takes_terms(),
            has_std_dev_form: f.has_std_dev_form(),
        })
        .collect();
    json_text(&entries)
}
