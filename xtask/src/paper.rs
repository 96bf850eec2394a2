//! The common setup of the paper's section 4 (see `docs/method.md`).

use jitterid::estimate::montecarlo::realization_rng;
use jitterid::prelude::*;
use jitterid::signal::PiecewiseConstant;
use rand::rngs::StdRng;
use rand::Rng;

/// Sampling interval (s).
pub const T: f64 = 1.0;
/// Samples per record.
pub const N: usize = 200;
/// Measurement-noise standard deviation.
pub const NOISE_STD: f64 = 0.01;
/// Realisations per case.
pub const RUNS: u64 = 128;

/// The grid `t_k = kT`, `k < n`.
pub fn grid_of(n: usize) -> SampleGrid {
    SampleGrid::new(0.0, T, n).expect("valid constants")
}

/// The paper's grid (`N = 200`).
pub fn grid() -> SampleGrid {
    grid_of(N)
}

/// The random binary input on `[0, nT + 1)`, system at rest before 0.
pub fn input_of(rng: &mut StdRng, mean_dwell: f64, n: usize) -> PiecewiseConstant {
    RandomBinary::new(mean_dwell, 0.0, 1.0)
        .and_then(|b| b.generate(0.0, n as f64 * T + 1.0, rng))
        .expect("valid constants")
}

/// The paper's input on `[0, NT + 1)`.
pub fn input(rng: &mut StdRng, mean_dwell: f64) -> PiecewiseConstant {
    input_of(rng, mean_dwell, N)
}

/// `θ ∘ (1 + U(−r, r))`, componentwise.
pub fn perturb(theta: &[f64], r: f64, rng: &mut StdRng) -> Vec<f64> {
    theta
        .iter()
        .map(|x| x * (1.0 + rng.random_range(-r..=r)))
        .collect()
}

/// The eq. (17) system `k0 (s + z) / ((s − pr)² + pi²)`.
pub fn eq17(k0: f64, z: f64, pr: f64, pi: f64) -> Result<Zpk, jitterid::signal::SignalError> {
    Zpk::new(
        k0,
        vec![Root::Real(-z)],
        vec![Root::Pair { re: pr, im: pi }],
    )
}

/// The generator of realisation `r` (same derivation as the library's Monte Carlo).
pub fn rng(seed: u64, r: u64) -> StdRng {
    realization_rng(seed, r)
}

/// `√(3(n+1))`: the ratio `a/σ` of the uniform-sum family with `n + 1` terms, read from the
/// registry as the half-width of its unit-σ member (`1 · √(3(n+1))`, the same number); NaN
/// for an `n` the family refuses, which every constructor then rejects.
pub fn uniform_sum_ratio(n: i64) -> f64 {
    let mut spec = serde_json::Map::new();
    spec.insert("n".into(), n.into());
    JitterRegistry::builtin()
        .from_std_dev("uniform-sum", 1.0, &spec)
        .map_or(f64::NAN, |j| j.params()[0])
}

/// The start of every `n` of a uniform-sum profile: `n + 1` terms and standard deviation
/// `sigma`.
pub fn uniform_sum_with_std(
    sigma: f64,
) -> impl Fn(i64) -> Result<UniformSum, jitterid::jitter::JitterError> + Sync {
    move |n| UniformSum::new(n as u32, sigma * uniform_sum_ratio(n))
}

/// `σ = a/√(3(n+1))` of a uniform sum (and the same scaling of a standard error of `a`).
pub fn uniform_sum_sigma(n: i64, a: f64) -> f64 {
    a / uniform_sum_ratio(n)
}
