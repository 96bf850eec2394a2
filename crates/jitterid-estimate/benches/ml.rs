//! Exact maximum likelihood:
//!
//! * one Table 1 record (N = 200, `G(s) = 1/(s+2)` known, uniform jitter `a = 1/2`, noise std
//!   0.01 known), with the integer-`n` profile over `n = 0..=9` (target: at most 50 ms median);
//! * one Table 2 record (N = 200, `G(s) = k0(s+z)/((s−pr)² + pi²)` estimated, uniform-sum
//!   jitter `n = 2, a = 1/(2√3)` and noise std 0.01 known), from a start 10 % off the truth
//!   (target: at most 20 ms);
//! * the LS-bias record (N = 1 000, `G(s) = 2(s+1)/((s+1)² + 4)` estimated, about 500 input
//!   switches, uniform jitter `a = 0.35` known), from a start 10 % off (target: at most 1 s),
//!   and one cost-and-gradient evaluation of it.

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_estimate::ml::{
    ml_estimate, ml_profile, ExactMl, LikelihoodObjective, MlOptions, QuasiMl,
};
use jitterid_estimate::{ModelStructure, Objective, Record};
use jitterid_jitter::registry::JitterRegistry;
use jitterid_jitter::UniformSum;
use jitterid_jitter::{JitterError, JitterModel};
use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Signal, Zpk};
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::hint::black_box;

/// The uniform-sum jitter with `n + 1` terms and the standard deviation of `start`, through the
/// registry.
fn keep_std_dev(start: &UniformSum) -> impl Fn(i64) -> Result<UniformSum, JitterError> + Sync {
    let sigma = start.std_dev();
    move |n| {
        let mut spec = serde_json::Map::new();
        spec.insert("n".into(), n.into());
        let j = JitterRegistry::builtin().from_std_dev("uniform-sum", sigma, &spec)?;
        Ok(*j
            .downcast_ref::<UniformSum>()
            .expect("the uniform-sum family holds a UniformSum"))
    }
}

fn table1_setup(seed: u64) -> (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record) {
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

/// A record of a second-order system with its system estimated from a start 10 % off the
/// truth (every parameter scaled by 1.1), jitter and noise level known.
fn system_setup(
    zpk: Zpk,
    mean_dwell: f64,
    jitter: UniformSum,
    samples: usize,
    seed: u64,
) -> (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record) {
    let mut rng = StdRng::seed_from_u64(seed);
    let u = RandomBinary::new(mean_dwell, 0.0, 1.0)
        .unwrap()
        .generate(0.0, samples as f64 + 1.0, &mut rng)
        .unwrap();
    let truth = LtiResponse::new(zpk, u);
    let grid = SampleGrid::new(0.0, 1.0, samples).unwrap();
    let data = simulate(&truth, &jitter, &grid, 0.01, &mut rng).unwrap();
    let record = Record::new(grid, data.y).unwrap();
    let start: Vec<f64> = truth.params().iter().map(|p| 1.1 * p).collect();
    let structure = ModelStructure::oe(truth.with_params(&start).unwrap(), jitter)
        .with_estimated(true, false, false)
        .with_noise_std(0.01)
        .unwrap();
    (structure, record)
}

fn table2_setup() -> (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record) {
    let g = Zpk::new(
        0.2,
        vec![Root::Real(-0.5)],
        vec![Root::Pair { re: -0.25, im: 0.3 }],
    )
    .unwrap();
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    system_setup(g, 8.0, jitter, 200, 21)
}

fn ls_bias_setup() -> (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record) {
    let g = Zpk::new(
        2.0,
        vec![Root::Real(-1.0)],
        vec![Root::Pair { re: -1.0, im: 2.0 }],
    )
    .unwrap();
    let jitter = UniformSum::new(0, 0.35).unwrap();
    system_setup(g, 2.0, jitter, 1000, 1)
}

fn table1(c: &mut Criterion) {
    let (structure, record) = table1_setup(11);
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

fn system(c: &mut Criterion) {
    let opts = MlOptions::default();
    let mut group = c.benchmark_group("system-estimated");
    group.sample_size(10);
    let (structure, record) = table2_setup();
    group.bench_function("table2 record, exact ml", |b| {
        b.iter(|| black_box(ml_estimate(&structure, &record, &ExactMl::default(), &opts).unwrap()))
    });
    let (structure, record) = ls_bias_setup();
    let criterion = ExactMl::default();
    let objective = LikelihoodObjective::new(&structure, &criterion, &record);
    let theta = structure.params();
    group.bench_function("ls-bias record, cost", |b| {
        b.iter(|| black_box(objective.cost(&theta)))
    });
    group.bench_function("ls-bias record, cost and gradient", |b| {
        b.iter(|| black_box(objective.cost_gradient(&theta)))
    });
    group.bench_function("ls-bias record, exact ml", |b| {
        b.iter(|| black_box(ml_estimate(&structure, &record, &criterion, &opts).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, table1, system);
criterion_main!(benches);
