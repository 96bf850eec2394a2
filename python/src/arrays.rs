//! NumPy arrays in and out: numbers and array-likes of real numbers in (lists, any integer or
//! floating dtype, non-contiguous views), checked as the command line checks its columns, and
//! float64 or complex128 arrays of the same shape out.
//!
//! An argument is read by `numpy.asarray` without a target type and refused by its dtype
//! before it is converted: converting to float64 first would turn `None` into NaN and drop the
//! imaginary part of a complex value with only a warning.

use crate::errors::value_error;
use jitterid::num_complex::Complex64;
use numpy::ndarray::{ArrayD, Dimension};
use numpy::{IntoPyArray, PyArrayDyn, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// What an argument's values may be.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Field {
    Real,
    Complex,
}

/// `x` as a NumPy array of `field` numbers (converted to float64 or complex128): `None`,
/// text, objects and (for reals) complex values are a `TypeError`, a ragged nesting a
/// `ValueError`, each naming the argument `name`.
fn numeric<'py>(x: &Bound<'py, PyAny>, name: &str, field: Field) -> PyResult<Bound<'py, PyAny>> {
    let py = x.py();
    let wanted = match field {
        Field::Real => "real numbers",
        Field::Complex => "numbers",
    };
    if x.is_none() {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected {wanted} (a number or an array of them), found None"
        )));
    }
    let np = py.import("numpy")?;
    let array = np.call_method1("asarray", (x,)).map_err(|e| {
        if e.is_instance_of::<PyValueError>(py) || e.is_instance_of::<PyTypeError>(py) {
            // NumPy's message says what is wrong (an inhomogeneous shape, say); it does not
            // say which argument.
            PyValueError::new_err(format!("{name}: not an array of {wanted}: {}", e.value(py)))
        } else {
            e
        }
    })?;
    let dtype = array.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    let target = match (kind.as_str(), field) {
        ("b" | "i" | "u" | "f", Field::Real) => "float64",
        ("b" | "i" | "u" | "f" | "c", Field::Complex) => "complex128",
        ("c", Field::Real) => {
            return Err(PyTypeError::new_err(format!(
                "{name}: expected {wanted}, found complex values (pass their .real or abs() if that is what is meant)"
            )))
        }
        _ => {
            let found = if array.getattr("ndim")?.extract::<usize>()? == 0 {
                format!("a value of type {}", x.get_type().name()?)
            } else {
                format!("an array of dtype {dtype}")
            };
            return Err(PyTypeError::new_err(format!(
                "{name}: expected {wanted}, found {found}"
            )));
        }
    };
    array.call_method1("astype", (target,))
}

/// Where element `index` of an array is, in words (`element 3`, `element (1, 2)`).
fn element(index: &[usize]) -> String {
    match index {
        [] => "the value".to_string(),
        [k] => format!("element {k}"),
        _ => format!(
            "element ({})",
            index
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// `x` (a number or an array-like of real numbers, any shape) as float64, every element
/// finite; `name` names the argument in the messages (see [`numeric`]; a NaN or an infinity is
/// a `ValueError` naming its element).
pub fn finite_reals<'py>(
    x: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let a: PyReadonlyArrayDyn<'py, f64> = numeric(x, name, Field::Real)?.extract()?;
    if let Some((index, v)) = a.as_array().indexed_iter().find(|(_, v)| !v.is_finite()) {
        return Err(value_error(format!(
            "{name}: {} is {v} (not a finite number)",
            element(index.slice())
        )));
    }
    Ok(a)
}

/// `x` (a number or an array-like of real or complex numbers, any shape) as complex128, every
/// real and imaginary part finite; as [`finite_reals`] otherwise.
pub fn finite_complexes<'py>(
    x: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, Complex64>> {
    let a: PyReadonlyArrayDyn<'py, Complex64> = numeric(x, name, Field::Complex)?.extract()?;
    if let Some((index, v)) = a.as_array().indexed_iter().find(|(_, v)| !v.is_finite()) {
        return Err(value_error(format!(
            "{name}: {} is {v} (not a finite number)",
            element(index.slice())
        )));
    }
    Ok(a)
}

/// `f` applied to every element of `x`, keeping its shape.
pub fn map_reals<'py, T: numpy::Element>(
    py: Python<'py>,
    x: &PyReadonlyArrayDyn<'py, f64>,
    f: impl Fn(f64) -> T,
) -> Bound<'py, PyArrayDyn<T>> {
    let out: ArrayD<T> = x.as_array().map(|&v| f(v));
    out.into_pyarray(py)
}

/// The samples of `x`, a one-dimensional array-like of real numbers, as a vector, refused
/// when empty or not finite; `name` names the argument in the message.
pub fn finite_samples(x: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<f64>> {
    let a = finite_reals(x, name)?;
    if a.ndim() != 1 {
        return Err(value_error(format!(
            "{name}: expected a one-dimensional array, found shape ({})",
            a.shape()
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let v: Vec<f64> = a.as_array().iter().copied().collect();
    if v.is_empty() {
        return Err(value_error(format!(
            "{name}: expected at least one sample, found an empty array"
        )));
    }
    Ok(v)
}
