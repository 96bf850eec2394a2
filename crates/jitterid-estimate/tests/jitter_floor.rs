//! The Box–Jenkins noise model with the jitter's white floor: on Table 2 records with AR(1)
//! measurement noise, the noise coefficient is unbiased with the floor and biased without it.

use jitterid_estimate::{
    estimate, mean_jitter_variance, AnyNoise, ArmaNoise, BoxJenkins, EstimateOptions,
    ModelStructure, NoiseModel, Record,
};
use jitterid_jitter::{NoJitter, UniformSum};
use jitterid_signal::testing::eq17;
use jitterid_signal::{simulate, LtiResponse, RandomBinary, SampleGrid};
use rand::SeedableRng;

/// The AR coefficient of the noise filter `1 / (1 + d q⁻¹)`.
const D1: f64 = -0.6;
/// Records per case: enough that the unfloored bias (about 30 standard errors of the mean at
/// 128 records) stands far outside the tolerance.
const RUNS: u64 = 40;
/// Tolerance on the mean, in Monte Carlo standard errors `sd/√RUNS`: a correct estimator passes
/// with probability above 0.9999 (normal tails), and 4 leaves room for the O(1/N) finite-record
/// bias of a Box–Jenkins estimate at N = 200.
const TOLERANCE_SE: f64 = 4.0;

/// `v = e / (1 + d₁ q⁻¹)`, at rest before the record.
fn ar1(e: &[f64], d1: f64) -> Vec<f64> {
    let mut v = Vec::with_capacity(e.len());
    let mut prev = 0.0;
    for &x in e {
        prev = x - d1 * prev;
        v.push(prev);
    }
    v
}

/// The estimates of `noise.d1` over `RUNS` seeded records, with or without the floor.
fn d1_estimates(with_floor: bool) -> Vec<f64> {
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let mut out = Vec::new();
    for seed in 0..RUNS {
        let mut rng = rand::rngs::StdRng::seed_from_u64(1000 + seed);
        let u = RandomBinary::paper()
            .generate(0.0, 201.0, &mut rng)
            .unwrap();
        let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), u.clone());
        let sim = simulate(&truth, &jitter, &grid, 0.01, &mut rng).unwrap();
        let v = ar1(&sim.noise, D1);
        let y = sim
            .y
            .iter()
            .zip(&sim.noise)
            .zip(&v)
            .map(|((y, e), v)| y - e + v)
            .collect();
        let record = Record::new(grid.clone(), y).unwrap();
        let noise = ArmaNoise::new(Vec::new(), vec![D1]).unwrap();
        let s = ModelStructure::bj(truth, jitter.clone(), noise);
        let s = if with_floor {
            s.with_jitter_floor(&grid, Some(0.01)).unwrap()
        } else {
            ModelStructure::bj(s.signal, s.jitter, AnyNoise::new(s.noise))
        };
        assert_eq!(s.noise.floor() > 0.0, with_floor);
        let fit = estimate(&s, &record, &BoxJenkins, &EstimateOptions::default()).unwrap();
        let i = fit.names.iter().position(|n| n == "noise.d1").unwrap();
        out.push(fit.params[i]);
    }
    out
}

fn mean_and_se(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn the_floor_removes_the_noise_models_bias() {
    let (mean, se) = mean_and_se(&d1_estimates(true));
    assert!(
        (mean - D1).abs() < TOLERANCE_SE * se,
        "with the floor: mean d1 {mean} vs {D1}, se {se}"
    );
    let (mean, se) = mean_and_se(&d1_estimates(false));
    assert!(
        (mean - D1).abs() > TOLERANCE_SE * se,
        "without the floor the bias should show: mean d1 {mean} vs {D1}, se {se}"
    );
}

#[test]
fn the_floor_start_is_the_jitter_variance_over_the_noise_level() {
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let u = jitterid_signal::testing::binary(3, 8.0, 0.0, 201.0).unwrap();
    let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), u);
    let lambda = mean_jitter_variance(&truth, &jitter, &grid);
    assert!(lambda > 0.0);
    let arma = ModelStructure::bj(
        truth.clone(),
        jitter.clone(),
        ArmaNoise::new(vec![], vec![D1]).unwrap(),
    );
    let rho = arma.jitter_floor_start(&grid, Some(0.01)).unwrap();
    assert!((rho - lambda / 1e-4).abs() <= 1e-12 * rho);
    assert_eq!(arma.jitter_floor_start(&grid, None), Some(1.0));
    let floored = arma.with_jitter_floor(&grid, Some(0.01)).unwrap();
    assert_eq!(
        floored.param_names().last().map(String::as_str),
        Some("noise.log_floor")
    );
    // Nothing to add to a floored shape, to white noise, or without jitter.
    assert_eq!(floored.jitter_floor_start(&grid, Some(0.01)), None);
    let white = ModelStructure::oe(truth.clone(), jitter);
    assert_eq!(white.jitter_floor_start(&grid, Some(0.01)), None);
    let s = ModelStructure::bj(
        truth,
        NoJitter::new(),
        ArmaNoise::new(vec![], vec![D1]).unwrap(),
    );
    assert_eq!(s.jitter_floor_start(&grid, Some(0.01)), None);
}
