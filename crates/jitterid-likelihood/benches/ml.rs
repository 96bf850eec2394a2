//! Exact maximum likelihood:
//!
//! * one Table 1 record (N = 200, `G(s) = 1/(s+2)` known, uniform jitter `a = 1/2`, noise std
//!   0.01 known), with the integer-`n` profile over `n = 0..=9` (target: at most 50 ms median);
//! * one Table 2 record (N = 200, `G(s) = k0(s+z)/((s−pr)² + pi²)` estimated, uniform-sum
//!   jitter `n = 2, a = 1/(2√3)` and noise std 0.01 known), from a start 10 % off the truth
//!   (target: at most 20 ms);
//! * the LS-bias record (N = 1 000, `G(s) = 2(s+1)/((s+1)² + 4)` estimated, about 500 input
//!   switches, uniform jitter `a = 0.35` known), from a start 10 % off (target: at most 1 s),
//!   and one cost-and-gradient evaluation of it;
//! * one likelihood evaluation of the Table 1 record for each `n = 0..=9`, and the profile on
//!   one thread's worth of samples (`parallel: false`);
//! * the sine case (N = 200, Gaussian jitter σ = 0.05): cost, cost and gradient, and the fit,
//!   with the samples in parallel and serially.

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_estimate::{fit, fit_profile, FitOptions, ModelStructure, Objective, Record};
use jitterid_jitter::registry::JitterRegistry;
use jitterid_jitter::{Gaussian, UniformSum};
use jitterid_jitter::{JitterError, JitterModel};
use jitterid_likelihood::{fit_sine, sine_least_squares, ExactMl, LikelihoodObjective, QuasiMl};
use jitterid_signal::{
    simulate, LtiResponse, RandomBinary, Root, SampleGrid, Signal, Sinusoid, Zpk,
};
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
    let opts = FitOptions::default().with_covariance(false);
    let mut group = c.benchmark_group("table1-record");
    group.sample_size(30);
    group.bench_function("exact-ml profile n=0..=9", |b| {
        b.iter(|| {
            black_box(
                fit_profile(
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
        b.iter(|| black_box(fit(&structure, &record, &ExactMl::default(), &opts).unwrap()))
    });
    group.bench_function("quasi-ml profile n=0..=9", |b| {
        b.iter(|| {
            black_box(
                fit_profile(
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
    let opts = FitOptions::default().with_covariance(false);
    let mut group = c.benchmark_group("system-estimated");
    group.sample_size(10);
    let (structure, record) = table2_setup();
    group.bench_function("table2 record, exact ml", |b| {
        b.iter(|| black_box(fit(&structure, &record, &ExactMl::default(), &opts).unwrap()))
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
        b.iter(|| black_box(fit(&structure, &record, &criterion, &opts).unwrap()))
    });
    group.finish();
}

/// The exact likelihood on one thread's worth of samples (`parallel: false`), as the Monte Carlo
/// workers run it.
fn serial() -> ExactMl {
    ExactMl {
        parallel: false,
        ..ExactMl::default()
    }
}

/// One evaluation of the Table 1 record's likelihood for each `n`, and the serial profile.
fn table1_per_n(c: &mut Criterion) {
    let (structure, record) = table1_setup(11);
    let mut group = c.benchmark_group("table1-per-n");
    group.sample_size(20);
    for n in 0u32..=9 {
        let a = 0.5 / 3f64.sqrt() * (3.0 * (n as f64 + 1.0)).sqrt();
        let s = ModelStructure::oe(structure.signal.clone(), UniformSum::new(n, a).unwrap())
            .with_estimated(false, true, false)
            .with_noise_std(0.01)
            .unwrap();
        let e = serial();
        let o = LikelihoodObjective::new(&s, &e, &record);
        // The objective keeps its last few values keyed by the exact bits of θ: every
        // iteration asks for a new θ, a few ulp from the last, so that each one evaluates.
        let mut k = 0u64;
        group.bench_function(format!("exact-ml cost n={n}"), |b| {
            b.iter(|| {
                k += 1;
                let theta = f64::from_bits(a.to_bits() + (k % 1024));
                black_box(o.cost(&[theta]))
            })
        });
    }
    let opts = FitOptions::default().with_covariance(false);
    group.bench_function("exact-ml profile n=0..=9, serial samples", |b| {
        b.iter(|| {
            black_box(
                fit_profile(
                    &structure,
                    &record,
                    &serial(),
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

/// The sine case: cost, cost and gradient, and the fit, parallel and serial samples.
fn sine(c: &mut Criterion) {
    let sine = Sinusoid::new(1.0, 1.78, 0.3).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let jitter = Gaussian::new(0.05).unwrap();
    let mut rng = StdRng::seed_from_u64(40);
    let data = simulate(&sine, &jitter, &grid, 0.01, &mut rng).unwrap();
    let record = Record::new(grid, data.y).unwrap();
    let ls = sine_least_squares(&record).unwrap();
    let structure = ModelStructure::oe(sine, jitter).with_estimated(true, false, false);
    let theta = [1.0, 1.78, 0.3, 0.01];
    let mut group = c.benchmark_group("sine");
    group.sample_size(10);
    for (name, e) in [("parallel", ExactMl::default()), ("serial", serial())] {
        let o = LikelihoodObjective::new(&structure, &e, &record);
        group.bench_function(format!("{name}: cost"), |b| {
            b.iter(|| black_box(o.cost(&theta)))
        });
        group.bench_function(format!("{name}: cost and gradient"), |b| {
            b.iter(|| black_box(o.cost_gradient(&theta)))
        });
        group.bench_function(format!("{name}: fit"), |b| {
            b.iter(|| {
                black_box(
                    fit_sine(
                        &record,
                        &ls,
                        1.78,
                        jitter,
                        false,
                        None,
                        &e,
                        &FitOptions::default().with_covariance(false),
                    )
                    .unwrap(),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, table1, system, table1_per_n, sine);
criterion_main!(benches);
