//! The free response from an unknown initial state and the input delay: the signal contract
//! (values, gradients against finite differences, moments against a reference integration and
//! Monte Carlo), and each against an independent construction.

use jitterid_jitter::{
    ExponentialDelay, Gaussian, JitterModel, Laplace, NoJitter, Shifted, TwoPoint, UniformSum,
};
use jitterid_signal::testing::{binary, check_contract, eq17};
use jitterid_signal::{
    Delayed, LtiResponse, Multisine, PiecewiseConstant, Root, SampleGrid, Signal, SignalError,
    TransferFunction, WithInitialState, Zpk,
};

fn jitters() -> Vec<Box<dyn JitterModel>> {
    vec![
        Box::new(NoJitter::new()),
        Box::new(UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap()),
        Box::new(Gaussian::new(0.17).unwrap()),
        Box::new(TwoPoint::new(0.13).unwrap()),
        Box::new(ExponentialDelay::new(0.21).unwrap()),
        Box::new(Laplace::new(0.1).unwrap()),
        Box::new(Shifted::new(UniformSum::new(0, 0.3).unwrap(), 0.1).unwrap()),
    ]
}

fn grid() -> SampleGrid {
    SampleGrid::new(0.0, 1.0, 30).unwrap()
}

fn check_all<S: Signal + Clone>(signal: &S) {
    check_with(signal, jitters());
}

/// The delayed responses leave out the Laplace family: a step in its tail moves `m_k` by an
/// event too rare for the contract's 4 000 draws, whose standard error then reads near zero.
/// The delay only moves the grid, and `delay_equals_shifted_input` covers Laplace exactly.
fn check_delayed<S: Signal + Clone>(signal: &S) {
    let mut js = jitters();
    js.retain(|j| j.name() != "laplace");
    check_with(signal, js);
}

fn check_with<S: Signal + Clone>(signal: &S, jitters: Vec<Box<dyn JitterModel>>) {
    for (i, j) in jitters.iter().enumerate() {
        check_contract(signal, j.as_ref(), &grid(), 21 + i as u64)
            .unwrap_or_else(|e| panic!("{}: {e}", j.name()));
    }
}

fn pair_and_real() -> Zpk {
    Zpk::new(
        0.8,
        vec![Root::Real(-0.5)],
        vec![Root::Pair { re: -0.3, im: 0.7 }, Root::Real(-0.9)],
    )
    .unwrap()
}

#[test]
fn delayed_response_passes() {
    let u = binary(3, 4.0, -5.0, 35.0).unwrap();
    check_delayed(&Delayed::new(LtiResponse::new(pair_and_real(), u), 1.37).unwrap());
}

#[test]
fn delayed_biproper_response_passes() {
    // Direct feed-through: ∂m_k/∂D carries the jitter's density at the steps.
    let g = TransferFunction::new(&[0.3, 1.0, 0.8], &[1.0, 1.5, 0.9]).unwrap();
    let u = binary(5, 3.0, -5.0, 35.0).unwrap();
    check_delayed(&Delayed::new(LtiResponse::new(g, u), 0.61).unwrap());
}

#[test]
fn free_response_passes() {
    let u = binary(7, 4.0, 0.0, 35.0).unwrap();
    let s = LtiResponse::new(pair_and_real(), u);
    check_all(&WithInitialState::new(s, 0.0, vec![0.4, -0.7, 1.1]).unwrap());
}

#[test]
fn free_response_of_a_delayed_tf_passes() {
    // Transfer-function parameters move both poles of the pair: ∂c_i/∂θ through A'(p_i).
    let g = TransferFunction::new(&[0.5, 1.0], &[1.0, 0.8, 0.6]).unwrap();
    let u = binary(9, 4.0, 0.0, 35.0).unwrap();
    let d = Delayed::new(LtiResponse::new(g, u), 2.2).unwrap();
    check_all(&WithInitialState::new(d, 0.0, vec![-0.3, 0.9]).unwrap());
}

#[test]
fn free_response_with_tones_passes() {
    let g = TransferFunction::new(&[1.0, 0.5], &[1.0, 1.2, 0.8]).unwrap();
    let u = Multisine::sine(0.13, 1.5, 0.2).unwrap();
    check_all(&WithInitialState::new(LtiResponse::new(g, u), 0.0, vec![0.5, 0.25]).unwrap());
}

/// The delay against the input shifted by hand: the same moments, up to rounding.
#[test]
fn delay_equals_shifted_input() {
    let u = binary(11, 3.0, 0.0, 40.0).unwrap();
    let d = 1.73;
    let shifted = PiecewiseConstant::new(
        u.edges().iter().map(|e| e + d).collect(),
        u.levels().to_vec(),
    )
    .unwrap();
    let delayed = Delayed::new(LtiResponse::new(pair_and_real(), u), d).unwrap();
    let by_hand = LtiResponse::new(pair_and_real(), shifted);
    for j in jitters() {
        let (a, b) = (
            delayed.expected_values(&grid(), j.as_ref()),
            by_hand.expected_values(&grid(), j.as_ref()),
        );
        let (qa, qb) = (
            delayed.expected_squares(&grid(), j.as_ref()),
            by_hand.expected_squares(&grid(), j.as_ref()),
        );
        for k in 0..a.len() {
            assert!(
                (a[k] - b[k]).abs() < 1e-12,
                "{}: m[{k}] {} vs {}",
                j.name(),
                a[k],
                b[k]
            );
            assert!((qa[k] - qb[k]).abs() < 1e-12, "{}: E s²[{k}]", j.name());
        }
    }
}

/// An input that ran before `t0` leaves, after `t0`, the response to the input from `t0` on
/// plus a free response: `q` solved from `n` instants reproduces every other instant.
#[test]
fn past_input_is_a_free_response() {
    let g = pair_and_real();
    let full = binary(13, 3.0, -20.0, 40.0).unwrap();
    let from_t0 = {
        let (edges, levels) = (full.edges(), full.levels());
        let first = edges.partition_point(|&e| e <= 0.0);
        let mut e = vec![0.0];
        e.extend_from_slice(&edges[first..]);
        let mut l = vec![full.value(0.0)];
        l.extend_from_slice(&levels[first..]);
        PiecewiseConstant::new(e, l).unwrap()
    };
    let truth = LtiResponse::new(g.clone(), full);
    let partial = LtiResponse::new(g, from_t0);
    // f is linear in q: columns from unit q's, then solve the 3×3 system at three instants.
    let probe = [0.05, 0.4, 1.1];
    let unit = |j: usize| {
        let mut q = vec![0.0; 3];
        q[j] = 1.0;
        WithInitialState::new(partial.clone(), 0.0, q).unwrap()
    };
    let cols: Vec<_> = (0..3).map(unit).collect();
    let a: Vec<Vec<f64>> = probe
        .iter()
        .map(|&t| cols.iter().map(|c| c.free_value(t)).collect())
        .collect();
    let rhs: Vec<f64> = probe
        .iter()
        .map(|&t| truth.value(t) - partial.value(t))
        .collect();
    let q = solve3(a, rhs);
    let fitted = WithInitialState::new(partial, 0.0, q).unwrap();
    for k in 0..200 {
        let t = 0.013 + 0.2 * k as f64;
        let (x, y) = (truth.value(t), fitted.value(t));
        assert!((x - y).abs() < 1e-9, "t = {t}: {x} vs {y}");
    }
}

fn solve3(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    for c in 0..3 {
        let p = (c..3)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..3 {
            let f = a[r][c] / a[c][c];
            let pivot = a[c].clone();
            for (x, y) in a[r][c..].iter_mut().zip(&pivot[c..]) {
                *x -= f * y;
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; 3];
    for r in (0..3).rev() {
        let s: f64 = (r + 1..3).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    x
}

#[test]
fn bad_input_is_named() {
    let u = binary(3, 4.0, -5.0, 35.0).unwrap();
    let s = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), u);
    assert!(matches!(
        WithInitialState::new(s.clone(), 0.0, vec![1.0]),
        Err(SignalError::WrongLength {
            name: "initial",
            expected: 2,
            got: 1
        })
    ));
    assert!(matches!(
        Delayed::new(s, f64::NAN),
        Err(SignalError::NotFinite { name: "delay", .. })
    ));
    let tones = LtiResponse::new(
        eq17(0.2, 0.5, -0.25, 0.3).unwrap(),
        Multisine::sine(0.1, 1.0, 0.0).unwrap(),
    );
    assert!(matches!(
        Delayed::new(tones, 1.0),
        Err(SignalError::NeedsSteps { .. })
    ));
}

/// The registry's `delay`, `initial` and `origin` keys: parameters named and ordered, the
/// spec rebuilt, and bad values named by key.
#[test]
fn registry_builds_delay_and_initial_state() {
    use jitterid_signal::registry::SignalRegistry;
    let input = binary(1, 8.0, 0.0, 200.0).unwrap().into();
    let registry = SignalRegistry::builtin();
    let spec = serde_json::json!({
        "kind": "tf", "num": [0.5], "den": [1.0, 0.8, 0.6],
        "delay": 1.5, "initial": [0.1, -0.2], "origin": 3.0,
    });
    let s = registry
        .build(spec.as_object().unwrap(), Some(&input))
        .unwrap();
    assert_eq!(
        s.param_names(),
        ["b0", "a1", "a0", "delay", "initial.0", "initial.1"]
    );
    assert_eq!(s.params(), [0.5, 0.8, 0.6, 1.5, 0.1, -0.2]);
    let t = s.with_params(&[0.5, 0.8, 0.6, 2.0, 0.3, 0.0]).unwrap();
    assert_eq!(t.spec()["delay"], serde_json::json!(2.0));
    assert_eq!(t.spec()["origin"], serde_json::json!(3.0));
    let again = registry.build(&t.spec(), Some(&input)).unwrap();
    assert_eq!(again.params(), t.params());
    let plain = serde_json::json!({"kind": "zpk", "gain": 1.0, "poles": [-1.0]});
    let p = registry
        .build(plain.as_object().unwrap(), Some(&input))
        .unwrap();
    assert_eq!(p.param_names(), ["gain", "pole0"]);
    for (key, bad) in [
        ("delay", serde_json::json!(-1.0)),
        ("initial", serde_json::json!([1.0])),
        ("origin", serde_json::json!(f64::NAN)),
    ] {
        let mut spec = serde_json::json!({"kind": "zpk", "gain": 1.0, "poles": [-1.0, -2.0]});
        spec[key] = bad;
        if key == "origin" {
            spec["initial"] = serde_json::json!([0.0, 0.0]);
            spec["origin"] = serde_json::json!("later");
        }
        let e = registry
            .build(spec.as_object().unwrap(), Some(&input))
            .unwrap_err();
        assert_eq!(e.key(), Some(key), "{e}");
    }
}

#[test]
fn a_delayed_input_is_the_input_moved_later_and_tones_are_refused() {
    let u: jitterid_signal::Input = PiecewiseConstant::new(vec![0.0, 2.5, 7.0], vec![1.0, -0.5])
        .unwrap()
        .into();
    let d = 1.3;
    let late = u.delayed(d).unwrap();
    for t in [-1.0, 0.0, 1.0, 1.3, 3.0, 3.8, 8.2, 8.3, 12.0] {
        assert_eq!(late.value(t), u.value(t - d), "t = {t}");
    }
    assert!(matches!(
        u.delayed(f64::NAN),
        Err(SignalError::NotFinite { name: "delay", .. })
    ));
    let tones: jitterid_signal::Input = Multisine::sine(0.1, 1.0, 0.0).unwrap().into();
    assert!(matches!(
        tones.delayed(d),
        Err(SignalError::NeedsSteps { .. })
    ));
}
