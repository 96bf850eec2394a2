//! No panic through a public door: functions with a slice-length contract return a typed error
//! for wrong lengths, and the solver types read from arbitrary JSON either fail to read or come
//! out valid.

use jitterid_estimate::solver::{
    LeastSquares, LevenbergMarquardt, LmOptions, Solver, SolverError, Transform, Transformed,
};
use jitterid_likelihood::{delta_method_std, MlError};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// Residuals `θ − 1`, one per parameter.
struct Shift(usize);

impl LeastSquares for Shift {
    fn num_params(&self) -> usize {
        self.0
    }
    fn num_residuals(&self) -> usize {
        self.0
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(p.iter().map(|x| x - 1.0).collect())
    }
}

/// Arbitrary JSON of small depth.
fn json() -> impl Strategy<Value = serde_json::Value> {
    let leaf = prop_oneof![
        Just(serde_json::Value::Null),
        any::<bool>().prop_map(serde_json::Value::Bool),
        any::<f64>().prop_map(|x| serde_json::json!(x)),
        any::<i64>().prop_map(|x| serde_json::json!(x)),
        "[a-z_]{0,16}".prop_map(serde_json::Value::String),
        prop_oneof![
            Just("Marquardt"),
            Just("Identity"),
            Just("Free"),
            Just("Positive"),
            Just("Bounded"),
        ]
        .prop_map(|s| serde_json::Value::String(s.to_string())),
    ];
    leaf.prop_recursive(3, 24, 8, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..8).prop_map(serde_json::Value::Array),
            prop::collection::vec(
                (
                    prop_oneof![
                        Just("max_iters".to_string()),
                        Just("xtol".to_string()),
                        Just("ftol".to_string()),
                        Just("gtol".to_string()),
                        Just("initial_lambda".to_string()),
                        Just("scaling".to_string()),
                        Just("max_seconds".to_string()),
                        Just("Bounded".to_string()),
                        Just("lo".to_string()),
                        Just("hi".to_string()),
                        "[a-z]{1,6}",
                    ],
                    inner
                ),
                0..8
            )
            .prop_map(|kv| serde_json::Value::Object(kv.into_iter().collect())),
        ]
    })
}

fn config() -> Config {
    Config {
        cases: 512,
        rng_seed: RngSeed::Fixed(13),
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn delta_method_std_checks_every_length(
        rows in prop::collection::vec(prop::collection::vec(-1.0f64..1.0, 0..5), 0..5),
        gradient in prop::collection::vec(-1.0f64..1.0, 0..5),
    ) {
        let square = rows.len() == gradient.len() && rows.iter().all(|r| r.len() == gradient.len());
        match delta_method_std(&rows, &gradient) {
            Ok(v) => prop_assert!(square && v >= 0.0),
            Err(MlError::InvalidArgument { name, .. }) => {
                prop_assert!(!square);
                prop_assert!(name.starts_with("covariance"));
            }
            Err(e) => prop_assert!(false, "unexpected error {e}"),
        }
    }

    #[test]
    fn solvers_check_start_and_transform_lengths(n in 1usize..4, start_len in 0usize..6, transforms in 0usize..6) {
        let start = vec![0.5; start_len];
        let lm = LevenbergMarquardt::default();
        match lm.minimize(&Shift(n), &start) {
            Ok(r) => prop_assert!(start_len == n && r.params.len() == n),
            Err(SolverError::WrongStartLength { expected, got }) => {
                prop_assert!(expected == n && got == start_len && start_len != n)
            }
            Err(e) => prop_assert!(false, "unexpected error {e}"),
        }
        match Transformed::new(Shift(n), vec![Transform::Positive; transforms]) {
            Ok(t) => {
                prop_assert_eq!(transforms, n);
                let r = t.minimize(&lm, &start);
                prop_assert!(r.is_ok() == (start_len == n), "{:?}", r);
            }
            Err(SolverError::WrongTransformCount { expected, got }) => {
                prop_assert!(expected == n && got == transforms && transforms != n)
            }
            Err(e) => prop_assert!(false, "unexpected error {e}"),
        }
    }

    #[test]
    fn solver_types_from_arbitrary_json_are_valid_or_refused(value in json()) {
        if let Ok(options) = serde_json::from_value::<LmOptions>(value.clone()) {
            prop_assert!(options.validate().is_ok());
            prop_assert!(LevenbergMarquardt::new(options).minimize(&Shift(1), &[0.0]).is_ok());
        }
        if let Ok(t) = serde_json::from_value::<Transform>(value.clone()) {
            prop_assert!(t.is_valid());
        }
        // Wrapped in the shapes the types are written in, so that most cases reach validation.
        for wrapped in [serde_json::json!({ "Bounded": value.clone() }), value] {
            if let Ok(t) = serde_json::from_value::<Transform>(wrapped) {
                prop_assert!(t.is_valid());
            }
        }
    }
}

#[test]
fn a_record_is_validated_when_read() {
    use jitterid_estimate::Record;
    let round = Record::new(
        jitterid_signal::SampleGrid::new(0.0, 1.0, 2).expect("grid"),
        vec![1.0, 2.0],
    )
    .expect("record");
    let back: Record =
        serde_json::from_str(&serde_json::to_string(&round).expect("writes")).expect("reads");
    assert_eq!(back, round);
    // JSON has no non-finite numbers; the length is what a hand-edited file gets wrong.
    let mut json = serde_json::to_value(&round).expect("writes");
    json["y"] = serde_json::json!([1.0]);
    let err = serde_json::from_value::<Record>(json.clone()).expect_err("one value, two instants");
    assert!(err.to_string().contains('2'), "{err}");
}

#[test]
fn invalid_solver_types_are_refused_when_read() {
    let bad = r#"{"max_iters":5,"xtol":-1.0,"ftol":1e-12,"gtol":1e-10,"initial_lambda":0.001,"scaling":"Marquardt"}"#;
    let err = serde_json::from_str::<LmOptions>(bad).expect_err("negative xtol");
    assert!(err.to_string().contains("xtol"), "{err}");
    let err = serde_json::from_str::<Transform>(r#"{"Bounded":{"lo":2.0,"hi":1.0}}"#)
        .expect_err("empty interval");
    assert!(err.to_string().contains("bounds"), "{err}");
    let ok: Transform = serde_json::from_str(r#"{"Bounded":{"lo":1.0,"hi":2.0}}"#).expect("valid");
    assert_eq!(ok, Transform::Bounded { lo: 1.0, hi: 2.0 });
    let options = LmOptions::default();
    let back: LmOptions =
        serde_json::from_str(&serde_json::to_string(&options).expect("writes")).expect("reads");
    assert_eq!(back, options);
}
