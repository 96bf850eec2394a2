//! Order × family selection: [`select`] over 1–3 poles × the families none, Gaussian, periodic
//! and two-point (12 candidates, each jittered one from 3 jitter starts) on one record of the
//! `cargo xtask reproduce select` case (N = 1 000, `G(s) = 5/((s + 1)² + 4)`, random binary
//! input of mean dwell `T`, periodic jitter of std 0.5 T, noise 0.01). Target: at most 10 s on
//! a 2-core machine.

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_estimate::Record;
use jitterid_jitter::registry::JitterRegistry;
use jitterid_likelihood::selection::{select, SelectionGrid, SelectionOptions};
use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
use rand::SeedableRng;
use std::hint::black_box;

fn bench_select(c: &mut Criterion) {
    let registry = JitterRegistry::builtin();
    let jitter = registry
        .from_std_dev("periodic", 0.5, &serde_json::Map::new())
        .unwrap();
    let truth = Zpk::new(5.0, vec![], vec![Root::Pair { re: -1.0, im: 2.0 }]).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let u = RandomBinary::new(1.0, 0.0, 1.0)
        .unwrap()
        .generate(-10.0, 1010.0, &mut rng)
        .unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 1000).unwrap();
    let data = simulate(
        &LtiResponse::new(truth, u.clone()),
        &jitter,
        &grid,
        0.01,
        &mut rng,
    )
    .unwrap();
    let record = Record::new(grid, data.y).unwrap();
    let input = u.into();
    let candidates = SelectionGrid {
        poles: (1, 3),
        zeros: (0, 0),
        families: ["none", "gaussian", "periodic", "two-point"]
            .map(String::from)
            .to_vec(),
    };
    let mut g = c.benchmark_group("select");
    g.sample_size(10);
    g.bench_function("3 orders x 4 families, N = 1000", |b| {
        b.iter(|| {
            select(
                black_box(&record),
                &input,
                &candidates,
                registry,
                &SelectionOptions::default(),
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench_select);
criterion_main!(benches);
