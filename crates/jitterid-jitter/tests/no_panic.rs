//! No input reaches a panic through the crate's public API: arbitrary JSON given to every
//! deserialisable type and to the registry either fails with an error or gives a model whose
//! methods all return.

use jitterid_jitter::registry::{JitterRegistry, SpecTable};
use jitterid_jitter::{
    AnyJitter, Atom, ExponentialDelay, Gaussian, JitterModel, Laplace, Mixture, NoJitter, Periodic,
    Shifted, Sum, TwoPoint, UniformSum,
};
use num_complex::Complex64;
use proptest::prelude::*;
use rand::rngs::StdRng;
use rand::SeedableRng;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

/// Keys and names that the crate's types and families read, so that generated tables reach
/// past the first missing-key error.
const KEYS: &[&str] = &[
    "family",
    "sigma",
    "a",
    "n",
    "d",
    "b",
    "scale",
    "mean",
    "amplitude",
    "offset",
    "terms",
    "weights",
    "fixed_weights",
    "inner",
    "components",
    "position",
    "mass",
];
const NAMES: &[&str] = &[
    "none",
    "uniform-sum",
    "gaussian",
    "laplace",
    "two-point",
    "exponential",
    "periodic",
    "sum",
    "mixture",
    "nope",
];

fn number() -> impl Strategy<Value = Value> {
    prop_oneof![
        (-3i64..300).prop_map(Value::from),
        (-1e3f64..1e3).prop_map(Value::from),
        (0.0f64..1.0).prop_map(Value::from),
        prop::sample::select(vec![
            0.0,
            1e-300,
            1e300,
            -1e-12,
            0.5,
            200.0,
            201.0,
            f64::MAX
        ])
        .prop_map(Value::from),
    ]
}

fn leaf() -> impl Strategy<Value = Value> {
    prop_oneof![
        4 => number(),
        2 => prop::sample::select(NAMES).prop_map(Value::from),
        1 => any::<bool>().prop_map(Value::from),
        1 => Just(Value::Null),
    ]
}

fn json() -> impl Strategy<Value = Value> {
    leaf().prop_recursive(3, 24, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::vec((prop::sample::select(KEYS), inner), 0..5).prop_map(|kv| {
                Value::Object(kv.into_iter().map(|(k, v)| (k.to_string(), v)).collect())
            }),
        ]
    })
}

/// Every method of a model, at a few arguments; expensive rules only for small models.
fn exercise<J: JitterModel + ?Sized>(j: &J) {
    let mut rng = StdRng::seed_from_u64(1);
    for f in [0.0, 0.3, -2.0, 1e9, f64::MAX] {
        let _ = j.cf(f);
        assert_eq!(j.cf_gradient(f).len(), j.num_params());
    }
    for z in [Complex64::new(0.1, -3.0), Complex64::new(-50.0, 0.0)] {
        let _ = j.mgf(z);
    }
    let _ = (j.pdf(0.01), j.mean(), j.variance(), j.std_dev(), j.reach());
    let _ = (j.params(), j.param_names(), j.name(), j.atoms());
    let pieces = j.pieces();
    if pieces.len() <= 64 && j.atoms().len() <= 64 {
        let _ = j.rule(&[0.0, 0.1], 1.0);
        let _ = j.rule_from(0.05, &[], 1.0);
    }
    let _ = j.sample(&mut rng);
}

fn try_type<T: DeserializeOwned + JitterModel>(v: &Value) {
    if let Ok(j) = serde_json::from_value::<T>(v.clone()) {
        exercise(&j);
        let _ = j.with_params(&[0.1, 0.2]);
        let _ = j.with_params(&j.params());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn arbitrary_json_never_panics(v in json()) {
        try_type::<Gaussian>(&v);
        try_type::<Laplace>(&v);
        try_type::<ExponentialDelay>(&v);
        try_type::<TwoPoint>(&v);
        try_type::<UniformSum>(&v);
        try_type::<NoJitter>(&v);
        try_type::<Periodic>(&v);
        try_type::<Shifted<Gaussian>>(&v);
        try_type::<Sum<Gaussian, TwoPoint>>(&v);
        try_type::<Mixture<Gaussian>>(&v);
        try_type::<AnyJitter>(&v);
        let _ = serde_json::from_value::<Atom>(v.clone());
        if let Value::Object(spec) = &v {
            let r = JitterRegistry::builtin();
            if let Ok(j) = r.build(spec) {
                exercise(&j);
                let _ = j.with_params(&[f64::NAN]);
                // What the registry builds, it rebuilds from its own spec.
                let rebuilt = r.build(&j.spec());
                prop_assert_eq!(rebuilt.as_ref(), Ok(&j));
            }
            for name in NAMES {
                for sigma in [0.1, -1.0, f64::NAN] {
                    if let Ok(j) = r.from_std_dev(name, sigma, spec) {
                        exercise(&j);
                    }
                }
            }
        }
    }

    #[test]
    fn registry_tables_with_family_keys_never_panic(
        name in prop::sample::select(NAMES),
        kv in prop::collection::vec((prop::sample::select(KEYS), json()), 0..4),
    ) {
        let mut spec: SpecTable = Map::new();
        spec.insert("family".into(), name.into());
        for (k, v) in kv {
            if k != "family" {
                spec.insert(k.to_string(), v);
            }
        }
        if let Ok(j) = JitterRegistry::builtin().build(&spec) {
            exercise(&j);
        }
    }
}
