//! The cost of estimating the initial state: one BCLS fit of the Table 2 system (N = 200,
//! uniform-sum jitter n = 2) on a record whose input started 50 s before `t0`, with the model
//! from rest and with the free response's 2 coefficients estimated too (target ≤ 1.5×).
//!
//! `cargo bench -p jitterid --bench initial_state`

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid::estimate::{estimate, Bcls, EstimateOptions, ModelStructure, Record};
use jitterid::prelude::*;
use jitterid::signal::{PiecewiseConstant, WithInitialState};
use rand::SeedableRng;

fn eq17(k0: f64, z: f64, pr: f64, pi: f64) -> Zpk {
    Zpk::new(
        k0,
        vec![Root::Real(-z)],
        vec![Root::Pair { re: pr, im: pi }],
    )
    .unwrap()
}

fn benches(c: &mut Criterion) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(4);
    let full = RandomBinary::paper()
        .generate(-50.0, 201.0, &mut rng)
        .unwrap();
    // What a measurement sees: the input from t0 = 0 on.
    let first = full.edges().partition_point(|&e| e <= 0.0);
    let mut edges = vec![0.0];
    edges.extend_from_slice(&full.edges()[first..]);
    let mut levels = vec![full.value(0.0)];
    levels.extend_from_slice(&full.levels()[first..]);
    let seen = PiecewiseConstant::new(edges, levels).unwrap();
    let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3), full);
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let y = simulate(&truth, &jitter, &grid, 0.01, &mut rng).unwrap().y;
    let record = Record::new(grid, y).unwrap();
    let start = LtiResponse::new(eq17(0.21, 0.45, -0.27, 0.33), seen);
    let options = EstimateOptions {
        covariance: false,
        ..EstimateOptions::default()
    };
    let at_rest = ModelStructure::oe(start.clone(), jitter);
    let free = ModelStructure::oe(WithInitialState::at_rest(start, 0.0).unwrap(), jitter);
    let mut g = c.benchmark_group("initial-state");
    g.bench_function("BCLS fit, model from rest", |b| {
        b.iter(|| estimate(&at_rest, &record, &Bcls, &options).unwrap())
    });
    g.bench_function("BCLS fit, initial state estimated", |b| {
        b.iter(|| estimate(&free, &record, &Bcls, &options).unwrap())
    });
    g.finish();
}

criterion_group!(initial_state, benches);
criterion_main!(initial_state);
