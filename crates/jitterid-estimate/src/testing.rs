//! Contract checks that every first-moment [`Criterion`] must pass.
//!
//! Run [`check_criterion`] in a test of any new criterion (see `docs/extending.md`), as
//! `jitterid_jitter::testing::check_contract` is run on every jitter family:
//!
//! ```
//! use jitterid_estimate::testing::{check_criterion, check_criterion_on, CriterionFixture};
//! use jitterid_estimate::{Bcls, WeightedBcls};
//!
//! check_criterion(&Bcls, 1).unwrap();
//! // A criterion that needs the frequency set (one user weight per frequency):
//! let fixture = CriterionFixture::new(1);
//! let n = fixture.frequencies().len();
//! let weighted = WeightedBcls::new((0..n).map(|i| 0.3 + (i % 5) as f64).collect()).unwrap();
//! check_criterion_on(&weighted, &fixture).unwrap();
//! ```
//!
//! The fixture ([`CriterionFixture`]) is a seeded simulation of the paper's eq. (17) system
//! driven by a random binary input, with uniform-sum jitter and an AR(1) noise model, sampled
//! 200 times (the 101 frequencies of the DFT grid, rectangular window); every part of the
//! structure is estimated (a JBJ structure). It holds two records of the same truth: one with
//! white measurement noise, one with noise coloured by the structure's AR(1) shape.
//!
//! The checks, on both records:
//!
//! * `name()` is non-empty and the same at every call; `validate` accepts the frequency set;
//! * the weights at the true parameters are one per frequency, finite, `≥ 0`, not all zero,
//!   and the same at every call;
//! * what the criterion declares its weights independent of does not move them: unless
//!   [`model_dependent_weights`](Criterion::model_dependent_weights), the weights at other
//!   signal and jitter parameters are identical; unless
//!   [`uses_noise_model`](Criterion::uses_noise_model), the weights with another noise shape
//!   are identical;
//! * the cost through the crate ([`FrequencyData::cost`]) equals `½ Σ_f w_f |Y(f) − μ_Y(f)|²`
//!   computed here from the weights and from `μ_Y`, the windowed transform of the first moment
//!   `m_k` taken with the structure's jitter (or without it, unless
//!   [`models_jitter`](Criterion::models_jitter)), at the truth and away from it;
//! * if the criterion claims [`flat_residuals`](Criterion::flat_residuals), the weighted
//!   residuals at the truth pass [`residual_flatness`] below [`FLATNESS_LIMIT`]: on the record
//!   with noise of the structure's shape for a criterion that uses the noise model, on the white
//!   record otherwise (a criterion that ignores the noise model can only promise flat residuals
//!   for white noise). A correct criterion fails this with probability below `10⁻⁶` (25
//!   frequencies per band; see [`FLATNESS_LIMIT`]).

use crate::criterion::Criterion;
use crate::data::Record;
use crate::flatness::{residual_flatness, FLATNESS_LIMIT};
use crate::frequency_data::FrequencyData;
use crate::noise::{ArmaNoise, NoiseModel};
use crate::structure::ModelStructure;
use jitterid_jitter::{JitterModel, NoJitter, UniformSum};
use jitterid_signal::testing::{binary, eq17};
use jitterid_signal::{simulate, LtiResponse, SampleGrid, Signal, Zpk};
use jitterid_window::{transform, DirichletWindow, FrequencySet, Window};
use num_complex::Complex64;
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::fmt::Write as _;

/// Number of samples of the fixture's records (so `N/2 + 1 = 101` frequencies).
pub const FIXTURE_SAMPLES: usize = 200;

/// The AR coefficient `d₁` of the fixture's noise shape `|1/(1 + d₁ e^{-i2πfT})|²`.
pub const FIXTURE_AR: f64 = -0.6;

/// Standard deviation of the fixture's white measurement noise (the innovation of the
/// coloured one).
pub const FIXTURE_NOISE_STD: f64 = 0.05;

/// Relative tolerance of the cost computed through the crate against the one computed here.
const COST_TOL: f64 = 1e-10;

/// The model structure of the fixture: eq. (17), uniform-sum jitter, ARMA noise shape.
pub type FixtureStructure = ModelStructure<LtiResponse<Zpk>, UniformSum, ArmaNoise>;

/// A seeded simulated record (two, in fact) and the structure that generated it, on which
/// [`check_criterion_on`] holds a criterion to its contract. See the module docs.
#[derive(Debug, Clone)]
pub struct CriterionFixture {
    truth: FixtureStructure,
    white: FrequencyData<DirichletWindow>,
    coloured: FrequencyData<DirichletWindow>,
}

impl CriterionFixture {
    /// The fixture drawn from `StdRng::seed_from_u64(seed)` (the input from `seed` too).
    ///
    /// # Panics
    ///
    /// Never for any seed: every part is built from valid constants.
    pub fn new(seed: u64) -> Self {
        let input = binary(seed, 8.0, -60.0, FIXTURE_SAMPLES as f64 + 1.0).expect("valid input");
        let signal = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).expect("valid system"), input);
        let jitter = UniformSum::new(2, 0.1).expect("valid jitter");
        let noise = ArmaNoise::new(vec![], vec![FIXTURE_AR]).expect("valid noise shape");
        let truth = ModelStructure::jbj(signal, jitter, noise);
        let grid = SampleGrid::new(0.0, 1.0, FIXTURE_SAMPLES).expect("valid grid");
        let mut rng = StdRng::seed_from_u64(seed);
        let sim = simulate(
            &truth.signal,
            &truth.jitter,
            &grid,
            FIXTURE_NOISE_STD,
            &mut rng,
        )
        .expect("valid simulation");
        // AR(1): v_k = e_k − d₁ v_{k−1}, started in its stationary law.
        let mut coloured_noise = Vec::with_capacity(sim.noise.len());
        let mut v = sim.noise[0] / (1.0 - FIXTURE_AR * FIXTURE_AR).sqrt();
        coloured_noise.push(v);
        for e in &sim.noise[1..] {
            v = e - FIXTURE_AR * v;
            coloured_noise.push(v);
        }
        let coloured_y: Vec<f64> = sim
            .y
            .iter()
            .zip(&sim.noise)
            .zip(&coloured_noise)
            .map(|((y, e), v)| y - e + v)
            .collect();
        let freqs = FrequencySet::dft(&grid);
        let data = |y: Vec<f64>| {
            FrequencyData::new(
                Record::new(grid, y).expect("finite samples"),
                DirichletWindow,
                freqs.clone(),
            )
            .expect("valid transform")
        };
        Self {
            white: data(sim.y),
            coloured: data(coloured_y),
            truth,
        }
    }

    /// The true structure (every part estimated).
    pub fn truth(&self) -> &FixtureStructure {
        &self.truth
    }

    /// The frequency set of both records (the DFT grid of [`FIXTURE_SAMPLES`] samples).
    pub fn frequencies(&self) -> &FrequencySet {
        self.white.frequencies()
    }

    /// The record with white measurement noise.
    pub fn white(&self) -> &FrequencyData<DirichletWindow> {
        &self.white
    }

    /// The record with measurement noise of the structure's AR(1) shape.
    pub fn coloured(&self) -> &FrequencyData<DirichletWindow> {
        &self.coloured
    }

    /// The truth with its signal and jitter parameters moved (by 5% and 20%), its noise shape
    /// kept.
    fn moved_model(&self) -> FixtureStructure {
        let (ns, nj, _) = self.truth.blocks();
        let p: Vec<f64> = self
            .truth
            .params()
            .iter()
            .enumerate()
            .map(|(j, &x)| {
                if j < ns {
                    x * 1.05
                } else if j < ns + nj {
                    x * 1.2
                } else {
                    x
                }
            })
            .collect();
        self.truth.with_params(&p).expect("valid moved parameters")
    }

    /// The truth with another noise shape (`d₁ = 0.3`, a high-pass shape).
    fn other_noise(&self) -> FixtureStructure {
        let mut m = self.truth.clone();
        m.noise = self
            .truth
            .noise
            .with_params(&[0.3])
            .expect("valid noise shape");
        m
    }
}

/// Runs [`check_criterion_on`] on [`CriterionFixture::new(seed)`](CriterionFixture::new).
///
/// # Errors
///
/// Every broken promise, one per line, after a first line naming the criterion.
pub fn check_criterion<C: Criterion + ?Sized>(criterion: &C, seed: u64) -> Result<(), String> {
    check_criterion_on(criterion, &CriterionFixture::new(seed))
}

/// Holds `criterion` to the contract of the [`Criterion`] trait on `fixture` (the checks are
/// listed in the module docs).
///
/// # Errors
///
/// Every broken promise, one per line, after a first line naming the criterion.
pub fn check_criterion_on<C: Criterion + ?Sized>(
    criterion: &C,
    fixture: &CriterionFixture,
) -> Result<(), String> {
    let mut fails = Vec::new();
    let name = criterion.name();
    if name.is_empty() {
        fails.push("name() is empty".to_string());
    }
    if criterion.name() != name {
        fails.push(format!(
            "name() is not stable: {name:?}, then {:?}",
            criterion.name()
        ));
    }
    if let Err(e) = criterion.validate(fixture.frequencies()) {
        fails.push(format!(
            "validate rejects the frequency set the weights are computed for: {e}"
        ));
    }
    let moved = fixture.moved_model();
    let other_noise = fixture.other_noise();
    let mut weights_valid = true;
    for (label, data) in [("white", fixture.white()), ("coloured", fixture.coloured())] {
        let mut fail = |what: String| fails.push(format!("{label} record: {what}"));
        let w = data.weights(criterion, &fixture.truth, None);
        if let Err(e) = check_weights(&w, data.frequencies().len()) {
            fail(format!("weights at the truth: {e}"));
            // The comparisons below would only repeat it.
            weights_valid = false;
            continue;
        }
        let again = data.weights(criterion, &fixture.truth, None);
        if !same(&w, &again) {
            fail("weights differ between two calls at the same parameters".into());
        }
        if !criterion.model_dependent_weights() {
            let at_moved = data.weights(criterion, &moved, None);
            if !same(&w, &at_moved) {
                fail(format!(
                    "model_dependent_weights() is false, but the weights change with the signal's \
                     and the jitter's parameters (first at frequency {})",
                    first_difference(&w, &at_moved)
                ));
            }
        }
        if !criterion.uses_noise_model() {
            let with_other = data.weights(criterion, &other_noise, None);
            if !same(&w, &with_other) {
                fail(format!(
                    "uses_noise_model() is false, but the weights change with the noise \
                     model's shape (first at frequency {})",
                    first_difference(&w, &with_other)
                ));
            }
        }
        for (at, model) in [("the truth", &fixture.truth), ("moved parameters", &moved)] {
            let through_crate = data.cost(criterion, model);
            let here = independent_cost(criterion, data, model);
            let tol = COST_TOL * here.abs();
            if !(through_crate.is_finite() && (through_crate - here).abs() <= tol) {
                fail(format!(
                    "at {at}, FrequencyData::cost is {through_crate}, but ½ Σ w |Y − μ|² from the \
                     weights and the first moment is {here}"
                ));
            }
        }
    }
    if criterion.flat_residuals() && weights_valid {
        let (label, data) = if criterion.uses_noise_model() {
            ("coloured", fixture.coloured())
        } else {
            ("white", fixture.white())
        };
        let r = data.residuals(criterion, &fixture.truth);
        match residual_flatness(&r) {
            Some(ratio) if ratio < FLATNESS_LIMIT => {}
            Some(ratio) => fails.push(format!(
                "flat_residuals() is true, but on the {label} record the weighted residuals at the \
                 truth have a band {ratio:.2} times the power of the others (limit {FLATNESS_LIMIT})"
            )),
            None => fails.push(format!(
                "flat_residuals() is true, but on the {label} record the weighted residuals at the \
                 truth have a band of zero or non-finite power"
            )),
        }
    }
    report(criterion, fails)
}

/// One weight per frequency, finite, non-negative, not all zero.
fn check_weights(w: &[f64], frequencies: usize) -> Result<(), String> {
    if w.len() != frequencies {
        return Err(format!(
            "{} weights for {frequencies} frequencies (must be one per frequency)",
            w.len()
        ));
    }
    if let Some((i, v)) = w.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(format!("w[{i}] = {v} is not finite"));
    }
    if let Some((i, v)) = w.iter().enumerate().find(|(_, v)| **v < 0.0) {
        return Err(format!("w[{i}] = {v} is negative"));
    }
    if w.iter().all(|&v| v == 0.0) {
        return Err("all weights are zero".into());
    }
    Ok(())
}

/// Equal to the bit (the same computation must give the same weights).
fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn first_difference(a: &[f64], b: &[f64]) -> String {
    match a
        .iter()
        .zip(b)
        .position(|(x, y)| x.to_bits() != y.to_bits())
    {
        Some(i) => format!("{i}: {} vs {}", a[i], b[i]),
        None => format!("lengths {} vs {}", a.len(), b.len()),
    }
}

/// `½ Σ_f w_f |Y(f) − μ_Y(f)|²`, with `μ_Y` the windowed transform of `m_k = E[s(t_k + τ)]`
/// (with the structure's jitter when the criterion models it) computed here.
fn independent_cost<C, S, J, N, W>(
    criterion: &C,
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
) -> f64
where
    C: Criterion + ?Sized,
    S: Signal,
    J: JitterModel,
    N: NoiseModel,
    W: Window,
{
    let grid = data.record().grid();
    let m = if criterion.models_jitter() {
        model.signal.expected_values(grid, &model.jitter)
    } else {
        model.signal.expected_values(grid, &NoJitter)
    };
    let mu = match transform(grid, data.window(), &m, data.frequencies()) {
        Ok(mu) => mu,
        Err(_) => return f64::NAN,
    };
    // The weights with μ_Y computed by the context itself (the crate's cost hands its own).
    let w = data.weights(criterion, model, None);
    if w.len() != mu.len() {
        return f64::NAN;
    }
    let y: &[Complex64] = data.dtft();
    0.5 * y
        .iter()
        .zip(&mu)
        .zip(&w)
        .map(|((y, mu), w)| w * (y - mu).norm_sqr())
        .sum::<f64>()
}

fn report<C: Criterion + ?Sized>(criterion: &C, fails: Vec<String>) -> Result<(), String> {
    if fails.is_empty() {
        return Ok(());
    }
    let mut msg = format!(
        "criterion `{}` ({criterion:?}) breaks {} contract check(s):",
        criterion.name(),
        fails.len()
    );
    for f in fails {
        let _ = write!(msg, "\n  - {f}");
    }
    Err(msg)
}
