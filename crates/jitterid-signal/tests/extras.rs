//! Cross-checks of `Sinusoid`, `PulseResponse` and `simulate` against independent routes: the
//! trait's default quadrature, finite differences, and Monte Carlo.

use jitterid_jitter::{
    ExponentialDelay, Gaussian, JitterModel, Laplace, NoJitter, TwoPoint, UniformSum,
};
use jitterid_signal::testing::Plain;
use jitterid_signal::{
    simulate, PiecewiseConstant, PulseResponse, RandomBinary, SampleGrid, Signal, SignalError,
    Sinusoid,
};
use rand::rngs::StdRng;
use rand::SeedableRng;

/// Symmetric, one-sided, atomic and heavy-ish families: an asymmetric one catches a
/// `γ(f0)`/`γ(-f0)` mix-up.
fn jitters() -> Vec<Box<dyn JitterModel>> {
    vec![
        Box::new(NoJitter::new()),
        Box::new(UniformSum::new(0, 0.3).unwrap()),
        Box::new(UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap()),
        Box::new(Gaussian::new(0.17).unwrap()),
        Box::new(TwoPoint::new(0.13).unwrap()),
        Box::new(ExponentialDelay::new(0.21).unwrap()),
        Box::new(Laplace::new(0.08).unwrap()),
    ]
}

fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= tol, "{what} [{k}]: {x} vs {y}");
    }
}

#[test]
fn sinusoid_closed_forms_equal_quadrature() {
    let grid = SampleGrid::new(-0.3, 0.45, 25).unwrap();
    let sines = [
        Sinusoid::new(1.3, 0.27, 0.4).unwrap(),
        Sinusoid::new(-0.8, 3.1, 2.0).unwrap(),
        Sinusoid::new(0.5, 0.0, 1.1).unwrap(),
    ];
    for s in sines {
        let plain = Plain(s);
        for jitter in jitters() {
            let j = jitter.as_ref();
            let what = format!("{s:?} {}", j.name());
            assert_close(
                &s.expected_values(&grid, j),
                &plain.expected_values(&grid, j),
                1e-12,
                &what,
            );
            assert_close(
                &s.expected_squares(&grid, j),
                &plain.expected_squares(&grid, j),
                1e-12,
                &what,
            );
            let exact = s.expected_values_gradient(&grid, j);
            let quad = plain.expected_values_gradient(&grid, j);
            for (e, q) in exact.iter().zip(&quad) {
                assert_close(e, q, 1e-12, &what);
            }
        }
    }
}

#[test]
fn sinusoid_expected_gradient_matches_central_differences() {
    let s = Sinusoid::new(1.3, 0.27, 0.4).unwrap();
    let grid = SampleGrid::new(-1.0, 0.7, 9).unwrap();
    let h = 1e-6;
    for jitter in jitters() {
        let j = jitter.as_ref();
        let grad = s.expected_values_gradient(&grid, j);
        for (p, col) in grad.iter().enumerate() {
            let mut up = s.params();
            let mut dn = s.params();
            up[p] += h;
            dn[p] -= h;
            let mu = s.with_params(&up).unwrap().expected_values(&grid, j);
            let md = s.with_params(&dn).unwrap().expected_values(&grid, j);
            for k in 0..grid.len() {
                let fd = (mu[k] - md[k]) / (2.0 * h);
                // Central differences: truncation h²·|∂³m|/6 ≲ 1e-12·(2π·5)³ ≈ 3e-8 here,
                // round-off ε/h ≈ 1e-10.
                assert!(
                    (col[k] - fd).abs() < 1e-7,
                    "{} θ{p} k={k}: {} vs {fd}",
                    j.name(),
                    col[k]
                );
            }
        }
    }
}

fn random_input(seed: u64) -> PiecewiseConstant {
    let mut rng = StdRng::seed_from_u64(seed);
    RandomBinary::new(0.9, -0.4, 1.0)
        .unwrap()
        .generate(-2.0, 24.0, &mut rng)
        .unwrap()
}

#[test]
fn pulse_exact_mean_equals_quadrature() {
    let grid = SampleGrid::new(0.0, 1.0, 20).unwrap();
    let pulses = [
        // Irregular switching and a pulse spacing unrelated to it.
        PulseResponse::new(vec![0.5, 0.25, -0.3, 0.1], 0.73, random_input(7)).unwrap(),
        // An input on the pulse grid: coinciding shifted edges.
        PulseResponse::new(
            vec![1.0, -0.5, 0.25],
            0.5,
            PiecewiseConstant::zero_order_hold(-1.0, 0.5, &[1.0, 0.0, 2.0, -1.0, 0.5, 3.0])
                .unwrap(),
        )
        .unwrap(),
    ];
    for p in pulses {
        let plain = Plain(p.clone());
        for jitter in jitters() {
            let j = jitter.as_ref();
            assert_close(
                &p.expected_values(&grid, j),
                &plain.expected_values(&grid, j),
                1e-12,
                j.name(),
            );
            let exact = p.expected_values_gradient(&grid, j);
            let quad = plain.expected_values_gradient(&grid, j);
            assert_eq!(exact.len(), p.num_params());
            for (e, q) in exact.iter().zip(&quad) {
                assert_close(e, q, 1e-12, j.name());
            }
        }
    }
}

#[test]
fn pulse_atom_on_an_edge_counts_as_after_it() {
    // Edges on the integers, instants half-way, atoms at ±1/2: every atom lands exactly on an
    // edge, where u (right-continuous) already has its new level.
    let input = PiecewiseConstant::zero_order_hold(0.0, 1.0, &[1.0, 3.0, -2.0, 5.0]).unwrap();
    let p = PulseResponse::new(vec![1.0, 0.5], 1.0, input).unwrap();
    let grid = SampleGrid::new(-0.5, 1.0, 7).unwrap();
    let jitter = TwoPoint::new(0.5).unwrap();
    let direct: Vec<f64> = grid
        .times()
        .map(|t| 0.5 * (p.value(t - 0.5) + p.value(t + 0.5)))
        .collect();
    assert_eq!(p.expected_values(&grid, &jitter), direct);
    assert_eq!(Plain(p).expected_values(&grid, &jitter), direct);
}

#[test]
fn simulation_is_reproducible_and_exact() {
    let s = Sinusoid::new(1.0, 0.2, 0.3).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 50).unwrap();
    let jitter = Gaussian::new(0.1).unwrap();
    let a = simulate(&s, &jitter, &grid, 0.05, &mut StdRng::seed_from_u64(3)).unwrap();
    let b = simulate(&s, &jitter, &grid, 0.05, &mut StdRng::seed_from_u64(3)).unwrap();
    let c = simulate(&s, &jitter, &grid, 0.05, &mut StdRng::seed_from_u64(4)).unwrap();
    assert_eq!(a, b);
    assert_ne!(a.y, c.y);
    assert_eq!(a.grid, grid);
    assert_eq!((a.y.len(), a.tau.len(), a.noise.len()), (50, 50, 50));
    for (k, t) in grid.times().enumerate() {
        // `y − noise` may round; the sum as the simulator formed it is bit-exact.
        assert_eq!(a.y[k], s.value(t + a.tau[k]) + a.noise[k]);
    }
    // The jitter is drawn first, so it does not depend on the noise level.
    let quiet = simulate(&s, &jitter, &grid, 0.0, &mut StdRng::seed_from_u64(3)).unwrap();
    assert_eq!(quiet.tau, a.tau);
    assert!(quiet.noise.iter().all(|&v| v == 0.0));
}

#[test]
fn simulation_without_jitter_or_noise_samples_the_signal() {
    let p = PulseResponse::new(vec![0.5, 0.25, -0.3], 0.73, random_input(11)).unwrap();
    let grid = SampleGrid::new(-1.0, 0.5, 40).unwrap();
    let sim = simulate(
        &p,
        &NoJitter::new(),
        &grid,
        0.0,
        &mut StdRng::seed_from_u64(1),
    )
    .unwrap();
    let direct: Vec<f64> = grid.times().map(|t| p.value(t)).collect();
    assert_eq!(sim.y, direct);
    assert!(sim.tau.iter().all(|&t| t == 0.0));
}

#[test]
fn simulation_rejects_bad_noise_levels() {
    let s = Sinusoid::new(1.0, 0.2, 0.3).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 5).unwrap();
    let mut rng = StdRng::seed_from_u64(0);
    let j = NoJitter::new();
    assert!(matches!(
        simulate(&s, &j, &grid, -0.1, &mut rng),
        Err(SignalError::NotPositive {
            name: "noise_std",
            ..
        })
    ));
    for bad in [f64::NAN, f64::INFINITY] {
        assert!(matches!(
            simulate(&s, &j, &grid, bad, &mut rng),
            Err(SignalError::NotFinite {
                name: "noise_std",
                ..
            })
        ));
    }
    // A dynamically sized signal works too.
    let dynamic: &dyn Signal = &s;
    assert!(simulate(dynamic, &j, &grid, 0.0, &mut rng).is_ok());
}

/// Monte Carlo means and (unbiased) variances of each sample over `runs` records.
fn monte_carlo(
    signal: &dyn Signal,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    noise_std: f64,
    runs: usize,
    seed: u64,
) -> (Vec<f64>, Vec<f64>) {
    let mut rng = StdRng::seed_from_u64(seed);
    let n = grid.len();
    let (mut sum, mut sq) = (vec![0.0; n], vec![0.0; n]);
    for _ in 0..runs {
        let sim = simulate(signal, jitter, grid, noise_std, &mut rng).unwrap();
        for k in 0..n {
            sum[k] += sim.y[k];
            sq[k] += sim.y[k] * sim.y[k];
        }
    }
    let r = runs as f64;
    let mean: Vec<f64> = sum.iter().map(|s| s / r).collect();
    let var = sq
        .iter()
        .zip(&mean)
        .map(|(q, m)| (q - r * m * m) / (r - 1.0))
        .collect();
    (mean, var)
}

/// A signal, its jitter and the instants to sample.
type Case = (Box<dyn Signal>, Box<dyn JitterModel>, SampleGrid);

#[test]
fn monte_carlo_mean_matches_expected_values() {
    // Per sample, |ȳ_k − m_k| ≤ 5·√(λ_k / R) with λ_k = σ_v² + E[s²] − m_k²: a 5-standard-error
    // CLT bound (two-sided tail ≈ 6e-7 per sample).
    let runs = 4000;
    let noise_std = 0.05;
    let cases: Vec<Case> = vec![
        (
            Box::new(Sinusoid::new(1.0, 0.3, 0.2).unwrap()),
            Box::new(UniformSum::new(2, 0.45).unwrap()),
            SampleGrid::new(0.0, 1.0, 30).unwrap(),
        ),
        (
            Box::new(PulseResponse::new(vec![0.8, 0.4, -0.2], 0.6, random_input(5)).unwrap()),
            Box::new(Gaussian::new(0.3).unwrap()),
            SampleGrid::new(0.0, 0.7, 30).unwrap(),
        ),
    ];
    for (seed, (signal, jitter, grid)) in cases.into_iter().enumerate() {
        let m = signal.expected_values(&grid, jitter.as_ref());
        let sq = signal.expected_squares(&grid, jitter.as_ref());
        let (mean, _) = monte_carlo(
            signal.as_ref(),
            jitter.as_ref(),
            &grid,
            noise_std,
            runs,
            seed as u64,
        );
        for k in 0..grid.len() {
            let lambda = noise_std * noise_std + sq[k] - m[k] * m[k];
            let se = (lambda / runs as f64).sqrt();
            assert!(
                (mean[k] - m[k]).abs() <= 5.0 * se,
                "case {seed} k={k}: {} vs {} (se {se})",
                mean[k],
                m[k]
            );
        }
    }
}

#[test]
fn monte_carlo_variance_of_a_jittered_sinusoid() {
    // λ_k = σ_v² + E[s²] − m_k². The unbiased sample variance has standard error
    // √((μ4 − λ²)/R) to first order, with μ4 = E[(y − m)⁴] = E[a⁴] + 6σ_v²E[a²] + 3σ_v⁴ for
    // a = s(t + τ) − m (jitter and noise independent); E[a⁴] by quadrature. Bound: 5 standard
    // errors per sample.
    let runs = 4000;
    let noise_std = 0.1;
    let s = Sinusoid::new(1.0, 0.3, 0.2).unwrap();
    let jitter = Gaussian::new(0.25).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 30).unwrap();
    let m = s.expected_values(&grid, &jitter);
    let sq = s.expected_squares(&grid, &jitter);
    let (_, var) = monte_carlo(&s, &jitter, &grid, noise_std, runs, 99);
    let rule = jitter.rule(&[], 4.0 * s.rate());
    let s2 = noise_std * noise_std;
    for (k, t) in grid.times().enumerate() {
        let a2 = sq[k] - m[k] * m[k];
        let lambda = s2 + a2;
        let a4 = rule.expect(|tau| (s.value(t + tau) - m[k]).powi(4));
        let mu4 = a4 + 6.0 * s2 * a2 + 3.0 * s2 * s2;
        let se = ((mu4 - lambda * lambda) / runs as f64).sqrt();
        assert!(
            (var[k] - lambda).abs() <= 5.0 * se,
            "k={k}: {} vs {lambda} (se {se})",
            var[k]
        );
    }
}
