//! What the tests of the wrappers around a response share (an output offset, an input level):
//! the jitter laws and grid their contract is checked on, and the response they wrap.

use jitterid_jitter::{Gaussian, JitterModel, NoJitter, TwoPoint, UniformSum};
use jitterid_signal::testing::{binary, check_contract, eq17};
use jitterid_signal::{LtiResponse, PiecewiseConstant, SampleGrid, Signal, Zpk};

/// No jitter, a uniform sum, a Gaussian and an atomic law.
pub fn jitters() -> Vec<Box<dyn JitterModel>> {
    vec![
        Box::new(NoJitter::new()),
        Box::new(UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap()),
        Box::new(Gaussian::new(0.17).unwrap()),
        Box::new(TwoPoint::new(0.13).unwrap()),
    ]
}

/// `T = 1 s`, 30 samples from 0.
pub fn grid() -> SampleGrid {
    SampleGrid::new(0.0, 1.0, 30).unwrap()
}

/// The paper's input (mean dwell 8 s) on `[−5, 35)`.
pub fn input() -> PiecewiseConstant {
    binary(4, 8.0, -5.0, 35.0).unwrap()
}

/// Table 2's system driven by [`input`].
pub fn response() -> LtiResponse<Zpk> {
    LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), input())
}

/// The signal contract of `signal` under every law of [`jitters`] on [`grid`], the law `i`
/// with the Monte Carlo seed `seed + i`.
pub fn check_all<S: Signal + Clone>(signal: &S, seed: u64) {
    for (i, j) in jitters().iter().enumerate() {
        check_contract(signal, j.as_ref(), &grid(), seed + i as u64)
            .unwrap_or_else(|e| panic!("{}: {e}", j.name()));
    }
}
