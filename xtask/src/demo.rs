//! `cargo xtask demo`: the paper's Table 2 setup, simulated, and its first moment `μ_Y(f)` by
//! both routes (the literal frequency integral and the exact time-domain identity).

use crate::paper;
use jitterid::prelude::*;
use jitterid::window::{
    first_moment, first_moment_integral, DirichletWindow, FrequencySet, IntegralOptions,
};
use std::time::Instant;

pub fn run() -> Result<(), String> {
    let mut rng = paper::rng(1, 0);
    let g = paper::eq17(0.2, 0.5, -0.25, 0.3).map_err(|e| e.to_string())?;
    let u = paper::input(&mut rng, 8.0);
    let switches = u.steps().len();
    let signal = LtiResponse::new(g, u);
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).map_err(|e| e.to_string())?;
    let grid = paper::grid();
    let data =
        simulate(&signal, &jitter, &grid, paper::NOISE_STD, &mut rng).map_err(|e| e.to_string())?;
    let freqs = FrequencySet::dft(&grid);

    let t = Instant::now();
    let b = first_moment(&signal, &jitter, &grid, &DirichletWindow, &freqs);
    let tb = t.elapsed();
    let t = Instant::now();
    let a = first_moment_integral(
        &signal,
        &jitter,
        &grid,
        &DirichletWindow,
        &freqs,
        &IntegralOptions::default(),
    )
    .map_err(|e| e.to_string())?;
    let ta = t.elapsed();
    let y = jitterid::window::transform(&grid, &DirichletWindow, &data.y, &freqs)
        .map_err(|e| e.to_string())?;

    println!("Table 2 setup: G(s) = 0.2 (s + 0.5) / ((s + 0.25)² + 0.3²), T = 1 s, N = 200,");
    println!("input: random binary, mean dwell 8 s ({switches} steps); jitter: uniform-sum n = 2, a = 1/(2√3) s;");
    println!("noise std 0.01. μ_Y(f) = E[Y(f)] on the DFT grid j/(NT), 0 ≤ j ≤ N/2:\n");
    println!(
        "{:>8}  {:>24}  {:>24}  {:>10}  {:>10}  {:>10}",
        "f (Hz)",
        "route (a) ∫ S_c γ Γ_N dψ",
        "route (b) Σ m_k e^..",
        "|a − b|",
        "bound (a)",
        "|Y(f)|"
    );
    for j in [0usize, 1, 2, 5, 10, 20, 40, 60, 80, 100] {
        let f = freqs.frequencies()[j];
        println!(
            "{f:>8.3}  {:>11.6}{:>+11.6}i  {:>11.6}{:>+11.6}i  {:>10.2e}  {:>10.2e}  {:>10.4}",
            a.values[j].re,
            a.values[j].im,
            b[j].re,
            b[j].im,
            (a.values[j] - b[j]).norm(),
            a.error_bounds[j],
            y[j].norm()
        );
    }
    let worst = a
        .values
        .iter()
        .zip(&b)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    let scale = b.iter().map(|v| v.norm()).fold(0.0, f64::max);
    println!(
        "\nlargest |a − b| over all {} frequencies: {worst:.3e} (max |μ_Y| = {scale:.3})",
        freqs.len()
    );
    println!("time: route (a) {:.1} ms, route (b) {:.1} µs (one evaluation, unoptimised timing; see docs/performance.md)", ta.as_secs_f64() * 1e3, tb.as_secs_f64() * 1e6);
    Ok(())
}
