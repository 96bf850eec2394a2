//! The input level `G (u − u₀ 1)`: the signal contract (values, gradients against finite
//! differences, jittered moments against the reference integration and Monte Carlo) for every
//! response it wraps, and its moments against two independent routes: the same system built by
//! hand on the shifted input, and linearity, `E[G(u − u₀1)] = E[Gu] − u₀ E[G1]`.

mod wrapper;

use wrapper::{check_all, grid, input, jitters, response};

use jitterid_signal::registry::SignalRegistry;
use jitterid_signal::testing::eq17;
use jitterid_signal::{
    Delayed, Input, InputLevel, LtiResponse, Multisine, PiecewiseConstant, Root, Signal,
    SignalError, Tone, WithInitialState, Zpk,
};

/// `1/s · 0.5/(s + 1.5)`: an integrator, whose response to a level is a ramp.
fn integrating() -> LtiResponse<Zpk> {
    let g = Zpk::new(0.5, vec![], vec![Root::Real(0.0), Root::Real(-1.5)])
        .unwrap()
        .with_integrators(1)
        .unwrap();
    LtiResponse::new(g, input())
}

fn tones() -> Input {
    Input::Tones(
        Multisine::new(vec![
            Tone {
                frequency: 0.05,
                amplitude: 1.0,
                phase: 0.3,
            },
            Tone {
                frequency: 0.11,
                amplitude: 0.4,
                phase: -1.0,
            },
        ])
        .unwrap(),
    )
}

#[test]
fn estimated_and_known_levels_pass_the_contract() {
    check_all(&InputLevel::new(response(), 0.35, true).unwrap(), 41);
    check_all(&InputLevel::new(response(), -0.6, false).unwrap(), 41);
    let delayed = Delayed::new(response(), 0.7).unwrap();
    check_all(&InputLevel::new(delayed, 0.35, true).unwrap(), 41);
    check_all(&InputLevel::new(integrating(), 0.2, true).unwrap(), 41);
    let level = InputLevel::new(response(), 0.35, true).unwrap();
    check_all(
        &WithInitialState::new(level, 0.0, vec![0.3, -0.2]).unwrap(),
        41,
    );
    let sines = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), tones());
    check_all(&InputLevel::new(sines, 0.8, true).unwrap(), 41);
}

/// The shifted input built by hand: the same response, so bit for bit the same numbers.
#[test]
fn a_level_is_the_response_to_the_input_shifted_by_hand() {
    let u = input();
    let u0 = 0.35;
    let shifted = PiecewiseConstant::new(
        u.edges().to_vec(),
        u.levels().iter().map(|v| v - u0).collect(),
    )
    .unwrap();
    let by_hand = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), shifted);
    let s = InputLevel::new(response(), u0, true).unwrap();
    let g = grid();
    for j in jitters() {
        let j = j.as_ref();
        assert_eq!(s.expected_values(&g, j), by_hand.expected_values(&g, j));
        assert_eq!(s.expected_squares(&g, j), by_hand.expected_squares(&g, j));
    }
}

/// Linearity from the unshifted response and the response to one step over the input's span,
/// built separately: `m = m(u) − u₀ m(1)`, and the level's gradient column `−m(1)`.
#[test]
fn moments_and_the_level_s_column_follow_from_linearity() {
    let u = input();
    let edges = u.edges();
    let span = PiecewiseConstant::new(vec![edges[0], edges[edges.len() - 1]], vec![1.0]).unwrap();
    let g17 = eq17(0.2, 0.5, -0.25, 0.3).unwrap();
    let (plain, unit) = (
        LtiResponse::new(g17.clone(), u.clone()),
        LtiResponse::new(g17, span),
    );
    let u0 = -0.8;
    let s = InputLevel::new(response(), u0, true).unwrap();
    let g = grid();
    for j in jitters() {
        let j = j.as_ref();
        let (m, cols) = s.expected_values_and_gradient(&g, j);
        let (mp, mu) = (plain.expected_values(&g, j), unit.expected_values(&g, j));
        let scale = mp.iter().fold(1.0f64, |a, v| a.max(v.abs()));
        let level = cols.last().unwrap();
        for k in 0..g.len() {
            let want = mp[k] - u0 * mu[k];
            assert!((m[k] - want).abs() <= 1e-12 * scale, "{}: m[{k}]", j.name());
            assert!(
                (level[k] + mu[k]).abs() <= 1e-12 * scale,
                "{}: ∂m[{k}]",
                j.name()
            );
        }
    }
}

#[test]
fn the_level_is_the_last_parameter_only_when_estimated() {
    let inner = response();
    let est = InputLevel::new(inner.clone(), 0.35, true).unwrap();
    let mut names = inner.param_names();
    names.push("level".into());
    assert_eq!(est.param_names(), names);
    assert_eq!(est.params().last(), Some(&0.35));
    let known = InputLevel::new(inner.clone(), 0.35, false).unwrap();
    assert_eq!(known.param_names(), inner.param_names());
    let moved = est.with_params(&[0.3, -0.5, -0.25, 0.3, -1.0]).unwrap();
    assert_eq!(moved.level(), -1.0);
    let again = InputLevel::new(
        LtiResponse::new(eq17(0.3, 0.5, -0.25, 0.3).unwrap(), input()),
        -1.0,
        true,
    )
    .unwrap();
    assert_eq!(moved, again);
    assert!(est.with_params(&[0.3, 0.5, -0.25, 0.3, f64::NAN]).is_err());
}

#[test]
fn only_a_settling_response_is_confounded_with_an_offset() {
    assert!(InputLevel::new(response(), 0.3, true).unwrap().settles());
    assert!(!InputLevel::new(integrating(), 0.3, true).unwrap().settles());
}

#[test]
fn a_tone_input_to_an_integrator_has_no_level() {
    let g = integrating().model().clone();
    let e = InputLevel::new(LtiResponse::new(g, tones()), 0.3, false).unwrap_err();
    assert!(
        matches!(e, SignalError::OutOfRange { name: "level", .. }),
        "{e}"
    );
    assert!(matches!(
        InputLevel::new(response(), f64::INFINITY, false).unwrap_err(),
        SignalError::NotFinite { name: "level", .. }
    ));
}

/// The registry builds the wrapper from the keys `level` and `estimate_level`, in its place
/// among the response's parameters (the model's, the delay, the level, the free response, the
/// offset), and writes both keys back.
#[test]
fn the_registry_builds_a_level_between_the_delay_and_the_free_response() {
    let spec = serde_json::json!({
        "kind": "zpk", "gain": 0.2, "zeros": [-0.5], "poles": [[-0.25, 0.3]],
        "delay": 0.4, "initial": [0.1, -0.2], "origin": 0.0,
        "level": 0.35, "estimate_level": true, "offset": 1.0, "estimate_offset": true,
    });
    let spec = spec.as_object().unwrap().clone();
    let u: Input = input().into();
    let s = SignalRegistry::builtin().build(&spec, Some(&u)).unwrap();
    assert_eq!(
        s.param_names(),
        [
            "gain",
            "zero0",
            "pole0.re",
            "pole0.im",
            "delay",
            "level",
            "initial.0",
            "initial.1",
            "offset"
        ]
    );
    let back = s.spec();
    assert_eq!(back.get("level"), Some(&serde_json::json!(0.35)));
    assert_eq!(back.get("estimate_level"), Some(&serde_json::json!(true)));
    let e = SignalRegistry::builtin()
        .build(
            &serde_json::json!({"kind": "tf", "num": [1.0], "den": [1.0, 0.5], "level": "high"})
                .as_object()
                .unwrap()
                .clone(),
            Some(&u),
        )
        .unwrap_err();
    assert_eq!(e.key(), Some("level"), "{e}");
}
