//! The LTI response against independent routes: a fine-step ODE integration for `s(t)`, the
//! generic quadrature route for `m_k`, and finite differences for every gradient.

mod common;
use common::ode_response;
use jitterid_jitter::{
    ExponentialDelay, Gaussian, JitterModel, Laplace, NoJitter, Shifted, TwoPoint, UniformSum,
};
use jitterid_signal::testing::Plain;
use jitterid_signal::{
    Input, LtiResponse, Multisine, PiecewiseConstant, RandomBinary, RationalModel, Root,
    SampleGrid, Signal, TransferFunction, Zpk,
};
use rand::SeedableRng;

fn paper_system() -> Zpk {
    Zpk::new(
        0.2,
        vec![Root::Real(-0.5)],
        vec![Root::Pair { re: -0.25, im: 0.3 }],
    )
    .unwrap()
}

fn third_order() -> TransferFunction {
    // Poles −0.5, −1 ± 2i; a zero; direct feed-through 0.3 (biproper).
    TransferFunction::new(&[0.3, 1.0, 0.8, 2.0], &[1.0, 2.5, 6.0, 2.5]).unwrap()
}

fn binary_input(seed: u64, end: f64) -> PiecewiseConstant {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    RandomBinary::new(3.0, -0.5, 1.0)
        .unwrap()
        .generate(-5.0, end, &mut rng)
        .unwrap()
}

fn jitters() -> Vec<Box<dyn JitterModel>> {
    vec![
        Box::new(NoJitter),
        Box::new(UniformSum::new(0, 0.5).unwrap()),
        Box::new(UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap()),
        Box::new(UniformSum::new(9, 1.3).unwrap()),
        Box::new(Gaussian::new(0.15).unwrap()),
        Box::new(Laplace::new(0.05).unwrap()),
        Box::new(TwoPoint::new(0.3).unwrap()),
        Box::new(ExponentialDelay::new(0.1).unwrap()),
        Box::new(Shifted::new(UniformSum::new(1, 0.4).unwrap(), -0.2).unwrap()),
    ]
}

#[test]
fn response_matches_fine_step_ode_integration() {
    let u = binary_input(7, 60.0);
    for (num, den) in [
        (vec![0.2, 0.1], vec![1.0, 0.5, 0.1525]),
        (vec![0.3, 1.0, 0.8, 2.0], vec![1.0, 2.5, 6.0, 2.5]),
    ] {
        let g = TransferFunction::new(&num, &den).unwrap();
        let s = LtiResponse::new(g.clone(), u.clone());
        // Every edge up to the end, and the end (left limits at the edges).
        let first = u.edges()[0];
        let mut times: Vec<f64> = u
            .edges()
            .iter()
            .copied()
            .filter(|&e| e > first && e < 60.0)
            .collect();
        times.push(60.0);
        let ode = ode_response(g.rational().num(), g.den(), &u, &times, 1e-3);
        for (t, y) in times.into_iter().zip(ode) {
            // Just before the edge, where the ODE state is; RK4 at h = 1e-3 is accurate to ~1e-11.
            let exact = s.value(t - 1e-12);
            assert!((exact - y).abs() < 1e-8, "t = {t}: exact {exact}, ode {y}");
        }
    }
}

#[test]
fn fast_first_moment_equals_quadrature_route() {
    let grid = SampleGrid::new(0.3, 1.0, 60).unwrap();
    let u = binary_input(11, 70.0);
    let paper = LtiResponse::new(paper_system(), u.clone());
    let third = LtiResponse::new(third_order(), u);
    let mut worst = 0.0f64;
    for jitter in jitters() {
        for (fast, slow) in [
            (
                paper.expected_values(&grid, jitter.as_ref()),
                Plain(paper.clone()).expected_values(&grid, jitter.as_ref()),
            ),
            (
                third.expected_values(&grid, jitter.as_ref()),
                Plain(third.clone()).expected_values(&grid, jitter.as_ref()),
            ),
        ] {
            for (a, b) in fast.iter().zip(&slow) {
                worst = worst.max((a - b).abs());
                // Both routes are exact up to quadrature rounding (~1e-15 per node).
                assert!((a - b).abs() < 1e-12, "{}: {a} vs {b}", jitter.name());
            }
        }
    }
    eprintln!("largest fast/quadrature difference: {worst:e}");
}

fn check_gradient<S: Signal + Clone>(s: &S, grid: &SampleGrid, jitter: &dyn JitterModel) {
    let jac = s.expected_values_gradient(grid, jitter);
    let plain = Plain(s.clone()).expected_values_gradient(grid, jitter);
    let p0 = s.params();
    for j in 0..p0.len() {
        let h = 1e-6 * p0[j].abs().max(0.1);
        let mut pp = p0.clone();
        pp[j] += h;
        let mut pm = p0.clone();
        pm[j] -= h;
        let mp = s.with_params(&pp).unwrap().expected_values(grid, jitter);
        let mm = s.with_params(&pm).unwrap().expected_values(grid, jitter);
        for k in 0..grid.len() {
            let fd = (mp[k] - mm[k]) / (2.0 * h);
            // Central differences: error O(h²·m''') plus rounding ~1e-16/h ≈ 1e-9.
            assert!(
                (fd - jac[j][k]).abs() < 1e-7,
                "{} param {j} sample {k}: fd {fd} analytic {}",
                jitter.name(),
                jac[j][k]
            );
            assert!((plain[j][k] - jac[j][k]).abs() < 1e-11);
        }
    }
}

#[test]
fn first_moment_gradient_matches_finite_differences() {
    let grid = SampleGrid::new(0.0, 1.0, 40).unwrap();
    let u = binary_input(3, 50.0);
    for jitter in jitters() {
        check_gradient(
            &LtiResponse::new(paper_system(), u.clone()),
            &grid,
            jitter.as_ref(),
        );
        check_gradient(
            &LtiResponse::new(third_order(), u.clone()),
            &grid,
            jitter.as_ref(),
        );
    }
}

#[test]
fn value_gradient_matches_finite_differences() {
    let s = LtiResponse::new(third_order(), binary_input(5, 30.0));
    let p0 = s.params();
    let mut g = vec![0.0; p0.len()];
    for t in [0.5, 3.3, 12.0, 29.0] {
        s.value_gradient(t, &mut g);
        for j in 0..p0.len() {
            let h = 1e-6;
            let mut pp = p0.clone();
            pp[j] += h;
            let mut pm = p0.clone();
            pm[j] -= h;
            let fd = (s.with_params(&pp).unwrap().value(t) - s.with_params(&pm).unwrap().value(t))
                / (2.0 * h);
            assert!(
                (fd - g[j]).abs() < 1e-7,
                "t {t} param {j}: {fd} vs {}",
                g[j]
            );
        }
    }
}

#[test]
fn tone_input_moments_match_quadrature() {
    let tones = Multisine::new(vec![
        jitterid_signal::Tone {
            frequency: 0.13,
            amplitude: 1.0,
            phase: 0.2,
        },
        jitterid_signal::Tone {
            frequency: 0.41,
            amplitude: 0.5,
            phase: -1.0,
        },
    ])
    .unwrap();
    let s = LtiResponse::new(paper_system(), Input::Tones(tones));
    let grid = SampleGrid::new(0.0, 1.0, 30).unwrap();
    for jitter in jitters() {
        let a = s.expected_values(&grid, jitter.as_ref());
        let b = Plain(s.clone()).expected_values(&grid, jitter.as_ref());
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-12, "{}: {x} vs {y}", jitter.name());
        }
        check_gradient(&s, &grid, jitter.as_ref());
    }
}

#[test]
fn no_jitter_first_moment_is_the_sampled_signal() {
    let s = LtiResponse::new(paper_system(), binary_input(9, 40.0));
    let grid = SampleGrid::new(0.0, 0.5, 70).unwrap();
    let m = s.expected_values(&grid, &NoJitter);
    for (k, t) in grid.times().enumerate() {
        assert!((m[k] - s.value(t)).abs() < 1e-14);
    }
}

#[test]
fn fast_second_moment_equals_quadrature_route() {
    let grid = SampleGrid::new(0.3, 1.0, 50).unwrap();
    let u = binary_input(13, 60.0);
    let tones = Multisine::new(vec![
        jitterid_signal::Tone {
            frequency: 0.13,
            amplitude: 1.0,
            phase: 0.2,
        },
        jitterid_signal::Tone {
            frequency: 0.41,
            amplitude: 0.5,
            phase: -1.0,
        },
    ])
    .unwrap();
    let signals = [
        LtiResponse::new(paper_system(), Input::from(u.clone())),
        LtiResponse::new(paper_system(), Input::Tones(tones)),
    ];
    let third = LtiResponse::new(third_order(), u);
    for jitter in jitters() {
        for (fast, slow) in [
            (
                signals[0].expected_squares(&grid, jitter.as_ref()),
                Plain(signals[0].clone()).expected_squares(&grid, jitter.as_ref()),
            ),
            (
                signals[1].expected_squares(&grid, jitter.as_ref()),
                Plain(signals[1].clone()).expected_squares(&grid, jitter.as_ref()),
            ),
            (
                third.expected_squares(&grid, jitter.as_ref()),
                Plain(third.clone()).expected_squares(&grid, jitter.as_ref()),
            ),
        ] {
            for (a, b) in fast.iter().zip(&slow) {
                assert!(
                    (a - b).abs() < 1e-12 * b.abs().max(1.0),
                    "{}: {a} vs {b}",
                    jitter.name()
                );
            }
        }
    }
}

/// The step response of `1/((s + 1)(s + 1 + d))`, in a form without cancellation for small
/// `d`: `[1 − e^{−x} − e^{−x} (1 − e^{−dx})/d] / (1 + d)` for `x ≥ 0`.
fn near_double_step(d: f64, x: f64) -> f64 {
    if x < 0.0 {
        return 0.0;
    }
    let e = (-x).exp();
    let spread = if d * x == 0.0 {
        x
    } else {
        -(-d * x).exp_m1() / d
    };
    (1.0 - e - e * spread) / (1.0 + d)
}

/// Poles `−1` and `−1 − d` that nearly coincide, given as poles and as coefficients: the
/// first moment follows the response of the
/// nearly repeated pole, checked against its closed form above (summed over the input's steps,
/// and for uniform jitter integrated over `τ` by composite Gauss–Legendre, 16 points on panels
/// of 0.01 s cut at the steps). The modal terms are of size `1/d` and cancel to `O(1)`, so
/// rounding alone leaves an error of order `ε/d`; the bound is `1e-12 + 64 ε/d`. With the
/// residues taken from the polynomial's coefficients instead of the poles, the error was
/// `2.5e-5` at `d = 1e-6` and `3e-3` at `d = 1e-7`.
#[test]
fn nearly_repeated_poles_follow_the_closed_form() {
    let u = binary_input(5, 40.0);
    let steps = u.steps();
    let grid = SampleGrid::new(0.25, 0.5, 70).unwrap();
    let a = 0.3;
    let uniform = UniformSum::new(0, a).unwrap();
    let response = |d: f64, t: f64| -> f64 {
        steps
            .iter()
            .map(|&(tj, du)| du * near_double_step(d, t - tj))
            .sum()
    };
    // (x, w) of 16-point Gauss–Legendre on [−1, 1], from the jitter crate's tables.
    let (nodes, weights) = jitterid_numeric::gauss::gl16();
    let uniform_mean = |d: f64, t: f64| -> f64 {
        let mut cuts: Vec<f64> = vec![t - a, t + a];
        cuts.extend(
            steps
                .iter()
                .map(|s| s.0)
                .filter(|&c| c > t - a && c < t + a),
        );
        cuts.sort_by(f64::total_cmp);
        let mut sum = 0.0;
        for w in cuts.windows(2) {
            let panels = ((w[1] - w[0]) / 0.01).ceil().max(1.0) as usize;
            let h = (w[1] - w[0]) / panels as f64;
            for p in 0..panels {
                let mid = w[0] + (p as f64 + 0.5) * h;
                for (x, wt) in nodes.iter().zip(weights) {
                    sum += wt * 0.5 * h * response(d, mid + 0.5 * h * x);
                }
            }
        }
        sum / (2.0 * a)
    };
    for d in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7] {
        let mut worst = 0.0f64;
        let tol = 1e-12 + 64.0 * f64::EPSILON / d;
        let zpk = Zpk::new(1.0, vec![], vec![Root::Real(-1.0), Root::Real(-1.0 - d)]).unwrap();
        // The same model from its coefficients: its polished roots are off by about `ε/d`
        // near the double root, and the residues of those roots are the partial fractions of
        // `Π (s − p_l)`, whose coefficients are within `ε/d` of `A`'s: inside the bound.
        let tf = TransferFunction::new(&[1.0], &[1.0, 2.0 + d, 1.0 + d]).unwrap();
        let responses: [(&str, Box<dyn Signal>); 2] = [
            ("zpk", Box::new(LtiResponse::new(zpk, u.clone()))),
            ("tf", Box::new(LtiResponse::new(tf, u.clone()))),
        ];
        for (form, s) in responses {
            let none = s.expected_values(&grid, &NoJitter);
            let smoothed = s.expected_values(&grid, &uniform);
            for k in 0..grid.len() {
                let t = grid.time(k);
                let (r0, r1) = (response(d, t), uniform_mean(d, t));
                worst = worst
                    .max((none[k] - r0).abs())
                    .max((smoothed[k] - r1).abs());
                assert!(
                    (none[k] - r0).abs() < tol,
                    "{form}, d = {d}, k = {k}: {} vs {r0}",
                    none[k]
                );
                assert!(
                    (s.value(t) - r0).abs() < tol,
                    "{form}, d = {d}, t = {t}: value"
                );
                assert!(
                    (smoothed[k] - r1).abs() < tol,
                    "{form}, d = {d}, k = {k}: uniform {} vs {r1}",
                    smoothed[k]
                );
            }
        }
        eprintln!("d = {d:e}: largest error {worst:e} (bound {tol:e})");
    }
}
