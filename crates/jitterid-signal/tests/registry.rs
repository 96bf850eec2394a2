//! The signal registry: every built-in kind builds from its spec table, passes the contract as an
//! `AnySignal`, rebuilds from its own spec, and bad tables name the offending key.

use jitterid_jitter::UniformSum;
use jitterid_signal::registry::{SignalKind, SignalRegistry, SpecTable};
use jitterid_signal::testing::{binary, check_contract};
use jitterid_signal::{AnySignal, Input, SampleGrid, Signal, SignalError, Sinusoid, Spectrum};
use serde_json::json;

fn table(v: serde_json::Value) -> SpecTable {
    v.as_object().cloned().unwrap()
}

fn input() -> Input {
    binary(4, 4.0, -5.0, 35.0).unwrap().into()
}

fn specs() -> Vec<SpecTable> {
    vec![
        table(json!({"kind": "zpk", "gain": 0.2, "zeros": [-0.5], "poles": [[-0.25, 0.3]]})),
        table(json!({"kind": "tf", "num": [0.3, 1.0], "den": [1.0, 1.5, 0.9]})),
        // Structural integrators: held at the origin, kept by the spec.
        table(json!({"kind": "tf", "num": [0.5], "den": [1.0, 1.5, 0.0], "integrators": 1})),
        table(json!({"kind": "zpk", "gain": 0.5, "poles": [0.0, -1.5, 0.0], "integrators": 2})),
        table(json!({"kind": "sinusoid", "amplitude": 1.3, "frequency": 0.27, "phase": 0.4})),
        table(
            json!({"kind": "pulse-response", "coefficients": [0.6, 0.3, -0.15], "interval": 0.5}),
        ),
        // Around an input level: estimated, with a delay; known, on a grey-box model's
        // transfer-function route.
        table(
            json!({"kind": "zpk", "gain": 0.2, "zeros": [-0.5], "poles": [[-0.25, 0.3]],
                     "delay": 0.4, "level": 0.35, "estimate_level": true}),
        ),
        table(json!({
            "kind": "grey-box", "params": {"m": 1.0, "damp": 0.4}, "fixed": {"k": 2.0},
            "a": [["0", "1"], ["-k/m", "-damp/m"]], "b": [[0], ["1/m"]], "c": [[1, 0]],
            "level": -0.5,
        })),
        // A mass–spring–damper with a known constant and a bound.
        table(json!({
            "kind": "grey-box", "params": {"m": 1.0, "damp": 0.4}, "fixed": {"k": 2.0},
            "bounds": {"m": [0.0, 1e3]}, "a": [["0", "1"], ["-k/m", "-damp/m"]],
            "b": [[0], ["1/m"]], "c": [[1, 0]], "d": [["0.1"]],
        })),
    ]
}

#[test]
fn every_builtin_kind_builds_passes_the_contract_and_rebuilds() {
    let registry = SignalRegistry::builtin();
    let names: Vec<&str> = registry.kinds().map(SignalKind::name).collect();
    assert_eq!(
        names,
        ["zpk", "tf", "sinusoid", "pulse-response", "grey-box"]
    );
    let grid = SampleGrid::new(0.0, 1.0, 30).unwrap();
    let jitter = UniformSum::new(2, 0.2887).unwrap();
    let u = input();
    for spec in specs() {
        let s = registry.build(&spec, Some(&u)).unwrap();
        assert!(s.has_spectrum());
        check_contract(&s, &jitter, &grid, 5).unwrap();
        // The spec written by the model rebuilds it (with the same input).
        let again = registry.build(&s.spec(), Some(&u)).unwrap();
        assert_eq!(again, s);
        assert_eq!(again.params(), s.params());
        // Fast routes are forwarded: the same numbers as the model itself.
        assert_eq!(
            s.expected_values(&grid, &jitter),
            s.model().expected_values(&grid, &jitter)
        );
        for kind in registry.kind(s.kind()).unwrap().params() {
            assert!(!kind.meaning.is_empty() && !kind.constraint.is_empty());
        }
    }
}

#[test]
fn bad_tables_name_the_key() {
    let registry = SignalRegistry::builtin();
    let u = input();
    let cases = [
        (json!({"gain": 1.0}), "kind"),
        (json!({"kind": "nope"}), "kind"),
        (json!({"kind": 3}), "kind"),
        (json!({"kind": "zpk", "gain": 1.0}), "poles"),
        (json!({"kind": "zpk", "gain": 1.0, "poles": [0.5]}), "poles"),
        (
            json!({"kind": "zpk", "gain": 1.0, "poles": [[-1.0, -2.0]]}),
            "poles",
        ),
        // An unstable pole, unless asked for; the permission must be a boolean.
        (json!({"kind": "zpk", "gain": 1.0, "poles": [0.5]}), "poles"),
        (
            json!({"kind": "tf", "num": [1.0], "den": [1.0, -0.5], "unstable": "yes"}),
            "unstable",
        ),
        (json!({"kind": "zpk", "gain": "x", "poles": [-1.0]}), "gain"),
        // More integrators than poles at the origin, or not a whole number.
        (
            json!({"kind": "tf", "num": [1.0], "den": [1.0, 1.0, 0.0], "integrators": 2}),
            "integrators",
        ),
        (
            json!({"kind": "zpk", "gain": 1.0, "poles": [-1.0], "integrators": 1}),
            "integrators",
        ),
        (
            json!({"kind": "zpk", "gain": 1.0, "poles": [0.0], "integrators": 0.5}),
            "integrators",
        ),
        (
            json!({"kind": "zpk", "gain": 1.0, "zeros": [1.0, 2.0], "poles": [-1.0]}),
            "zeros",
        ),
        (
            json!({"kind": "zpk", "gain": 1.0, "poles": [-1.0], "gian": 2.0}),
            "gian",
        ),
        (
            json!({"kind": "tf", "num": [1.0], "den": [0.0, 1.0]}),
            "den",
        ),
        (
            json!({"kind": "tf", "num": [1.0, 0.0, 0.0], "den": [1.0, 1.0]}),
            "num",
        ),
        (json!({"kind": "tf", "num": 1.0, "den": [1.0, 1.0]}), "num"),
        (
            json!({"kind": "sinusoid", "amplitude": 1.0, "frequency": -1.0}),
            "frequency",
        ),
        (
            json!({"kind": "pulse-response", "coefficients": [], "interval": 1.0}),
            "coefficients",
        ),
        (
            json!({"kind": "pulse-response", "coefficients": [1.0], "interval": -1.0}),
            "interval",
        ),
    ];
    for (spec, key) in cases {
        let e = registry.build(&table(spec.clone()), Some(&u)).unwrap_err();
        assert_eq!(e.key(), Some(key), "{spec}: {e}");
    }
    let e = registry
        .build(
            &table(json!({"kind": "tf", "num": [1.0], "den": [1.0, 1.0]})),
            None,
        )
        .unwrap_err();
    assert!(matches!(e, SignalError::MissingInput { .. }), "{e}");
    let tones: Input = jitterid_signal::Multisine::sine(0.1, 1.0, 0.0)
        .unwrap()
        .into();
    let e = registry
        .build(
            &table(json!({"kind": "pulse-response", "coefficients": [1.0], "interval": 1.0})),
            Some(&tones),
        )
        .unwrap_err();
    assert_eq!(e.key(), Some("kind"), "{e}");
}

#[test]
fn a_kind_registered_at_run_time_builds() {
    let mut registry = SignalRegistry::builtin().clone();
    let kind = SignalKind::new(
        "tone",
        "a sinusoid of unit amplitude",
        vec![],
        false,
        |_, _| {
            let s = Sinusoid::new(1.0, 0.1, 0.0)?;
            Ok(AnySignal::new("tone", s, |_| SpecTable::new()))
        },
    );
    registry.register(kind.clone()).unwrap();
    assert!(matches!(
        registry.register(kind),
        Err(SignalError::DuplicateKind { .. })
    ));
    let s = registry
        .build(&table(json!({"kind": "tone"})), None)
        .unwrap();
    assert!(!s.has_spectrum());
    assert!(s.density(0.1).re.is_nan());
    assert_eq!(s.params(), [1.0, 0.1, 0.0]);
}
