//! The one place where design reaches into the experiment's input and system: the model
//! signal of one input realisation, built exactly as a Monte Carlo realisation builds the
//! signal its fit sees.
//!
//! Keeping this in one function means that a change to how an experiment holds its inputs
//! (several inputs, say) changes design here and nowhere else.

use crate::error::StudyResult;
use crate::experiment::{Experiment, InputSpec};
use crate::fit::signal_of;
use crate::simulate::{realize_inputs, seen_inputs};
use jitterid::rand::rngs::StdRng;
use jitterid::signal::AnySignal;

/// Whether the experiment's input is drawn anew for every realisation (a random binary
/// input), so that a prediction must average over draws; a fixed input needs one.
pub(crate) fn input_is_random(exp: &Experiment) -> bool {
    exp.random_input()
}

/// The signal a fit of realisation `rng` sees, at the experiment's true system: the input
/// drawn from `rng` as [`realize_inputs`] draws it (the first draw of Monte Carlo run `r`'s
/// stream), cut to what the record sees ([`seen_inputs`]), driving the `[system]` model.
pub(crate) fn realized_signal(exp: &Experiment, rng: &mut StdRng) -> StudyResult<AnySignal> {
    let truth = realize_inputs(exp, rng)?;
    let seen = seen_inputs(exp, &truth)?;
    signal_of(exp, &seen)
}

/// The random binary input's mean dwell (s), `None` for another input or several inputs.
pub(crate) fn mean_dwell_of(exp: &Experiment) -> Option<f64> {
    match exp.inputs.as_slice() {
        [c] => match &c.spec {
            InputSpec::RandomBinary(rb) => Some(rb.mean_dwell()),
            InputSpec::Known(_) => None,
        },
        _ => None,
    }
}

/// The random binary input's levels `(low, high)`, `None` for another input or several
/// inputs.
pub(crate) fn levels_of(exp: &Experiment) -> Option<(f64, f64)> {
    match exp.inputs.as_slice() {
        [c] => match &c.spec {
            InputSpec::RandomBinary(rb) => Some((rb.low(), rb.high())),
            InputSpec::Known(_) => None,
        },
        _ => None,
    }
}

/// The multisine input's tones, `None` for another input or several inputs.
pub(crate) fn tones_of(exp: &Experiment) -> Option<Vec<jitterid::signal::Tone>> {
    match exp.inputs.as_slice() {
        [c] => match &c.spec {
            InputSpec::Known(jitterid::signal::Input::Tones(m)) => Some(m.tones().to_vec()),
            _ => None,
        },
        _ => None,
    }
}
