//! Every deserializable type of the crate goes through its validating constructor: the reported
//! panics are typed errors now, and no JSON value makes a read or a later evaluation panic.

use jitterid_signal::{
    Input, LtiResponse, Multisine, PiecewiseConstant, PulseResponse, RandomBinary, Rational, Root,
    SampleGrid, Signal, Sinusoid, TransferFunction, Zpk,
};
use proptest::prelude::*;
use rand::SeedableRng;
use serde_json::{json, Value};

#[test]
fn reported_panics_are_typed_errors() {
    // A PiecewiseConstant whose levels do not match its edges used to panic in `value`.
    let e =
        serde_json::from_value::<PiecewiseConstant>(json!({"edges": [0, 1, 2, 3], "levels": [1]}));
    assert!(e.unwrap_err().to_string().contains("edges"));
    // A negative mean dwell used to panic in `generate`.
    let e = serde_json::from_value::<RandomBinary>(json!({"mean_dwell": -1, "low": 0, "high": 1}));
    assert!(e.unwrap_err().to_string().contains("mean_dwell"));
    // An empty grid with a negative interval was accepted.
    let e = serde_json::from_value::<SampleGrid>(json!({"start": 0, "interval": -1, "len": 0}));
    assert!(e.unwrap_err().to_string().contains("interval"));
    let e = serde_json::from_value::<SampleGrid>(json!({"start": 0, "interval": 1, "len": 0}));
    assert!(e.unwrap_err().to_string().contains("samples"));
    // A subnormal mean dwell overflows the rate: an error, not a panic.
    let b = RandomBinary::new(5e-324, 0.0, 1.0).unwrap();
    assert!(RandomBinary::new(1e-3, 0.0, 1.0)
        .unwrap()
        .generate(0.0, 1e6, &mut rand::rngs::StdRng::seed_from_u64(1))
        .is_err());
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    assert!(b.generate(0.0, 1.0, &mut rng).is_err());
}

#[test]
fn serialized_values_read_back_equal() {
    let u = PiecewiseConstant::new(vec![0.0, 1.0, 2.5], vec![1.0, -0.5]).unwrap();
    let zpk = Zpk::new(
        0.2,
        vec![Root::Real(-0.5)],
        vec![Root::Pair { re: -0.25, im: 0.3 }],
    )
    .unwrap();
    let tf = TransferFunction::new(&[1.0, 2.0], &[2.0, 3.0, 1.0]).unwrap();
    fn round<T: serde::Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug>(
        x: &T,
    ) {
        let v = serde_json::to_value(x).unwrap();
        assert_eq!(&serde_json::from_value::<T>(v).unwrap(), x);
    }
    round(&u);
    round(&zpk);
    round(&tf);
    round(&zpk.rational().clone());
    round(&SampleGrid::new(0.5, 0.25, 7).unwrap());
    round(&Sinusoid::new(1.0, 0.2, 0.3).unwrap());
    round(&RandomBinary::paper());
    round(&Multisine::sine(0.1, 1.0, 0.2).unwrap());
    round(&PulseResponse::new(vec![1.0, 0.5], 0.5, u.clone()).unwrap());
    let r = LtiResponse::new(zpk, u);
    let back: LtiResponse<Zpk> = serde_json::from_value(serde_json::to_value(&r).unwrap()).unwrap();
    assert_eq!(back.value(1.7), r.value(1.7));
    assert_eq!(back.steps(), r.steps());
}

use jitterid_signal::RationalModel;

/// Arbitrary JSON: scalars (including edge numbers), arrays and objects, nested.
fn arb_json() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::from),
        prop_oneof![
            Just(0.0),
            Just(-1.0),
            Just(1e308),
            Just(-1e308),
            Just(5e-324),
            -10.0f64..10.0
        ]
        .prop_map(|x| json!(x)),
        (0u64..5).prop_map(Value::from),
        "[a-z_]{0,10}".prop_map(Value::from),
    ];
    leaf.prop_recursive(4, 32, 6, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..6).prop_map(Value::Array),
            prop::collection::btree_map(
                prop_oneof![
                    Just("edges".to_string()),
                    Just("levels".to_string()),
                    Just("start".to_string()),
                    Just("interval".to_string()),
                    Just("len".to_string()),
                    Just("mean_dwell".to_string()),
                    Just("low".to_string()),
                    Just("high".to_string()),
                    Just("tones".to_string()),
                    Just("frequency".to_string()),
                    Just("amplitude".to_string()),
                    Just("phase".to_string()),
                    Just("gain".to_string()),
                    Just("zeros".to_string()),
                    Just("poles".to_string()),
                    Just("num".to_string()),
                    Just("den".to_string()),
                    Just("d_num".to_string()),
                    Just("d_den".to_string()),
                    Just("coefficients".to_string()),
                    Just("input".to_string()),
                    Just("model".to_string()),
                    Just("Piecewise".to_string()),
                    Just("Tones".to_string()),
                    Just("Real".to_string()),
                    Just("Pair".to_string()),
                    Just("re".to_string()),
                    Just("im".to_string()),
                ],
                inner,
                0..6
            )
            .prop_map(|m| Value::Object(m.into_iter().collect())),
        ]
    })
}

/// Reads `v` as every deserializable type, and uses what reads: nothing may panic.
fn exercise(v: &Value) {
    let t = [-1.0, 0.0, 0.5, 2.0, 1e6];
    if let Ok(g) = serde_json::from_value::<SampleGrid>(v.clone()) {
        let _: Vec<f64> = g.times().take(3).collect();
    }
    if let Ok(p) = serde_json::from_value::<PiecewiseConstant>(v.clone()) {
        t.iter().for_each(|&t| {
            p.value(t);
        });
        p.spectrum(0.3);
    }
    if let Ok(b) = serde_json::from_value::<RandomBinary>(v.clone()) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        let _ = b.generate(0.0, 3.0, &mut rng);
    }
    if let Ok(m) = serde_json::from_value::<Multisine>(v.clone()) {
        m.value(0.5);
    }
    if let Ok(s) = serde_json::from_value::<Sinusoid>(v.clone()) {
        s.value(0.5);
    }
    if let Ok(i) = serde_json::from_value::<Input>(v.clone()) {
        i.value(0.5);
    }
    if let Ok(r) = serde_json::from_value::<Rational>(v.clone()) {
        r.response(num_complex::Complex64::new(0.0, 1.0));
    }
    for s in [
        serde_json::from_value::<LtiResponse<Zpk>>(v.clone())
            .ok()
            .map(|s| Box::new(s) as Box<dyn Signal>),
        serde_json::from_value::<LtiResponse<TransferFunction>>(v.clone())
            .ok()
            .map(|s| Box::new(s) as _),
        serde_json::from_value::<PulseResponse>(v.clone())
            .ok()
            .map(|s| Box::new(s) as _),
    ]
    .into_iter()
    .flatten()
    {
        let mut g = vec![0.0; s.num_params()];
        t.iter().for_each(|&t| {
            s.value(t);
            s.value_gradient(t, &mut g);
        });
    }
    let _ = serde_json::from_value::<Zpk>(v.clone());
    let _ = serde_json::from_value::<TransferFunction>(v.clone());
    let _ = serde_json::from_value::<Root>(v.clone());
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5e_7d_e5),
        ..ProptestConfig::default()
    })]

    #[test]
    fn no_json_value_panics(v in arb_json()) {
        exercise(&v);
        // Wrapped the way the enum and generic types expect their fields.
        exercise(&json!({"Piecewise": v.clone()}));
        exercise(&json!({"model": v.clone(), "input": {"Piecewise": {"edges": [0, 1], "levels": [1]}}}));
        exercise(&json!({"coefficients": [1.0], "interval": 1.0, "input": v}));
    }
}
