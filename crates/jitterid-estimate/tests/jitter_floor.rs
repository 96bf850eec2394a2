//! The Box–Jenkins noise model with the jitter's white floor: on Table 2 records with AR(1)
//! measurement noise, the noise level and the AR coefficient of the default fit (the floor, then
//! the exact restricted likelihood of the noise parameters in time) are unbiased, and the AR
//! coefficient's bias towards white noise is much smaller than without the floor.

use jitterid_estimate::{
    fit, mean_jitter_variance, ArmaNoise, BoxJenkins, FitOptions, ModelStructure, NoiseModel,
    Record,
};
use jitterid_jitter::{NoJitter, UniformSum};
use jitterid_signal::testing::eq17;
use jitterid_signal::{simulate, LtiResponse, RandomBinary, SampleGrid};
use rand::SeedableRng;

/// The AR coefficient of the noise filter `1 / (1 + d q⁻¹)`.
const D1: f64 = -0.6;
/// The white noise's standard deviation.
const SIGMA_E: f64 = 0.01;
/// Records fitted with the floor: the Monte Carlo standard error of the mean of `noise.d1` is
/// then about 0.006 (its spread over records about 0.07), that of the noise level about
/// 0.00006.
const RUNS: u64 = 128;
/// Records fitted without the floor: the bias there (about 0.23) is about 16 standard errors
/// of a 24-record mean.
const RUNS_WITHOUT: u64 = 24;
/// A mean further than this many Monte Carlo standard errors (`sd/√runs`) from the truth counts
/// as biased: for an unbiased estimator the mean over the records is normal to a good
/// approximation (central limit theorem), so a correct implementation fails with probability
/// 0.0027 per parameter at 3, and with fixed seeds the outcome is reproducible.
const UNBIASED_SE: f64 = 3.0;
/// Margin, in Monte Carlo standard errors of a difference of means, by which the floor must
/// reduce the bias (a false positive has probability below 0.0001).
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

/// The estimates of `noise.d1` and of `σ_e` over `runs` seeded records, with or without the
/// floor.
fn noise_estimates(with_floor: bool, runs: u64) -> (Vec<f64>, Vec<f64>) {
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let (mut d1, mut std) = (Vec::new(), Vec::new());
    for seed in 0..runs {
        let mut rng = rand::rngs::StdRng::seed_from_u64(1000 + seed);
        let u = RandomBinary::paper()
            .generate(0.0, 201.0, &mut rng)
            .unwrap();
        let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), u.clone());
        let sim = simulate(&truth, &jitter, &grid, SIGMA_E, &mut rng).unwrap();
        let v = ar1(&sim.noise, D1);
        let y = sim
            .y
            .iter()
            .zip(&sim.noise)
            .zip(&v)
            .map(|((y, e), v)| y - e + v)
            .collect();
        let record = Record::new(grid, y).unwrap();
        let noise = ArmaNoise::new(Vec::new(), vec![D1]).unwrap();
        let s = ModelStructure::bj(truth, jitter, noise);
        let options = FitOptions::default();
        let fit = if with_floor {
            let (fit, fitted) = s
                .fit_with_jitter_floor(&record, Some(SIGMA_E), |floored| {
                    fit(floored, &record, &BoxJenkins, &options)
                })
                .unwrap();
            assert!(fitted.noise.floor() > 0.0);
            fit
        } else {
            fit(&s, &record, &BoxJenkins, &options).unwrap()
        };
        let i = fit.names.iter().position(|n| n == "noise.d1").unwrap();
        d1.push(fit.params[i]);
        std.push(fit.noise_std);
    }
    (d1, std)
}

fn mean_and_se(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn the_floor_and_the_restricted_likelihood_make_the_noise_parameters_unbiased() {
    let (d1, std) = noise_estimates(true, RUNS);
    let (d1_with, se_with) = mean_and_se(&d1);
    let (std_mean, std_se) = mean_and_se(&std);
    // The noise parameters come from the exact restricted likelihood in time: both are held
    // to the unbiased tolerance.
    assert!(
        (std_mean - SIGMA_E).abs() <= UNBIASED_SE * std_se,
        "with the floor: mean noise std {std_mean} vs {SIGMA_E}, se {std_se}"
    );
    assert!(
        (d1_with - D1).abs() <= UNBIASED_SE * se_with,
        "with the floor: mean d1 {d1_with} vs {D1}, se {se_with}"
    );
    // Without the floor the ARMA shape absorbs the jitter's white noise and d1 is pulled
    // towards 0 (white); with it, the pull is smaller by several standard errors of the
    // difference of the two means.
    let (without, se_without) = mean_and_se(&noise_estimates(false, RUNS_WITHOUT).0);
    let se = (se_with * se_with + se_without * se_without).sqrt();
    assert!(
        without - D1 > TOLERANCE_SE * se_without,
        "without the floor the bias should show: mean d1 {without} vs {D1}, se {se_without}"
    );
    assert!(
        (without - D1) - (d1_with - D1).abs() > TOLERANCE_SE * se,
        "with the floor: mean d1 {d1_with} (se {se_with}); without: {without} (se {se_without})"
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
        jitter,
        ArmaNoise::new(vec![], vec![D1]).unwrap(),
    );
    let rho = arma.jitter_floor_start(&grid, Some(0.01)).unwrap();
    assert!((rho - lambda / 1e-4).abs() <= 1e-12 * rho);
    assert_eq!(arma.jitter_floor_start(&grid, None), Some(1.0));
    let floored = arma.clone().with_jitter_floor(&grid, Some(0.01)).unwrap();
    // A known floor: no new parameter.
    assert_eq!(floored.param_names(), arma.param_names());
    assert!((floored.noise.floor() - rho).abs() <= 1e-12 * rho);
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
