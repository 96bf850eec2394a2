//! Several inputs: one BCLS fit of a two-input system whose channels are both second order
//! against the fit of one of those channels alone, on N = 1 000 samples (T = 1 s, uniform-sum
//! jitter n = 2, a = 1/(2√3), random binary inputs of mean dwell 8 s), each from the same 10 %
//! perturbation of its truth. The target is at most 2.5× the single-input fit.
//!
//! `cargo bench -p jitterid --bench multi_input`

use criterion::{criterion_group, criterion_main, Criterion};
use jitterid::estimate::{fit, Bcls, FitOptions, ModelStructure, Record};
use jitterid::prelude::*;
use jitterid::signal::registry::SignalRegistry;
use jitterid::signal::superposition::superposition;
use jitterid::signal::{AnySignal, Channel};
use rand::SeedableRng;
use std::hint::black_box;

const N: usize = 1_000;

/// The response of `spec` (a registry spec table as JSON) to `input`.
fn response(spec: serde_json::Value, input: &Input) -> AnySignal {
    SignalRegistry::builtin()
        .build(spec.as_object().unwrap(), Some(input))
        .unwrap()
}

fn benches(c: &mut Criterion) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let span = (N + 1) as f64;
    let u1: Input = RandomBinary::paper()
        .generate(0.0, span, &mut rng)
        .unwrap()
        .into();
    let u2: Input = RandomBinary::paper()
        .generate(0.0, span, &mut rng)
        .unwrap()
        .into();
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, N).unwrap();
    let g1 = |k: f64| serde_json::json!({"kind": "zpk", "gain": 0.2 * k, "zeros": [-0.5 * k], "poles": [[-0.25 * k, 0.3 * k]]});
    let g2 = |k: f64| serde_json::json!({"kind": "tf", "num": [0.3 * k], "den": [1.0, 0.6 * k, 0.4 * k]});
    let two = |k: f64| {
        superposition(
            vec![
                Channel {
                    name: "u1".into(),
                    signal: response(g1(k), &u1),
                    estimated: true,
                },
                Channel {
                    name: "u2".into(),
                    signal: response(g2(k), &u2),
                    estimated: true,
                },
            ],
            0.0,
            false,
        )
        .unwrap()
    };
    let one = |k: f64| response(g1(k), &u1);
    let options = FitOptions::default().with_covariance(false);
    for (name, truth, start) in [
        ("one input (4 parameters)", one(1.0), one(1.1)),
        ("two inputs (4 + 3 parameters)", two(1.0), two(1.1)),
    ] {
        let y = simulate(&truth, &jitter, &grid, 0.01, &mut rng).unwrap().y;
        let record = Record::new(grid, y).unwrap();
        let structure = ModelStructure::oe(start, jitter);
        c.bench_function(&format!("multi_input/BCLS fit, N = 1000, {name}"), |b| {
            b.iter(|| fit(black_box(&structure), &record, &Bcls, &options).unwrap())
        });
    }
}

criterion_group!(multi_input, benches);
criterion_main!(multi_input);
