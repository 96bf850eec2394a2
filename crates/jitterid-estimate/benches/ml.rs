//! Exact maximum likelihood for one Table 1 record (N = 200, `G(s) = 1/(s+2)` known, uniform
//! jitter `a = 1/2`, noise std 0.01 known), with the integer-`n` profile over `n = 0..=9`.
//! Target (issue 4): at most 50 ms median.

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_estimate::ml::{ml_estimate, ml_profile, ExactMl, MlOptions, QuasiMl};
use jitterid_estimate::{ModelStructure, Record};
use jitterid_jitter::UniformSum;
use jitterid_jitter::{JitterError, JitterModel};
use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::hint::black_box;

/// The uniform-sum jitter with `n` terms and the standard deviation of `start`.
fn keep_std_dev(start: &UniformSum) -> impl Fn(i64) -> Result<UniformSum, JitterError> + Sync {
    let sigma = start.std_dev();
    move |n| UniformSum::new(n as u32, sigma * (3.0 * (n as f64 + 1.0)).sqrt())
}

fn setup(seed: u64) -> (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record) {
    let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let u = RandomBinary::paper()
        .generate(0.0, 201.0, &mut rng)
        .unwrap();
    let signal = LtiResponse::new(g, u);
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let truth = UniformSum::new(0, 0.5).unwrap();
    let data = simulate(&signal, &truth, &grid, 0.01, &mut rng).unwrap();
    let record = Record::new(grid, data.y).unwrap();
    // Start: σ 10% off, n profiled.
    let start = UniformSum::new(0, 1.1 * 0.5).unwrap();
    let structure = ModelStructure::oe(signal, start)
        .with_estimated(false, true, false)
        .with_noise_std(0.01)
        .unwrap();
    (structure, record)
}

fn bench(c: &mut Criterion) {
    let (structure, record) = setup(11);
    let opts = MlOptions::default();
    let mut group = c.benchmark_group("table1-record");
    group.sample_size(30);
    group.bench_function("exact-ml profile n=0..=9", |b| {
        b.iter(|| {
            black_box(
                ml_profile(
                    &structure,
                    &record,
                    &ExactMl::default(),
                    &opts,
                    0..=9,
                    keep_std_dev(&structure.jitter),
                )
                .unwrap(),
            )
        })
    });
    group.bench_function("exact-ml n=0", |b| {
        b.iter(|| black_box(ml_estimate(&structure, &record, &ExactMl::default(), &opts).unwrap()))
    });
    group.bench_function("quasi-ml profile n=0..=9", |b| {
        b.iter(|| {
            black_box(
                ml_profile(
                    &structure,
                    &record,
                    &QuasiMl,
                    &opts,
                    0..=9,
                    keep_std_dev(&structure.jitter),
                )
                .unwrap(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
