//! NumPy arrays in and out: any array-like of numbers in (lists, float32, non-contiguous
//! views), float64 or complex128 arrays of the same shape out.

use crate::errors::value_error;
use numpy::ndarray::ArrayD;
use numpy::{AllowTypeChange, IntoPyArray, PyArrayDyn, PyArrayLike1, PyArrayLikeDyn};
use pyo3::prelude::*;

/// An array-like of reals, converted to float64.
pub type RealsIn<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// A one-dimensional array-like of reals, converted to float64.
pub type SamplesIn<'py> = PyArrayLike1<'py, f64, AllowTypeChange>;

/// `f` applied to every element of `x`, keeping its shape.
pub fn map_reals<'py, T: numpy::Element>(
    py: Python<'py>,
    x: &RealsIn<'py>,
    f: impl Fn(f64) -> T,
) -> Bound<'py, PyArrayDyn<T>> {
    let out: ArrayD<T> = x.as_array().map(|&v| f(v));
    out.into_pyarray(py)
}

/// The samples of `x` as a vector, refused when empty or not finite; `name` names the
/// argument in the message.
pub fn finite_samples(x: &SamplesIn<'_>, name: &str) -> PyResult<Vec<f64>> {
    let v: Vec<f64> = x.as_array().iter().copied().collect();
    if v.is_empty() {
        return Err(value_error(format!(
            "{name}: expected at least one sample, found an empty array"
        )));
    }
    if let Some(k) = v.iter().position(|y| !y.is_finite()) {
        return Err(value_error(format!(
            "{name}: element {k} is {} (not a finite number)",
            v[k]
        )));
    }
    Ok(v)
}
