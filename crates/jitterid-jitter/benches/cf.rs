//! Cost of the characteristic function and of building an expectation rule.

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_jitter::{Gaussian, JitterModel, UniformSum};
use std::hint::black_box;

fn cf(c: &mut Criterion) {
    // The paper's Table 2 jitter, n = 2, a = 1/(2√3).
    let us = UniformSum::new(2, 0.2887).unwrap();
    let gauss = Gaussian::new(1.0 / 6.0).unwrap();
    let freqs: Vec<f64> = (0..101).map(|j| j as f64 / 200.0).collect();
    c.bench_function("uniform_sum_n2_cf_101_freqs", |b| {
        b.iter(|| {
            freqs
                .iter()
                .map(|&f| black_box(&us).cf(black_box(f)).re)
                .sum::<f64>()
        })
    });
    c.bench_function("gaussian_cf_101_freqs", |b| {
        b.iter(|| {
            freqs
                .iter()
                .map(|&f| black_box(&gauss).cf(black_box(f)).re)
                .sum::<f64>()
        })
    });
}

fn rule(c: &mut Criterion) {
    let us2 = UniformSum::new(2, 0.2887).unwrap();
    let us50 = UniformSum::new(50, 0.2887).unwrap();
    let gauss = Gaussian::new(1.0 / 6.0).unwrap();
    c.bench_function("uniform_sum_n2_rule", |b| {
        b.iter(|| black_box(&us2).rule(&[], 0.0))
    });
    c.bench_function("uniform_sum_n50_rule", |b| {
        b.iter(|| black_box(&us50).rule(&[], 0.0))
    });
    c.bench_function("gaussian_rule", |b| {
        b.iter(|| black_box(&gauss).rule(&[], 0.0))
    });
}

criterion_group!(benches, cf, rule);
criterion_main!(benches);
