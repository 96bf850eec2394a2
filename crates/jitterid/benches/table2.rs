//! The paper's Table 2 setup (T = 1 s, N = 200, second-order system, random binary input with
//! mean dwell 8 s, uniform-sum jitter n = 2, a = 1/(2√3)): `s(t)`, `μ_Y` on the full grid by
//! both routes, and one BCLS fit from a perturbed start.
//!
//! `cargo bench -p jitterid --bench table2`

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid::estimate::{fit, Bcls, FitOptions, ModelStructure, Record};
use jitterid::prelude::*;
use jitterid::window::{
    first_moment, first_moment_integral, DirichletWindow, FrequencySet, IntegralOptions,
};
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

fn setup() -> (LtiResponse<Zpk>, UniformSum, SampleGrid, Vec<f64>) {
    // Seed 4 gives 26 steps (the paper's input has about 25 switches in 200 s).
    let mut rng = rand::rngs::StdRng::seed_from_u64(4);
    let u = RandomBinary::paper()
        .generate(0.0, 201.0, &mut rng)
        .unwrap();
    let signal = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3), u);
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let y = simulate(&signal, &jitter, &grid, 0.01, &mut rng).unwrap().y;
    (signal, jitter, grid, y)
}

fn benches(c: &mut Criterion) {
    let (signal, jitter, grid, y) = setup();
    let steps = signal.steps().len();
    let freqs = FrequencySet::dft(&grid);
    c.bench_function(
        &format!("table2/s(t) at 200 instants ({steps} steps)"),
        |b| {
            b.iter(|| {
                grid.times()
                    .map(|t| signal.value(black_box(t)))
                    .sum::<f64>()
            })
        },
    );
    c.bench_function("table2/m_k (time-domain expectation)", |b| {
        b.iter(|| signal.expected_values(black_box(&grid), &jitter))
    });
    c.bench_function("table2/mu_Y route (b): m_k + FFT, 101 frequencies", |b| {
        b.iter(|| first_moment(&signal, &jitter, black_box(&grid), &DirichletWindow, &freqs))
    });
    c.bench_function("table2/dm_k/dtheta (4 parameters)", |b| {
        b.iter(|| signal.expected_values_gradient(black_box(&grid), &jitter))
    });
    let mut slow = c.benchmark_group("table2-slow");
    slow.sample_size(10);
    slow.bench_function("mu_Y route (a): frequency integral, 101 frequencies", |b| {
        b.iter(|| {
            first_moment_integral(
                &signal,
                &jitter,
                black_box(&grid),
                &DirichletWindow,
                &freqs,
                &IntegralOptions::default(),
            )
            .unwrap()
        })
    });
    slow.finish();

    let record = Record::new(grid, y).unwrap();
    let start = LtiResponse::new(eq17(0.21, 0.45, -0.27, 0.33), signal.input().clone());
    let structure = ModelStructure::oe(start, jitter);
    let with_cov = FitOptions::default();
    let no_cov = FitOptions::default().with_covariance(false);
    c.bench_function("table2/BCLS fit from a perturbed start", |b| {
        b.iter(|| fit(&structure, &record, &Bcls, &no_cov).unwrap())
    });
    c.bench_function("table2/BCLS fit + sandwich covariance", |b| {
        b.iter(|| fit(&structure, &record, &Bcls, &with_cov).unwrap())
    });
}

criterion_group!(table2, benches);
criterion_main!(table2);
