//! Jittered records of a system and the exact moments of their samples: the library's
//! simulator (`y_k = s(t_k + τ_k) + v_k`), `m_k = E[s(t_k + τ)]` and
//! `λ_k = σ_v² + E[s(t_k + τ)²] − m_k²`.

use crate::errors::value_error;
use crate::input::Input;
use crate::jitter::Jitter;
use crate::system::System;
use jitterid::estimate::ml::second_moments_of;
use jitterid::rand::rngs::StdRng;
use jitterid::rand::SeedableRng;
use jitterid::signal::{AnySignal, SampleGrid, Signal};
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The grid `t_k = start + k·interval`, `k < samples`, and the system driven by `inputs`
/// (none, one, or one per input of a system with several).
fn setup(
    system: &System,
    inputs: &[PyRef<'_, Input>],
    samples: usize,
    interval: f64,
    start: f64,
) -> PyResult<(SampleGrid, AnySignal)> {
    let grid = SampleGrid::new(start, interval, samples).map_err(value_error)?;
    let inputs: Vec<_> = inputs.iter().map(|i| i.input.clone()).collect();
    let signal = system.driven_by(&inputs)?;
    Ok((grid, signal))
}

/// `samples` jittered samples of `system` driven by `inputs` at `start + k·interval`, with
/// white noise of standard deviation `noise_std`, from a generator seeded with `seed`: a dict
/// of arrays `t`, `y`, `u` (with an input; a dict of arrays by input name for a system with
/// several) and with `truth` the drawn `tau` and `v`.
#[pyfunction]
#[pyo3(signature = (system, jitter, inputs, samples, interval, start, noise_std, seed, truth))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    system: &System,
    jitter: &Jitter,
    inputs: Vec<PyRef<'py, Input>>,
    samples: usize,
    interval: f64,
    start: f64,
    noise_std: f64,
    seed: u64,
    truth: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (grid, signal) = setup(system, &inputs, samples, interval, start)?;
    let sim = py
        .detach(|| {
            let mut rng = StdRng::seed_from_u64(seed);
            jitterid::signal::simulate(
                signal.model(),
                jitter.model.model(),
                &grid,
                noise_std,
                &mut rng,
            )
        })
        .map_err(value_error)?;
    let t: Vec<f64> = grid.times().collect();
    let out = PyDict::new(py);
    let sampled = |i: &Input| -> Vec<f64> { t.iter().map(|&t| i.input.value(t)).collect() };
    match (system.input_names(), inputs.as_slice()) {
        (Some(names), _) => {
            let u = PyDict::new(py);
            for (name, i) in names.iter().zip(&inputs) {
                u.set_item(name, sampled(i).into_pyarray(py))?;
            }
            out.set_item("u", u)?;
        }
        (None, [i]) => out.set_item("u", sampled(i).into_pyarray(py))?,
        (None, _) => {}
    }
    out.set_item("t", t.into_pyarray(py))?;
    out.set_item("y", sim.y.into_pyarray(py))?;
    if truth {
        out.set_item("tau", sim.tau.into_pyarray(py))?;
        out.set_item("v", sim.noise.into_pyarray(py))?;
    }
    Ok(out)
}

/// `m_k = E[s(t_k + τ)]` at `t_k = start + k·interval`, exact.
#[pyfunction]
pub fn first_moment<'py>(
    py: Python<'py>,
    system: &System,
    jitter: &Jitter,
    inputs: Vec<PyRef<'py, Input>>,
    samples: usize,
    interval: f64,
    start: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (grid, signal) = setup(system, &inputs, samples, interval, start)?;
    let m = py.detach(|| signal.expected_values(&grid, jitter.model.model()));
    Ok(m.into_pyarray(py))
}

/// `λ_k = Var y_k = noise_std² + E[s(t_k + τ)²] − m_k²` at `t_k = start + k·interval`, exact
/// (the jitter's part clamped at 0 against rounding), by the library's `second_moments_of`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn second_moment<'py>(
    py: Python<'py>,
    system: &System,
    jitter: &Jitter,
    inputs: Vec<PyRef<'py, Input>>,
    samples: usize,
    interval: f64,
    start: f64,
    noise_std: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    if !noise_std.is_finite() || noise_std < 0.0 {
        return Err(value_error(format!(
            "noise_std: expected a finite number >= 0, found {noise_std}"
        )));
    }
    let (grid, signal) = setup(system, &inputs, samples, interval, start)?;
    let moments = py
        .detach(|| second_moments_of(&signal, jitter.model.model(), &grid, noise_std))
        .map_err(value_error)?;
    Ok(moments.variance.into_pyarray(py))
}
