//! Benchmarks: kernels, transforms of an `N = 200` record, and both first-moment routes on a
//! test-local signal (an exponential pulse with closed-form spectrum).

#[path = "../tests/common/mod.rs"]
mod common;

use common::ExpPulse;
use criterion::{criterion_group, criterion_main, Criterion};
use jitterid_jitter::{Gaussian, UniformSum};
use jitterid_signal::SampleGrid;
use jitterid_window::{
    dirichlet, dtft, fft_grid, first_moment, first_moment_integral, transform, DirichletWindow,
    FrequencySet, HannWindow, IntegralOptions, Window,
};
use std::hint::black_box;

fn record(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| ((k as f64) * 0.37).sin() + 0.1 * ((k * k) as f64 * 0.013).cos())
        .collect()
}

fn kernels(c: &mut Criterion) {
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    c.bench_function("dirichlet_kernel_n200", |b| {
        b.iter(|| dirichlet(black_box(&grid), black_box(0.123_456)))
    });
    c.bench_function("hann_kernel_n200_closed_form", |b| {
        b.iter(|| HannWindow.kernel(black_box(&grid), black_box(0.123_456)))
    });
}

fn transforms(c: &mut Criterion) {
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let y = record(200);
    let set = FrequencySet::dft(&grid);
    let freqs = set.frequencies().to_vec();
    c.bench_function("dtft_n200_101_freqs", |b| {
        b.iter(|| dtft(black_box(&grid), black_box(&y), None, black_box(&freqs)))
    });
    c.bench_function("fft_n200", |b| b.iter(|| fft_grid(black_box(&y), None)));
    c.bench_function("transform_n200_dft_set", |b| {
        b.iter(|| transform(black_box(&grid), &DirichletWindow, black_box(&y), &set))
    });
}

fn moments(c: &mut Criterion) {
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let set = FrequencySet::dft(&grid);
    let pulse = ExpPulse {
        alpha: 0.05,
        start: 10.0,
        len: 150.0,
    };
    let uniform = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let gaussian = Gaussian::new(0.1).unwrap();
    c.bench_function("first_moment_route_b_pulse_uniform_sum_n200", |b| {
        b.iter(|| first_moment(black_box(&pulse), &uniform, &grid, &DirichletWindow, &set))
    });
    let mut group = c.benchmark_group("first_moment_route_a");
    group.sample_size(10);
    group.bench_function("pulse_gaussian_n200", |b| {
        b.iter(|| {
            first_moment_integral(
                black_box(&pulse),
                &gaussian,
                &grid,
                &DirichletWindow,
                &set,
                &IntegralOptions::default(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, kernels, transforms, moments);
criterion_main!(benches);
