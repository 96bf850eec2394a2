//! Repeated poles and poles on the imaginary axis (integrators, undamped modes): models without
//! a modal form, evaluated through their realisation. Checked against a fine-step ODE
//! integration of another realisation, closed forms, the contract's independent quadrature and
//! Monte Carlo, and the modal form itself on both sides of the switch between the two routes.

mod common;
use common::ode_response;
use jitterid_jitter::{ExponentialDelay, Gaussian, JitterModel, NoJitter, TwoPoint, UniformSum};
use jitterid_signal::testing::{binary, check_contract};
use jitterid_signal::{
    Delayed, LtiResponse, PiecewiseConstant, RationalModel, Root, SampleGrid, Signal,
    TransferFunction, WithInitialState, Zpk,
};
use proptest::prelude::*;

/// Models without a modal form: a double and a triple real pole, a repeated complex pair,
/// integrators (single and double) beside a stable pole, an undamped pair.
fn arb_confluent() -> impl Strategy<Value = Zpk> {
    (
        0usize..6,
        -2.0f64..-0.2,
        0.3f64..2.0,
        0.2f64..3.0,
        proptest::option::of(-3.0f64..3.0),
    )
        .prop_map(|(kind, p, w, gain, zero)| {
            let poles = match kind {
                0 => vec![Root::Real(p), Root::Real(p)],
                1 => vec![Root::Real(p), Root::Real(p), Root::Real(p)],
                2 => vec![Root::Real(0.0), Root::Real(p)],
                3 => vec![
                    Root::Pair { re: p / 2.0, im: w },
                    Root::Pair { re: p / 2.0, im: w },
                ],
                4 => vec![Root::Pair { re: 0.0, im: w }, Root::Real(p)],
                _ => vec![Root::Real(0.0), Root::Real(0.0), Root::Real(p)],
            };
            let zeros = zero.map(Root::Real).into_iter().collect();
            Zpk::new(gain, zeros, poles).unwrap()
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// `s(t)` against RK4 on another realisation: with `h = 1e-3` and poles of modulus ≤ 2
    /// the integration error is about `(h|p|)⁴` per unit time of the response's scale
    /// (`< 1e-10` over 12 s), so `1e-8` of the scale is tight for the route and far below any
    /// wrong term (`t e^{pt}` against `e^{pt}` differs by the scale itself).
    #[test]
    fn response_matches_fine_step_ode(g in arb_confluent(), seed in 0u64..1000) {
        prop_assert!(g.modal().is_none());
        let u = binary(seed, 2.0, 0.0, 12.0).unwrap();
        let times: Vec<f64> = (1..=60).map(|k| 0.2 * k as f64 - 0.013).collect();
        let s = LtiResponse::new(g.clone(), u.clone());
        let r = g.rational();
        let ode = ode_response(r.num(), r.den(), &u, &times, 1e-3);
        let scale = ode.iter().fold(1.0f64, |a, y| a.max(y.abs()));
        for (t, want) in times.iter().zip(&ode) {
            let got = s.value(*t);
            prop_assert!((got - want).abs() <= 1e-8 * scale, "t = {t}: {got} vs {want} ({g:?})");
        }
    }
}

fn jitters() -> Vec<Box<dyn JitterModel>> {
    vec![
        Box::new(NoJitter::new()),
        Box::new(UniformSum::new(2, 0.3).unwrap()),
        Box::new(Gaussian::new(0.17).unwrap()),
        Box::new(TwoPoint::new(0.13).unwrap()),
        Box::new(ExponentialDelay::new(0.21).unwrap()),
    ]
}

fn check_all<S: Signal + Clone>(signal: &S) {
    let grid = SampleGrid::new(0.0, 1.0, 30).unwrap();
    for (i, j) in jitters().iter().enumerate() {
        check_contract(signal, j.as_ref(), &grid, 31 + i as u64)
            .unwrap_or_else(|e| panic!("{}: {e}", j.name()));
    }
}

/// The whole contract (values and gradients against central differences, `m_k` and `E[s²]`
/// against the adaptive reference and Monte Carlo) for each kind of confluent model, in zpk and
/// tf form, with feed-through, delay and free response.
#[test]
fn confluent_models_pass_the_contract() {
    let u = binary(7, 3.0, -5.0, 35.0).unwrap();
    let double = Zpk::new(
        0.8,
        vec![Root::Real(-0.5)],
        vec![Root::Real(-0.7), Root::Real(-0.7)],
    )
    .unwrap();
    check_all(&LtiResponse::new(double.clone(), u.clone()));
    let integrator = Zpk::new(0.3, vec![], vec![Root::Real(0.0), Root::Real(-1.0)]).unwrap();
    check_all(&LtiResponse::new(integrator.clone(), u.clone()));
    // tf form: (s + 1)³ with a biproper numerator (the response jumps at every switch).
    let triple = TransferFunction::new(&[0.4, 1.0, 0.5, 2.0], &[1.0, 3.0, 3.0, 1.0]).unwrap();
    assert!(triple.modal().is_none());
    check_all(&LtiResponse::new(triple, u.clone()));
    let undamped = TransferFunction::new(&[1.0], &[1.0, 0.0, 1.0]).unwrap();
    check_all(&LtiResponse::new(undamped, u.clone()));
    check_all(&Delayed::new(LtiResponse::new(double.clone(), u.clone()), 0.35).unwrap());
    let free = WithInitialState::new(
        LtiResponse::new(integrator, u.clone()),
        0.0,
        vec![0.6, -0.4],
    )
    .unwrap();
    check_all(&free);
    let free = WithInitialState::new(LtiResponse::new(double, u), 0.0, vec![1.2, -0.5]).unwrap();
    check_all(&free);
}

/// Closed forms for a unit step at 0 seen far from the step (reach clear of it) under
/// Gaussian jitter, `M(z) = E[e^{zτ}] = e^{σ²z²/2}`, `E[τ e^{zτ}] = σ² z M(z)`:
/// `1/s` → `t`; `1/(s(s+1))` → `t − 1 + e^{−t} M(−1)`; `1/(s+1)²` →
/// `1 − e^{−t}((1 + t) M(−1) + E[τ e^{−τ}])`; `1/(s² + 1)` → `1 − cos t · M(i)`; and the second
/// moment of the ramp, `t² + σ²`. Tf and zpk forms both.
#[test]
fn step_responses_match_closed_forms() {
    let sigma = 0.15;
    let jitter = Gaussian::new(sigma).unwrap();
    let m1 = (sigma * sigma / 2.0).exp();
    let dm1 = -sigma * sigma * m1;
    let step = PiecewiseConstant::new(vec![0.0, 100.0], vec![1.0]).unwrap();
    let grid = SampleGrid::new(2.0, 0.5, 60).unwrap();
    let check = |name: &str, m: Vec<f64>, want: &dyn Fn(f64) -> f64| {
        for (k, t) in grid.times().enumerate() {
            let w = want(t);
            assert!(
                (m[k] - w).abs() <= 1e-12 * w.abs().max(1.0),
                "{name}, t = {t}: {} vs {w}",
                m[k]
            );
        }
    };
    let tf = |num: &[f64], den: &[f64]| {
        LtiResponse::new(TransferFunction::new(num, den).unwrap(), step.clone())
    };
    let zpk =
        |poles: Vec<Root>| LtiResponse::new(Zpk::new(1.0, vec![], poles).unwrap(), step.clone());
    for s in [tf(&[1.0], &[1.0, 0.0]), zpk_tf(zpk(vec![Root::Real(0.0)]))] {
        check("1/s", s.expected_values(&grid, &jitter), &|t| t);
        check("1/s squared", s.expected_squares(&grid, &jitter), &|t| {
            t * t + sigma * sigma
        });
    }
    for s in [
        tf(&[1.0], &[1.0, 1.0, 0.0]),
        zpk_tf(zpk(vec![Root::Real(0.0), Root::Real(-1.0)])),
    ] {
        check("1/(s(s+1))", s.expected_values(&grid, &jitter), &|t| {
            t - 1.0 + (-t).exp() * m1
        });
    }
    for s in [
        tf(&[1.0], &[1.0, 2.0, 1.0]),
        zpk_tf(zpk(vec![Root::Real(-1.0), Root::Real(-1.0)])),
    ] {
        check("1/(s+1)²", s.expected_values(&grid, &jitter), &|t| {
            1.0 - (-t).exp() * ((1.0 + t) * m1 + dm1)
        });
    }
    let mi = (-sigma * sigma / 2.0).exp();
    for s in [
        tf(&[1.0], &[1.0, 0.0, 1.0]),
        zpk_tf(zpk(vec![Root::Pair { re: 0.0, im: 1.0 }])),
    ] {
        check("1/(s²+1)", s.expected_values(&grid, &jitter), &|t| {
            1.0 - t.cos() * mi
        });
    }
}

/// The same response in tf form (coefficients of the zpk model).
fn zpk_tf(s: LtiResponse<Zpk>) -> LtiResponse<TransferFunction> {
    let r = s.model().rational();
    LtiResponse::new(
        TransferFunction::new(r.num(), r.den()).unwrap(),
        s.input().clone(),
    )
}

/// `m_k` and its gradient's columns.
type Moments = (Vec<f64>, Vec<Vec<f64>>);

/// Two real poles `−1` and `−1 − δ` as `δ` passes the switch between the modal form (`δ > 1e-4`)
/// and the realisation (`δ < 1e-4`) down to 0: `m_k` and its gradient are smooth in `δ`. A
/// quadratic through the modal side's values predicts the realisation's to its own error
/// (`δ³ m'''/6 ≈ 1e-12`) plus the modal form's rounding at this gap (`ε/δ ≈ 2e-12` of the scale),
/// so `1e-9` of the scale is tight; a wrong term on either side misses by the scale.
#[test]
fn responses_are_continuous_through_coincidence() {
    let u = binary(11, 2.0, -3.0, 40.0).unwrap();
    let grid = SampleGrid::new(0.0, 0.5, 80).unwrap();
    let jitter = UniformSum::new(1, 0.2).unwrap();
    // Two real poles as two parameters (a template with distinct poles, moved by
    // `with_params`): two equal poles given to `Zpk::new` would be one quadratic factor.
    let template = Zpk::new(
        1.5,
        vec![Root::Real(-0.4)],
        vec![Root::Real(-1.0), Root::Real(-1.5)],
    )
    .unwrap();
    let at = |delta: f64| {
        let g = template
            .with_params(&[1.5, -0.4, -1.0, -1.0 - delta])
            .unwrap();
        assert_eq!(g.modal().is_some(), delta > 1e-4, "δ = {delta}");
        LtiResponse::new(g, u.clone()).expected_values_and_gradient(&grid, &jitter)
    };
    let modal: Vec<(f64, Moments)> = [4e-4, 2.5e-4, 1.2e-4].iter().map(|&d| (d, at(d))).collect();
    let scale = modal[0].1 .0.iter().fold(1.0f64, |a, v| a.max(v.abs()));
    for delta in [0.9e-4, 3e-5, 0.0] {
        let (values, cols) = at(delta);
        // Lagrange interpolation through the three modal points.
        let predict = |pick: &dyn Fn(&Moments) -> f64| -> f64 {
            let mut sum = 0.0;
            for (i, (di, vi)) in modal.iter().enumerate() {
                let mut l = 1.0;
                for (j, (dj, _)) in modal.iter().enumerate() {
                    if i != j {
                        l *= (delta - dj) / (di - dj);
                    }
                }
                sum += l * pick(vi);
            }
            sum
        };
        for k in 0..grid.len() {
            let want = predict(&|v| v.0[k]);
            assert!(
                (values[k] - want).abs() <= 1e-9 * scale,
                "δ = {delta}, k = {k}: {} vs {want}",
                values[k]
            );
            // Gradients: the modal form's rounding is `ε/δ²` (2e-8 at this gap), amplified by
            // the extrapolation's weights (about 10): 1e-6 of the scale.
            for (j, col) in cols.iter().enumerate() {
                let want = predict(&|v| v.1[j][k]);
                assert!(
                    (col[k] - want).abs() <= 1e-6 * scale,
                    "δ = {delta}, param {j}, k = {k}: {} vs {want}",
                    col[k]
                );
            }
        }
    }
}

/// An unstable pole is refused unless asked for; then it is kept by `with_params` and through
/// serde, and its (growing) response still matches the ODE.
#[test]
fn unstable_poles_only_when_asked_for() {
    assert!(Zpk::new(1.0, vec![], vec![Root::Real(0.01)]).is_err());
    assert!(TransferFunction::new(&[1.0], &[1.0, -0.5, 1.0]).is_err());
    assert!(TransferFunction::new(&[1.0], &[1.0, 1.0, 0.0]).is_ok());
    let g = TransferFunction::new_allowing_unstable(&[0.5, 1.0], &[1.0, -0.3, 1.0]).unwrap();
    assert!(g.rational().allows_unstable() && g.modal().is_none());
    let moved = g.with_params(&[0.5, 1.0, -0.2, 1.1]).unwrap();
    assert!(moved.rational().allows_unstable());
    let json = serde_json::to_string(&g).unwrap();
    let back: TransferFunction = serde_json::from_str(&json).unwrap();
    assert_eq!(back, g);
    let z =
        Zpk::new_allowing_unstable(1.0, vec![], vec![Root::Real(0.2), Root::Real(-1.0)]).unwrap();
    assert!(z.with_params(&[1.0, 0.3, -1.0]).is_ok());
    let u = binary(3, 2.0, 0.0, 10.0).unwrap();
    let times: Vec<f64> = (1..=40).map(|k| 0.25 * k as f64).collect();
    let ode = ode_response(g.rational().num(), g.rational().den(), &u, &times, 1e-3);
    let s = LtiResponse::new(g, u);
    let scale = ode.iter().fold(1.0f64, |a, y| a.max(y.abs()));
    for (t, want) in times.iter().zip(&ode) {
        assert!((s.value(*t) - want).abs() <= 1e-8 * scale, "t = {t}");
    }
}
