//! BCLS cost against the record length: one residual + Jacobian evaluation and one fit
//! of the Table 2 system for `N` = 200, 2 000, 20 000, 200 000, with the random binary input's
//! mean dwell fixed at 8 s so that the number of input steps grows like `N`.
//!
//! `cargo bench -p jitterid --bench scale` (about three minutes). `cargo xtask scale` prints the
//! same sweep as a table, with `N = 10^6` and the peak memory.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use jitterid::estimate::{fit, Bcls, FitOptions, FrequencyData, ModelStructure, Record};
use jitterid::prelude::*;
use jitterid::window::{DirichletWindow, FrequencySet};
use rand::SeedableRng;
use std::hint::black_box;
use std::time::Duration;

fn eq17(k0: f64, z: f64, pr: f64, pi: f64) -> Zpk {
    Zpk::new(
        k0,
        vec![Root::Real(-z)],
        vec![Root::Pair { re: pr, im: pi }],
    )
    .unwrap()
}

type Setup = (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record);

fn setup(n: usize) -> Setup {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7 + n as u64);
    let u = RandomBinary::new(8.0, 0.0, 1.0)
        .unwrap()
        .generate(0.0, n as f64 + 1.0, &mut rng)
        .unwrap();
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, n).unwrap();
    let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3), u.clone());
    let y = simulate(&truth, &jitter, &grid, 0.01, &mut rng).unwrap().y;
    let record = Record::new(grid, y).unwrap();
    let start = LtiResponse::new(eq17(0.21, 0.45, -0.27, 0.33), u);
    (ModelStructure::oe(start, jitter), record)
}

fn benches(c: &mut Criterion) {
    let no_cov = FitOptions::default().with_covariance(false);
    let mut group = c.benchmark_group("scale");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    for n in [200usize, 2_000, 20_000, 200_000] {
        let (structure, record) = setup(n);
        let data = FrequencyData::new(
            record.clone(),
            DirichletWindow,
            FrequencySet::dft(record.grid()),
        )
        .unwrap();
        group.bench_with_input(BenchmarkId::new("residual+jacobian", n), &n, |b, _| {
            b.iter(|| {
                let r = black_box(&data).residuals(&Bcls, &structure);
                let j = data.jacobian(&Bcls, &structure);
                (r, j)
            })
        });
        group.bench_with_input(BenchmarkId::new("fit", n), &n, |b, _| {
            b.iter(|| fit(&structure, black_box(&record), &Bcls, &no_cov).unwrap())
        });
    }
    group.finish();
}

criterion_group!(scale, benches);
criterion_main!(scale);
