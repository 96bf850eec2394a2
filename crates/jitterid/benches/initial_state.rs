//! The cost of estimating the initial state: one BCLS fit of the Table 2 system (N = 200,
//! uniform-sum jitter n = 2) with the model from rest and with the free response's 2
//! coefficients estimated too (target ≤ 1.5×).
//!
//! A fit's time is its number of Levenberg–Marquardt iterations times the cost of one
//! evaluation, so the bench times both parts:
//!
//! * `BCLS fit, …`: the record whose input started 50 s before `t0` (the model from rest
//!   converges to a biased point there, in a different number of iterations);
//! * `BCLS fit (input from t0), …`: a record whose input started at `t0`, where both models
//!   describe the data and converge to the same point: the like-for-like fit;
//! * `one evaluation, …`: the jittered mean and its gradient on the grid
//!   (`expected_values_and_gradient`), what each iteration asks of the signal.
//!
//! The iterations of each fit are printed once before the timings.
//!
//! `cargo bench -p jitterid --bench initial_state`

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid::estimate::{fit, Bcls, FitOptions, ModelStructure, Record};
use jitterid::prelude::*;
use jitterid::signal::{PiecewiseConstant, WithInitialState};
use rand::SeedableRng;
use std::hint::black_box;

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
    let options = FitOptions::default().with_covariance(false);
    let at_rest = ModelStructure::oe(start.clone(), jitter);
    let with_state = WithInitialState::at_rest(start.clone(), 0.0).unwrap();
    let free = ModelStructure::oe(with_state.clone(), jitter);

    // The same system driven by an input that starts at t0: no history, so the free
    // response is zero at the truth and both models fit the same point.
    let fresh = RandomBinary::paper()
        .generate(0.0, 201.0, &mut rng)
        .unwrap();
    let fresh_truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3), fresh.clone());
    let fresh_y = simulate(&fresh_truth, &jitter, &grid, 0.01, &mut rng)
        .unwrap()
        .y;
    let fresh_record = Record::new(grid, fresh_y).unwrap();
    let fresh_start = LtiResponse::new(eq17(0.21, 0.45, -0.27, 0.33), fresh);
    let fresh_rest = ModelStructure::oe(fresh_start.clone(), jitter);
    let fresh_free =
        ModelStructure::oe(WithInitialState::at_rest(fresh_start, 0.0).unwrap(), jitter);

    for (name, iterations) in [
        (
            "history, model from rest",
            fit(&at_rest, &record, &Bcls, &options).unwrap().iterations,
        ),
        (
            "history, initial state estimated",
            fit(&free, &record, &Bcls, &options).unwrap().iterations,
        ),
        (
            "input from t0, model from rest",
            fit(&fresh_rest, &fresh_record, &Bcls, &options)
                .unwrap()
                .iterations,
        ),
        (
            "input from t0, initial state estimated",
            fit(&fresh_free, &fresh_record, &Bcls, &options)
                .unwrap()
                .iterations,
        ),
    ] {
        eprintln!("LM iterations, {name}: {iterations}");
    }

    let mut g = c.benchmark_group("initial-state");
    g.bench_function("BCLS fit, model from rest", |b| {
        b.iter(|| fit(&at_rest, &record, &Bcls, &options).unwrap())
    });
    g.bench_function("BCLS fit, initial state estimated", |b| {
        b.iter(|| fit(&free, &record, &Bcls, &options).unwrap())
    });
    g.bench_function("BCLS fit (input from t0), model from rest", |b| {
        b.iter(|| fit(&fresh_rest, &fresh_record, &Bcls, &options).unwrap())
    });
    g.bench_function("BCLS fit (input from t0), initial state estimated", |b| {
        b.iter(|| fit(&fresh_free, &fresh_record, &Bcls, &options).unwrap())
    });
    g.bench_function("one evaluation, model from rest", |b| {
        b.iter(|| black_box(&start).expected_values_and_gradient(&grid, &jitter))
    });
    g.bench_function("one evaluation, initial state estimated", |b| {
        b.iter(|| black_box(&with_state).expected_values_and_gradient(&grid, &jitter))
    });
    g.finish();
}

criterion_group!(initial_state, benches);
criterion_main!(initial_state);
