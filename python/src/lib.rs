//! `jitterid._jitterid`: the compiled core of the `jitterid` Python package.
//!
//! Thin bindings over the library's run-time registries and the command line's library, so
//! that a number computed from Python is the number `jitterid simulate / fit / montecarlo`
//! computes for the same seed. The pure-Python modules beside it (`python/jitterid/`) give the
//! keyword-argument API and the result classes; this module exchanges spec tables and results
//! as JSON text and samples as NumPy arrays.
#![warn(missing_docs)]

mod arrays;
mod designing;
mod errors;
mod experiment;
mod input;
mod jitter;
mod sampling;
mod study;
mod system;
mod toml_text;
mod validating;
mod watching;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _jitterid(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<jitter::Jitter>()?;
    m.add_class::<experiment::Experiment>()?;
    m.add_class::<experiment::Fit>()?;
    m.add_class::<system::System>()?;
    m.add_class::<input::Input>()?;
    m.add_class::<validating::Validated>()?;
    m.add_function(wrap_pyfunction!(system::system_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(sampling::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(sampling::first_moment, m)?)?;
    m.add_function(wrap_pyfunction!(sampling::second_moment, m)?)?;
    m.add_function(wrap_pyfunction!(jitter::jitter_families, m)?)?;
    m.add_function(wrap_pyfunction!(study::montecarlo, m)?)?;
    m.add_function(wrap_pyfunction!(study::merge, m)?)?;
    m.add_function(wrap_pyfunction!(validating::validate, m)?)?;
    m.add_function(wrap_pyfunction!(validating::select, m)?)?;
    m.add_function(wrap_pyfunction!(experiment::read_record, m)?)?;
    m.add_function(wrap_pyfunction!(designing::design, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
