//! Cost of `m_k` and its gradient by the two routes of an LTI response: the modal form
//! (distinct poles) and the realisation (a double pole, an integrator), on one record.

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_jitter::UniformSum;
use jitterid_signal::testing::binary;
use jitterid_signal::{LtiResponse, Root, SampleGrid, Signal, Zpk};
use std::hint::black_box;

fn routes(c: &mut Criterion) {
    // N = 1000 at T = 1 s, a random binary input of mean dwell 2 s, uniform-sum jitter n = 2.
    let u = binary(1, 2.0, -5.0, 1005.0).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 1000).unwrap();
    let jitter = UniformSum::new(2, 0.25).unwrap();
    let cases = [
        (
            "modal_distinct_poles",
            vec![Root::Real(-0.8), Root::Real(-0.9)],
        ),
        (
            "realisation_double_pole",
            vec![Root::Real(-0.8), Root::Real(-0.8)],
        ),
        (
            "realisation_integrator",
            vec![Root::Real(0.0), Root::Real(-0.8)],
        ),
    ];
    for (name, poles) in cases {
        let s = LtiResponse::new(Zpk::new(0.64, vec![], poles).unwrap(), u.clone());
        c.bench_function(&format!("m_k_and_gradient_n1000_{name}"), |b| {
            b.iter(|| black_box(&s).expected_values_and_gradient(&grid, &jitter))
        });
        c.bench_function(&format!("second_moment_n1000_{name}"), |b| {
            b.iter(|| black_box(&s).expected_squares(&grid, &jitter))
        });
    }
}

criterion_group!(benches, routes);
criterion_main!(benches);
