//! Tests of the maximum-likelihood layer (issue 4) through the public API.

use jitterid_estimate::ml::*;
use jitterid_estimate::{ModelStructure, Record};
use jitterid_jitter::{Gaussian, JitterModel, NoJitter, TwoPoint, UniformSum};
use jitterid_signal::{
    simulate, LtiResponse, PiecewiseConstant, RandomBinary, Root, SampleGrid, Signal, Sinusoid,
    Zpk,
};
use rand::rngs::StdRng;
use rand::SeedableRng;

/// The Table 1 system `1/(s+2)` driven by the paper's random binary input.
fn table1_signal(seed: u64, n: usize) -> LtiResponse<Zpk> {
    let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let u = RandomBinary::paper()
        .generate(0.0, n as f64 + 1.0, &mut rng)
        .unwrap();
    LtiResponse::new(g, u)
}

/// `log p(y)` by brute force: composite Simpson on a fine grid over each piece, split at the
/// signal's breakpoints, plus the atoms.
fn brute_log_p<S: Signal, J: JitterModel>(signal: &S, jitter: &J, t: f64, y: f64, sigma: f64) -> f64 {
    let phi = |e: f64| (-0.5 * (e / sigma).powi(2)).exp() / (sigma * (2.0 * std::f64::consts::PI).sqrt());
    let mut breaks: Vec<f64> = signal.breakpoints().iter().map(|b| b - t).collect();
    breaks.sort_by(f64::total_cmp);
    let mut total = 0.0;
    for (a, b) in jitter.pieces() {
        let mut cuts = vec![a];
        cuts.extend(breaks.iter().copied().filter(|&x| x > a && x < b));
        cuts.push(b);
        for w in cuts.windows(2) {
            let m = 20_000;
            let h = (w[1] - w[0]) / m as f64;
            let mut s = 0.0;
            for i in 0..=m {
                let tau = w[0] + i as f64 * h;
                let c = if i == 0 || i == m { 1.0 } else if i % 2 == 1 { 4.0 } else { 2.0 };
                s += c * jitter.pdf(tau) * phi(y - signal.value(t + tau));
            }
            total += s * h / 3.0;
        }
    }
    for atom in jitter.atoms() {
        total += atom.mass * phi(y - signal.value(t + atom.position));
    }
    total.ln()
}

/// Worst `|log p − brute force|` over a record of the Table 1 system.
fn exact_vs_brute<J: JitterModel + Clone>(jitter: J, sigma: f64, n: usize) -> f64 {
    let signal = table1_signal(1, n);
    let grid = SampleGrid::new(0.0, 1.0, n).unwrap();
    let mut rng = StdRng::seed_from_u64(9);
    let data = simulate(&signal, &jitter, &grid, sigma, &mut rng).unwrap();
    let record = Record::new(grid, data.y.clone()).unwrap();
    let structure = ModelStructure::oe(signal.clone(), jitter)
        .with_noise_std(sigma)
        .unwrap();
    let lp = ExactMl::default()
        .log_likelihoods(&structure, &record, sigma)
        .unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..grid.len() {
        let b = brute_log_p(&signal, &structure.jitter, grid.time(k), data.y[k], sigma);
        worst = worst.max((lp[k] - b).abs());
    }
    worst
}

#[test]
fn exact_likelihood_matches_brute_force() {
    // Brute force: Simpson with 20 000 panels per piece, accurate to ~1e-12 here.
    for (name, worst) in [
        ("uniform n=0", exact_vs_brute(UniformSum::new(0, 0.5).unwrap(), 0.01, 60)),
        ("uniform n=3", exact_vs_brute(UniformSum::new(3, 0.7).unwrap(), 0.01, 60)),
        ("gaussian", exact_vs_brute(Gaussian::new(0.17).unwrap(), 0.01, 60)),
        ("uniform n=0, σ_v = 1e-3", exact_vs_brute(UniformSum::new(0, 0.5).unwrap(), 0.001, 60)),
        ("two-point", exact_vs_brute(TwoPoint::new(0.3).unwrap(), 0.01, 30)),
    ] {
        println!("{name}: worst |Δ log p| = {worst:e}");
        assert!(worst < 1e-9, "{name}: {worst}");
    }
}
