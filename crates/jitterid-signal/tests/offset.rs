//! The output offset `y₀ + s(t)`: the signal contract (values, gradients against finite
//! differences, jittered moments against the reference integration and Monte Carlo), and its
//! moments against the inner signal's by the independent identities `E[y₀ + s] = y₀ + E[s]`
//! and `E[(y₀ + s)²] = y₀² + 2y₀E[s] + E[s²]` computed from the inner signal alone.

mod wrapper;

use wrapper::{check_all, grid, jitters, response};

use jitterid_signal::registry::SignalRegistry;
use jitterid_signal::testing::binary;
use jitterid_signal::{Offset, Signal, SignalError, Spectrum, WithInitialState};

#[test]
fn estimated_and_known_offsets_pass_the_contract() {
    check_all(&Offset::new(response(), 1.7, true).unwrap(), 31);
    check_all(&Offset::new(response(), -0.4, false).unwrap(), 31);
    let free = WithInitialState::new(response(), 0.0, vec![0.3, -0.2]).unwrap();
    check_all(&Offset::new(free, 2.5, true).unwrap(), 31);
}

#[test]
fn the_offset_is_the_last_parameter_only_when_estimated() {
    let inner = response();
    let est = Offset::new(inner.clone(), 1.7, true).unwrap();
    let mut names = inner.param_names();
    names.push("offset".into());
    assert_eq!(est.param_names(), names);
    assert_eq!(est.params().last(), Some(&1.7));
    let known = Offset::new(inner.clone(), 1.7, false).unwrap();
    assert_eq!(known.param_names(), inner.param_names());
    assert_eq!(known.params(), inner.params());
    // A known offset survives a change of the other parameters.
    let moved = known.with_params(&[0.3, 0.5, -0.25, 0.3]).unwrap();
    assert_eq!(moved.offset(), 1.7);
    assert_eq!(moved.value(4.0), 1.7 + moved.signal().value(4.0));
}

#[test]
fn moments_are_the_inner_moments_moved_by_the_constant() {
    let inner = response();
    let y0 = -0.83;
    let s = Offset::new(inner.clone(), y0, true).unwrap();
    let g = grid();
    for j in jitters() {
        let (m, m_in) = (
            s.expected_values(&g, j.as_ref()),
            inner.expected_values(&g, j.as_ref()),
        );
        let (s2, s2_in) = (
            s.expected_squares(&g, j.as_ref()),
            inner.expected_squares(&g, j.as_ref()),
        );
        for k in 0..g.len() {
            assert!((m[k] - (m_in[k] + y0)).abs() <= 1e-14 * (1.0 + m_in[k].abs()));
            let want = y0 * y0 + 2.0 * y0 * m_in[k] + s2_in[k];
            assert!(
                (s2[k] - want).abs() <= 1e-13 * (1.0 + want.abs()),
                "{}",
                j.name()
            );
            // The variance is the inner signal's: a constant adds none.
            let (var, var_in) = (s2[k] - m[k] * m[k], s2_in[k] - m_in[k] * m_in[k]);
            assert!(
                (var - var_in).abs() <= 1e-12,
                "{}: {var} vs {var_in}",
                j.name()
            );
        }
        let cols = s.expected_values_gradient(&g, j.as_ref());
        assert_eq!(cols.len(), inner.num_params() + 1);
        assert!(cols.last().unwrap().iter().all(|&c| c == 1.0));
    }
}

#[test]
fn the_spectrum_gains_one_line_at_zero() {
    let s = Offset::new(response(), 0.6, true).unwrap();
    let lines = s.lines();
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].frequency, 0.0);
    assert_eq!(lines[0].coefficient.re, 0.6);
    let grad = s.lines_gradient();
    assert_eq!(grad[0].len(), s.num_params());
    assert_eq!(grad[0][s.num_params() - 1].0.re, 1.0);
    assert!(grad[0][..s.num_params() - 1]
        .iter()
        .all(|g| g.0.norm() == 0.0));
    assert_eq!(s.density(0.1), s.signal().density(0.1));
}

#[test]
fn bad_offsets_are_typed_errors() {
    for bad in [f64::NAN, f64::INFINITY] {
        let e = Offset::new(response(), bad, true).unwrap_err();
        assert!(
            matches!(e, SignalError::NotFinite { name: "offset", .. }),
            "{e:?}"
        );
    }
    let s = Offset::new(response(), 0.5, true).unwrap();
    assert!(matches!(
        s.with_params(&[0.2, 0.5, -0.25, 0.3]),
        Err(SignalError::WrongParamCount {
            expected: 5,
            got: 4
        })
    ));
}

#[test]
fn the_registry_builds_and_writes_back_the_offset() {
    let input = binary(1, 8.0, 0.0, 200.0).unwrap().into();
    let registry = SignalRegistry::builtin();
    let spec = serde_json::json!({
        "kind": "zpk", "gain": 0.2, "zeros": [-0.5], "poles": [[-0.25, 0.3]],
        "offset": 1.5, "estimate_offset": true,
    });
    let s = registry
        .build(spec.as_object().unwrap(), Some(&input))
        .unwrap();
    assert_eq!(s.param_names().last().map(String::as_str), Some("offset"));
    assert_eq!(s.params(), [0.2, -0.5, -0.25, 0.3, 1.5]);
    let moved = s.with_params(&[0.2, -0.5, -0.25, 0.3, -2.0]).unwrap();
    assert_eq!(moved.spec()["offset"], serde_json::json!(-2.0));
    assert_eq!(moved.spec()["estimate_offset"], serde_json::json!(true));
    assert_eq!(moved.with_input(&input).unwrap(), moved);
    assert!(moved.has_spectrum());
    // Known: a constant of the model, not a parameter.
    let known = serde_json::json!({"kind": "tf", "num": [1.0], "den": [1.0, 2.0], "offset": 0.25});
    let k = registry
        .build(known.as_object().unwrap(), Some(&input))
        .unwrap();
    assert_eq!(k.param_names(), ["b0", "a0"]);
    assert_eq!(k.value(-1.0), 0.25);
    // Without the keys: the unwrapped response, bit for bit.
    let plain = serde_json::json!({"kind": "tf", "num": [1.0], "den": [1.0, 2.0]});
    let p = registry
        .build(plain.as_object().unwrap(), Some(&input))
        .unwrap();
    assert_eq!(p.spec().get("offset"), None);
    for (bad, key) in [
        (
            serde_json::json!({"kind": "tf", "num": [1.0], "den": [1.0, 2.0], "offset": "x"}),
            "offset",
        ),
        (
            serde_json::json!({"kind": "tf", "num": [1.0], "den": [1.0, 2.0], "estimate_offset": 1}),
            "estimate_offset",
        ),
    ] {
        let e = registry
            .build(bad.as_object().unwrap(), Some(&input))
            .unwrap_err();
        assert_eq!(e.key(), Some(key), "{e}");
    }
}
