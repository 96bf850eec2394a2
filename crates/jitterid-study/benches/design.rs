//! The predicted covariance of one design of the Table 2 setup (`examples/experiments/
//! table2.toml`: T = 1 s, N = 200, random binary input of mean dwell 8 s, uniform-sum jitter):
//! BCLS (the sandwich at the truth on the expected record) and exact ML (the inverse exact
//! Fisher information), each for one input draw and averaged over the `[design]` default of 16.
//!
//! `cargo bench -p jitterid-study --bench design`

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_study::design::predict;
use jitterid_study::experiment::{self, DesignEstimator, Purpose};
use std::hint::black_box;
use std::path::Path;

fn benches(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/experiments/table2.toml");
    let exp = experiment::read(&path, Purpose::Simulate).expect("table2.toml reads");
    let mut g = c.benchmark_group("design-table2");
    g.sample_size(10);
    for (name, estimator) in [("bcls", DesignEstimator::Bcls), ("ml", DesignEstimator::Ml)] {
        for draws in [1usize, 16] {
            g.bench_function(format!("{name}/draws-{draws}"), |b| {
                b.iter(|| black_box(predict(&exp, estimator, draws, 1).expect("predicts")))
            });
        }
    }
    g.finish();
}

criterion_group!(design, benches);
criterion_main!(design);
