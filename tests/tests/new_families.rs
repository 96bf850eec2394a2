//! The periodic and sum jitter families fitted end to end through the registry's run-time type:
//! simulate with the true law, fit its parameters by BCLS with the system known (the JOE
//! structure with the jitter estimated), and check that the Monte Carlo mean is within 3
//! standard errors (`se = std/√R`, R runs) of the truth.

use jitterid::estimate::montecarlo::{realization_rng, Summary};
use jitterid::estimate::{fit, Bcls, FitOptions, ModelStructure, Record};
use jitterid::jitter::registry::JitterRegistry;
use jitterid::jitter::serde_json::{self, json};
use jitterid::jitter::AnyJitter;
use jitterid::prelude::*;
use rand::Rng;

const RUNS: u64 = 32;

fn build(spec: serde_json::Value) -> AnyJitter {
    let spec = spec.as_object().cloned().expect("a table");
    JitterRegistry::builtin().build(&spec).expect("valid spec")
}

/// Sampling of the records: interval `T` (s), number of samples, mean dwell of the input (s).
struct Design {
    interval: f64,
    samples: usize,
    dwell: f64,
}

/// Fits `truth`'s parameters from a start perturbed by ±20 %, over `RUNS` records of the
/// response of `2/(s + 2)` to a random binary input; returns the estimates per parameter.
fn monte_carlo(truth: &AnyJitter, design: &Design, seed: u64) -> Vec<Summary> {
    let p = truth.params();
    let mut est: Vec<Vec<f64>> = vec![Vec::new(); p.len()];
    for r in 0..RUNS {
        let mut rng = realization_rng(seed, r);
        let end = design.interval * design.samples as f64 + 2.0;
        let input = RandomBinary::new(design.dwell, 0.0, 1.0)
            .unwrap()
            .generate(-2.0, end, &mut rng)
            .unwrap();
        let g = Zpk::new(2.0, vec![], vec![Root::Real(-2.0)]).unwrap();
        let grid = SampleGrid::new(0.0, design.interval, design.samples).unwrap();
        let signal = LtiResponse::new(g, input);
        let data = simulate(&signal, truth, &grid, 0.01, &mut rng).unwrap();
        let start: Vec<f64> = p
            .iter()
            .map(|x| x * (1.0 + rng.random_range(-0.2..=0.2)))
            .collect();
        let start = truth.with_params(&start).unwrap();
        let structure = ModelStructure::joe(signal, start).with_estimated(false, true, false);
        let e = fit(
            &structure,
            &Record::new(grid, data.y).unwrap(),
            &Bcls,
            &FitOptions::default(),
        )
        .unwrap();
        assert!(e.converged, "run {r}: {}", e.termination);
        for (k, x) in e.params.iter().enumerate() {
            est[k].push(*x);
        }
    }
    est.into_iter().map(|v| v.into_iter().collect()).collect()
}

fn assert_unbiased(truth: &AnyJitter, summaries: &[Summary]) {
    for ((name, t), s) in truth
        .param_names()
        .iter()
        .zip(truth.params())
        .zip(summaries)
    {
        println!(
            "{name}: truth {t}, mean {:.5}, se {:.5}, std {:.5}",
            s.mean,
            s.se(),
            s.std()
        );
        assert!(
            (s.mean - t).abs() <= 3.0 * s.se(),
            "{name}: mean {} ± {} (se), truth {t}",
            s.mean,
            s.se()
        );
        assert!(s.std() < 0.5 * t, "{name} is informative: std {}", s.std());
    }
}

#[test]
fn periodic_jitter_is_fitted_without_bias() {
    let truth = build(json!({"family": "periodic", "amplitude": 0.3}));
    let design = Design {
        interval: 1.0,
        samples: 400,
        dwell: 2.0,
    };
    let s = monte_carlo(&truth, &design, 41);
    assert_unbiased(&truth, &s);
}

#[test]
fn dual_dirac_sum_is_fitted_without_bias() {
    let truth = build(json!({"family": "sum", "terms": [
        {"family": "gaussian", "sigma": 0.1},
        {"family": "two-point", "d": 0.3},
    ]}));
    assert_eq!(truth.param_names(), vec!["terms.0.sigma", "terms.1.d"]);
    // Below 0.5 Hz, γ = e^{-2π²σ²f²} cos(2πfd) hardly separates σ from d (both enter as
    // σ² + d² to second order in f): sample faster so that the first moment reaches 2 Hz.
    let design = Design {
        interval: 0.25,
        samples: 800,
        dwell: 0.5,
    };
    let s = monte_carlo(&truth, &design, 43);
    assert_unbiased(&truth, &s);
}
