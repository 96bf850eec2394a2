//! Records of an experiment's truth: the input of one realisation, the jittered samples and
//! the coloured measurement noise, exactly as `jitterid simulate` writes them and as every
//! Monte Carlo realisation draws them.

use crate::error::StudyResult;
use crate::experiment::{Experiment, InputSpec};
use crate::fit::signal_of;
use crate::inputs::input_span;
use crate::study_err;
use jitterid::estimate::montecarlo::realization_rng;
use jitterid::estimate::NoiseModel;
use jitterid::rand::rngs::StdRng;
use jitterid::signal::{simulate, AnySignal, Input};

/// The true inputs of one realisation, in order: a random binary input is drawn from `rng`
/// (from its `history` seconds before `t0`), others are fixed. Inputs are drawn in order from
/// the one generator, so a single input is drawn as it always was.
pub fn realize_inputs(exp: &Experiment, rng: &mut StdRng) -> StudyResult<Vec<Input>> {
    exp.inputs
        .iter()
        .map(|c| {
            Ok(match &c.spec {
                InputSpec::Known(i) => i.clone(),
                InputSpec::RandomBinary(rb) => {
                    let (a, b) = input_span(&exp.grid);
                    Input::Piecewise(rb.generate(a - c.history, b, rng).map_err(|e| {
                        study_err!("{}: [input] {}: random-binary: {e}", exp.file, c.name)
                    })?)
                }
            })
        })
        .collect()
}

/// The inputs as a fit sees them: each true input from the record's first instant `t0` on
/// (what `simulate` writes beside the record), as a measurement of it would.
pub fn seen_inputs(exp: &Experiment, truth: &[Input]) -> StudyResult<Vec<Input>> {
    exp.inputs
        .iter()
        .zip(truth)
        .map(|(c, u)| {
            Ok(match u {
                Input::Piecewise(p) if c.history > 0.0 => {
                    Input::Piecewise(crate::inputs::from_start(p, exp.grid.start()).map_err(
                        |e| study_err!("{}: [input] {}: history: {e}", exp.file, c.name),
                    )?)
                }
                other => other.clone(),
            })
        })
        .collect()
}

/// One simulated record: `y`, and the drawn `τ` and `v`.
pub struct Simulated {
    /// Samples.
    pub y: Vec<f64>,
    /// Jitter of each sample.
    pub tau: Vec<f64>,
    /// Measurement noise of each sample (after the noise filter).
    pub v: Vec<f64>,
}

/// Simulates the experiment's truth with `signal`; coloured noise is white noise filtered by
/// the `[noise]` model with zero initial conditions.
pub fn simulate_record(
    exp: &Experiment,
    signal: &AnySignal,
    rng: &mut StdRng,
) -> StudyResult<Simulated> {
    let sim = simulate(signal, &exp.jitter.truth, &exp.grid, exp.noise.std, rng)
        .map_err(|e| study_err!("{}: simulation: {e}", exp.file))?;
    let shape = &exp.noise.shape;
    // The ARMA model's parameters are `c1…` then `d1…`.
    let coloured = (!shape.is_white()).then(|| {
        let p = shape.params();
        let nc = shape
            .param_names()
            .iter()
            .filter(|n| n.starts_with('c'))
            .count();
        arma_filter(&p[..nc], &p[nc..], &sim.noise)
    });
    // `y - e + v`, in place: the white noise drawn into `y` replaced by the filtered one. White
    // noise is its own filtered noise (`v = e`, not a copy of it), and the same expression
    // keeps its samples bit for bit those of earlier versions.
    let mut y = sim.y;
    let v = coloured.as_deref().unwrap_or(&sim.noise);
    for ((y, e), v) in y.iter_mut().zip(&sim.noise).zip(v) {
        *y = *y - e + v;
    }
    let v = coloured.unwrap_or(sim.noise);
    // The door refuses values outside the representable range; this catches a combination of
    // values inside it that still overflows, rather than writing NaN samples.
    if let Some(k) = y.iter().position(|x| !x.is_finite()) {
        return Err(study_err!(
            "{}: sample {k} of the simulated record is {}: the experiment's values are beyond what double precision can simulate",
            exp.file,
            y[k]
        ));
    }
    Ok(Simulated { y, tau: sim.tau, v })
}

/// `v = (C(q)/D(q)) e` with `C = 1 + c_1 q^{-1} + …`, `D = 1 + d_1 q^{-1} + …`, at rest before.
pub fn arma_filter(c: &[f64], d: &[f64], e: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = Vec::with_capacity(e.len());
    for k in 0..e.len() {
        let mut x = e[k];
        for (i, ci) in c.iter().enumerate() {
            if k > i {
                x += ci * e[k - i - 1];
            }
        }
        for (i, di) in d.iter().enumerate() {
            if k > i {
                x -= di * v[k - i - 1];
            }
        }
        v.push(x);
    }
    v
}

/// One simulated record of an experiment, as values (what `jitterid simulate` writes).
#[derive(Debug, Clone)]
pub struct SimulatedData {
    /// Requested sampling times `t_k = t0 + kT`.
    pub t: Vec<f64>,
    /// Samples.
    pub y: Vec<f64>,
    /// Each input at `t_k`, in order (none when the experiment has no input).
    pub u: Vec<Vec<f64>>,
    /// Jitter of each sample.
    pub tau: Vec<f64>,
    /// Measurement noise of each sample.
    pub v: Vec<f64>,
    /// The input realisations, in order (a random binary input's switch times and levels
    /// among others).
    pub inputs: Vec<Input>,
}

/// Realisation `run` of the experiment's truth under master seed `seed`: the record of Monte
/// Carlo run `run`.
pub fn simulate_data(exp: &Experiment, seed: u64, run: u64) -> StudyResult<SimulatedData> {
    let mut rng = realization_rng(seed, run);
    let truth = realize_inputs(exp, &mut rng)?;
    let signal = signal_of(exp, &truth)?;
    let sim = simulate_record(exp, &signal, &mut rng)?;
    // What a measurement records, and what the side file holds: the input from t0 on.
    let inputs = seen_inputs(exp, &truth)?;
    if let Some(k) = sim.y.iter().position(|y| !y.is_finite()) {
        return Err(study_err!(
            "{}: the simulated sample {k} is {} (not a finite number): the experiment's values are outside the range that can be simulated; nothing was written",
            exp.file,
            sim.y[k]
        ));
    }
    let t: Vec<f64> = exp.grid.times().collect();
    let u = inputs
        .iter()
        .map(|i| t.iter().map(|&t| i.value(t)).collect())
        .collect();
    Ok(SimulatedData {
        t,
        y: sim.y,
        u,
        tau: sim.tau,
        v: sim.v,
        inputs,
    })
}
