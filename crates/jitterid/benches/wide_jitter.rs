//! The cost of the exact first moment, its gradient and the second moment when the jitter is
//! far wider than the response, or a pole far faster than the sampling: the cases of the test
//! `wide_jitter_moments_are_finite_and_match_closed_forms` (which checks their values), timed here instead
//! of in the test. Each should stay within a small multiple of the narrow-jitter case.
//!
//! `cargo bench -p jitterid --bench wide_jitter`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use jitterid::jitter::{ExponentialDelay, Gaussian, JitterModel};
use jitterid::prelude::*;
use std::hint::black_box;

/// `m_k`, `∂m_k/∂θ` and `E[s²]` on the test's 49-sample grid.
fn moments(s: &LtiResponse<Zpk>, grid: &SampleGrid, j: &dyn JitterModel) {
    black_box(s.expected_values(grid, j));
    black_box(s.expected_values_gradient(grid, j));
    black_box(s.expected_squares(grid, j));
}

fn wide_jitter(c: &mut Criterion) {
    let u = PiecewiseConstant::new(
        vec![-31.66, -29.66, -29.657, -29.653, -5.58, 19.0, 19.06],
        vec![1.66, 1.16, -1.46, 0.86, 1.05, 0.5],
    )
    .unwrap();
    let grid = SampleGrid::new(-1.875, 1.664, 49).unwrap();
    let slow = LtiResponse::new(
        Zpk::new(-2.5, vec![], vec![Root::Real(-0.222), Root::Real(-0.396)]).unwrap(),
        u.clone(),
    );
    let mut group = c.benchmark_group("wide_jitter");
    for sigma in [0.03, 1e2, 1e4, 1e6] {
        let jitter = Gaussian::new(sigma).unwrap();
        group.bench_with_input(BenchmarkId::new("gaussian", sigma), &jitter, |b, j| {
            b.iter(|| moments(&slow, &grid, j))
        });
    }
    let fast = LtiResponse::new(
        Zpk::new(1e8, vec![], vec![Root::Real(-1e8), Root::Real(-0.5)]).unwrap(),
        u.clone(),
    );
    let sum54 = UniformSum::new(54, 0.5).unwrap();
    group.bench_function("pole -1e8, uniform-sum n = 54", |b| {
        b.iter(|| moments(&fast, &grid, &sum54))
    });
    let ringing = LtiResponse::new(
        Zpk::new(
            1e8,
            vec![],
            vec![
                Root::Pair {
                    re: -0.79,
                    im: 1e12,
                },
                Root::Real(-25.0),
            ],
        )
        .unwrap(),
        u,
    );
    let delay = ExponentialDelay::new(0.15).unwrap();
    group.bench_function("poles -0.79 ± 1e12 i, exponential delay", |b| {
        b.iter(|| moments(&ringing, &grid, &delay))
    });
    group.finish();
}

criterion_group!(benches, wide_jitter);
criterion_main!(benches);
