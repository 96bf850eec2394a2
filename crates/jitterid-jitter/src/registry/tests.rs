use super::*;
use crate::testing::check_contract;
use crate::{Gaussian, JitterModel, UniformSum};
use serde_json::json;

fn table(v: serde_json::Value) -> SpecTable {
    v.as_object().cloned().unwrap_or_default()
}

#[test]
fn every_builtin_family_builds_from_its_keys_and_round_trips() {
    let r = JitterRegistry::builtin();
    for spec in [
        json!({"family": "none"}),
        json!({"family": "uniform-sum", "n": 2, "a": 0.3}),
        json!({"family": "gaussian", "sigma": 0.1}),
        json!({"family": "laplace", "scale": 0.2}),
        json!({"family": "two-point", "d": 0.05}),
        json!({"family": "exponential", "mean": 0.4}),
        json!({"family": "gaussian", "sigma": 0.1, "offset": -0.25}),
    ] {
        let j = r.build(&table(spec.clone())).unwrap();
        assert_eq!(serde_json::to_value(&j).unwrap(), spec);
        let back: AnyJitter = serde_json::from_value(spec.clone()).unwrap();
        assert_eq!(back, j);
        check_contract(&j, 11).unwrap();
    }
}

#[test]
fn any_jitter_forwards_to_the_family() {
    let r = JitterRegistry::builtin();
    let j = r
        .build(&table(json!({"family": "uniform-sum", "n": 1, "a": 0.5})))
        .unwrap();
    let u = UniformSum::new(1, 0.5).unwrap();
    assert_eq!(j.downcast_ref::<UniformSum>(), Some(&u));
    assert_eq!(j.cf(0.7), u.cf(0.7));
    assert_eq!(j.rule(&[0.1], 3.0), u.rule(&[0.1], 3.0));
    assert_eq!(j.rule_from(0.1, &[], 3.0), u.rule_from(0.1, &[], 3.0));
    assert_eq!(format!("{j:?}"), format!("{u:?}"));
    let k = j.with_params(&[0.25]).unwrap();
    assert_eq!(k.spec()["a"], 0.25);
    assert_eq!(k.spec()["n"], 1);
    assert_ne!(k, j);
    // A Gaussian is never equal to a uniform sum, whatever the numbers.
    let g = r
        .build(&table(json!({"family": "gaussian", "sigma": 0.5})))
        .unwrap();
    assert_ne!(g, j);
}

#[test]
fn errors_name_the_family_and_the_key() {
    let r = JitterRegistry::builtin();
    let err = |v| r.build(&table(v)).unwrap_err();
    assert!(matches!(err(json!({})), JitterError::MissingKey { key, .. } if key == "family"));
    assert!(
        matches!(err(json!({"family": 3})), JitterError::InvalidKey { key, .. } if key == "family")
    );
    assert!(matches!(
        err(json!({"family": "gauss"})),
        JitterError::UnknownFamily { .. }
    ));
    assert!(
        matches!(err(json!({"family": "gaussian"})), JitterError::MissingKey { family, key } if family == "gaussian" && key == "sigma")
    );
    assert!(
        matches!(err(json!({"family": "gaussian", "sigma": 1, "d": 2})), JitterError::UnexpectedKey { key, .. } if key == "d")
    );
    assert!(
        matches!(err(json!({"family": "gaussian", "sigma": -1})), JitterError::InvalidKey { key, .. } if key == "sigma")
    );
    assert!(
        matches!(err(json!({"family": "gaussian", "sigma": "x"})), JitterError::InvalidKey { key, .. } if key == "sigma")
    );
    assert!(
        matches!(err(json!({"family": "uniform-sum", "n": 1.5, "a": 1})), JitterError::InvalidKey { key, .. } if key == "n")
    );
    assert!(
        matches!(err(json!({"family": "uniform-sum", "n": 201, "a": 1})), JitterError::InvalidKey { key, .. } if key == "n")
    );
    let e = err(json!({"family": "gaussian", "sigma": 1, "offset": true}));
    assert_eq!(e.key(), Some("offset"));
}

#[test]
fn from_std_dev_gives_the_requested_spread() {
    let r = JitterRegistry::builtin();
    for fam in r
        .families()
        .filter(|f| f.has_std_dev_form() && f.name() != "none")
    {
        for n in [0, 3] {
            let spec = if fam.params().iter().any(|p| p.key == "n") {
                table(json!({ "n": n }))
            } else {
                SpecTable::new()
            };
            let j = r.from_std_dev(fam.name(), 0.125, &spec).unwrap();
            assert!(
                (j.std_dev() - 0.125).abs() < 1e-15,
                "{}: {}",
                fam.name(),
                j.std_dev()
            );
        }
    }
    assert_eq!(
        r.from_std_dev("none", 0.1, &SpecTable::new())
            .unwrap()
            .std_dev(),
        0.0
    );
    assert!(matches!(
        r.from_std_dev("gaussian", -1.0, &SpecTable::new()),
        Err(JitterError::NotPositive { .. })
    ));
    let shifted = r
        .from_std_dev("gaussian", 0.1, &table(json!({"offset": 1.0})))
        .unwrap();
    assert_eq!(shifted.mean(), 1.0);
}

#[test]
fn a_family_added_at_run_time_is_built_like_the_others() {
    let mut r = JitterRegistry::builtin().clone();
    let entry = Family::new(
        "narrow",
        "a Gaussian of a tenth of the given width",
        vec![ParamSpec::new(
            "width",
            "ten standard deviations",
            "s",
            "> 0",
        )],
        |r, _| {
            let g = Gaussian::new(0.1 * r.f64("width")?).map_err(|e| r.invalid("width", e))?;
            Ok(AnyJitter::new("narrow", g, |g: &Gaussian| {
                builtin::spec_of([("width", (10.0 * g.sigma()).into())])
            }))
        },
    );
    r.register(entry.clone()).unwrap();
    assert!(matches!(
        r.register(entry),
        Err(JitterError::DuplicateFamily { .. })
    ));
    let j = r
        .build(&table(json!({"family": "narrow", "width": 2.0})))
        .unwrap();
    assert!((j.std_dev() - 0.2).abs() < 1e-16);
    assert!(matches!(
        r.from_std_dev("narrow", 0.1, &SpecTable::new()),
        Err(JitterError::NoStdDevForm { .. })
    ));
    assert!(JitterRegistry::builtin().family("narrow").is_none());
}

#[test]
fn composite_families_build_from_terms_and_round_trip() {
    let r = JitterRegistry::builtin();
    for spec in [
        json!({"family": "periodic", "amplitude": 0.2}),
        json!({"family": "sum", "terms": [
            {"family": "gaussian", "sigma": 0.01}, {"family": "two-point", "d": 0.03}]}),
        json!({"family": "sum", "terms": [
            {"family": "gaussian", "sigma": 0.01}, {"family": "two-point", "d": 0.03},
            {"family": "periodic", "amplitude": 0.02, "offset": 0.1}]}),
        json!({"family": "mixture", "weights": [0.25, 0.75], "terms": [
            {"family": "gaussian", "sigma": 0.01}, {"family": "laplace", "scale": 0.03}]}),
        json!({"family": "mixture", "weights": [0.5, 0.5], "fixed_weights": true, "terms": [
            {"family": "gaussian", "sigma": 0.01}, {"family": "gaussian", "sigma": 0.02}]}),
    ] {
        let j = r.build(&table(spec.clone())).unwrap();
        assert_eq!(serde_json::to_value(&j).unwrap(), spec);
        check_contract(&j, 5).unwrap();
    }
    let three = r
        .build(&table(json!({"family": "sum", "terms": [
            {"family": "gaussian", "sigma": 0.01}, {"family": "two-point", "d": 0.03},
            {"family": "uniform-sum", "n": 1, "a": 0.02}]})))
        .unwrap();
    assert_eq!(
        three.param_names(),
        vec!["terms.0.sigma", "terms.1.d", "terms.2.a"]
    );
    let p = r.from_std_dev("periodic", 0.1, &SpecTable::new()).unwrap();
    assert!((p.std_dev() - 0.1).abs() < 1e-16);
}

#[test]
fn errors_inside_a_term_name_the_term() {
    let r = JitterRegistry::builtin();
    let err = |v| r.build(&table(v)).unwrap_err();
    let e = err(json!({"family": "sum", "terms": [
        {"family": "gaussian", "sigma": 0.01}, {"family": "two-point", "d": -1}]}));
    assert_eq!(e.key(), Some("terms.1.d"), "{e}");
    let e = err(json!({"family": "sum", "terms": [{"family": "gaussian", "sigma": 0.01}]}));
    assert_eq!(e.key(), Some("terms"), "{e}");
    let e = err(json!({"family": "sum", "terms": [{"family": "gaussian", "sigma": 0.01}, 3]}));
    assert_eq!(e.key(), Some("terms.1"), "{e}");
    let e = err(
        json!({"family": "mixture", "weights": [0.5, 0.6], "terms": [
        {"family": "gaussian", "sigma": 0.01}, {"family": "gaussian", "sigma": 0.02}]}),
    );
    assert_eq!(e.key(), Some("weights"), "{e}");
    let e = err(
        json!({"family": "mixture", "weights": [0.5, 0.5], "terms": [
        {"family": "gaussian", "sigma": 0.01}, {"family": "nope"}]}),
    );
    assert_eq!(e.key(), Some("terms.1.family"), "{e}");
    assert!(matches!(
        r.from_std_dev("sum", 0.1, &SpecTable::new()),
        Err(JitterError::NoStdDevForm { .. })
    ));
}

#[test]
fn the_docs_table_of_families_is_the_registry_s() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/experiments.md");
    let text = std::fs::read_to_string(path).expect("docs/experiments.md is readable");
    let header = "| family | key | unit | accepts | default | meaning |";
    let start = text
        .find(header)
        .expect("docs/experiments.md has the table of jitter families");
    let table: String = text[start..]
        .lines()
        .take_while(|l| l.starts_with('|'))
        .map(|l| format!("{l}\n"))
        .collect();
    let expected = JitterRegistry::builtin().markdown_table();
    assert!(
        table == expected,
        "the [jitter] families table of docs/experiments.md differs from the registry; \
         replace it with:\n\n{expected}"
    );
}
