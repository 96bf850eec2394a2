//! The `grey-box` kind: a state-space model whose matrices are expressions of named physical
//! parameters ([`ExprModel`] driven by the input through [`GreyBox`]).

use super::{ParamSpec, SignalKind, SpecReader, SpecTable};
use crate::greybox::{
    Entry, ExprModel, GreyBox, GreyTf, StateSpaceModel, WrittenMatrices, GREY_BOX,
};
use crate::RationalModel;
use crate::{AnySignal, Input, Signal, SignalError};
use serde_json::{json, Map, Value};

pub(super) fn kind() -> SignalKind {
    let mut keys = vec![
            ParamSpec::new(
                "params",
                "the parameters θ and their values, a table {name = value}; reported in the order of their names",
                "",
                "finite, inside their bounds; names of letters, digits and _",
            ),
            ParamSpec::new(
                "fixed",
                "named constants the expressions may use, never estimated, a table {name = value}",
                "",
                "optional; finite",
            ),
            ParamSpec::new(
                "bounds",
                "bounds of some parameters, a table {name = [lo, hi]} (a parameter outside them is refused; the estimate stays inside)",
                "",
                "optional; lo ≤ hi",
            ),
            ParamSpec::new(
                "a",
                "A, n×n: rows of expressions (strings such as \"-k/m\": numbers, names, + − * / ^, parentheses, sqrt exp ln sin cos tan abs, pi) or numbers",
                "1/s",
                "square",
            ),
            ParamSpec::new("b", "B, n×1: one row of one entry per state", "", "n rows"),
            ParamSpec::new("c", "C, 1×n: one row", "", "n columns"),
            ParamSpec::new("d", "D, 1×1: [[entry]]", "", "optional; default 0"),
        ];
    keys.extend(super::builtin::response_keys());
    SignalKind::new(
        GREY_BOX,
        "ẋ = A(θ)x + B(θ)u, y = C(θ)x + D(θ)u with named physical parameters θ, driven by the input, exact (the sensitivities by the augmented matrix exponential)",
        keys,
        true,
        build,
    )
}

/// The keys that put the model on its transfer function's route ([`GreyBox::transfer_response`]),
/// where an input delay, a free response and an output offset are built as for `tf`.
const RESPONSE_KEYS: [&str; 6] = [
    "delay",
    "initial",
    "level",
    "estimate_level",
    "offset",
    "estimate_offset",
];

fn build(r: &SpecReader<'_>, input: Option<&Input>) -> Result<AnySignal, SignalError> {
    let params = named_numbers(r, "params")?;
    let fixed = if r.has("fixed") {
        named_numbers(r, "fixed")?
    } else {
        Vec::new()
    };
    let bounds = match r.get("bounds") {
        None => Vec::new(),
        Some(Value::Object(o)) => o
            .iter()
            .map(|(name, v)| Ok((name.clone(), bound(r, name, v)?)))
            .collect::<Result<_, SignalError>>()?,
        Some(v) => return Err(r.invalid("bounds", format!("expected a table, found {v}"))),
    };
    let written = WrittenMatrices {
        a: matrix(r, "a")?,
        b: matrix(r, "b")?,
        c: matrix(r, "c")?,
        d: r.has("d").then(|| matrix(r, "d")).transpose()?,
    };
    let names: Vec<String> = params.iter().map(|(n, _)| n.clone()).collect();
    let theta: Vec<f64> = params.iter().map(|(_, x)| *x).collect();
    let model = ExprModel::new(&names, &fixed, &bounds, &written)?;
    let input = input.cloned().ok_or(SignalError::MissingInput {
        kind: GREY_BOX.into(),
    })?;
    let g = GreyBox::new(model, theta, input).map_err(|e| match e {
        SignalError::InvalidKey { .. } => e,
        // Shapes and finiteness were checked with the matrices; what is left is about the
        // values the parameters give them.
        other => r.invalid("params", other),
    })?;
    if !RESPONSE_KEYS.iter().any(|k| r.has(k)) {
        return Ok(AnySignal::with_spectrum(GREY_BOX, g, spec_of));
    }
    let response = g.transfer_response().map_err(|e| r.invalid("a", e))?;
    super::builtin::lti_signal(GREY_BOX, r, response, spec_of_tf)
}

/// The keys of a grey-box model on its transfer function's route (without the response's
/// own keys, which the route writes back).
fn spec_of_tf(g: &GreyTf<ExprModel>) -> SpecTable {
    model_keys(g.model(), &g.params())
}

/// The keys of a grey-box model at its current parameters (the texts as written).
fn spec_of(g: &GreyBox<ExprModel>) -> SpecTable {
    model_keys(g.model(), &g.params())
}

/// The keys of `model` at the parameters `theta`.
fn model_keys(model: &ExprModel, theta: &[f64]) -> SpecTable {
    let names = model.param_names();
    let mut spec = SpecTable::new();
    let params: Map<String, Value> = names
        .iter()
        .zip(theta)
        .map(|(n, x)| (n.clone(), json!(x)))
        .collect();
    spec.insert("params".into(), Value::Object(params));
    if !model.fixed().is_empty() {
        let fixed: Map<String, Value> = model
            .fixed()
            .iter()
            .map(|(n, x)| (n.clone(), json!(x)))
            .collect();
        spec.insert("fixed".into(), Value::Object(fixed));
    }
    let bounds: Map<String, Value> = names
        .iter()
        .cloned()
        .zip(model.bounds())
        .filter(|(_, (lo, hi))| lo.is_finite() || hi.is_finite())
        // An infinite side is written as null (JSON has no infinity).
        .map(|(n, (lo, hi))| {
            let side = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
            (n, json!([side(*lo), side(*hi)]))
        })
        .collect();
    if !bounds.is_empty() {
        spec.insert("bounds".into(), Value::Object(bounds));
    }
    for (key, m) in ["a", "b", "c", "d"].into_iter().zip(model.texts()) {
        spec.insert(key.into(), json!(m));
    }
    spec
}

/// A table `{name = number}`, in the order of the names.
fn named_numbers(r: &SpecReader<'_>, key: &str) -> Result<Vec<(String, f64)>, SignalError> {
    match r.get(key) {
        Some(Value::Object(o)) => o
            .iter()
            .map(|(name, v)| match v.as_f64() {
                Some(x) => Ok((name.clone(), x)),
                None => Err(r.invalid(key, format!("{name}: expected a number, found {v}"))),
            })
            .collect(),
        Some(v) => Err(r.invalid(key, format!("expected a table of numbers, found {v}"))),
        None => Err(r.missing(key)),
    }
}

/// `[lo, hi]`, a null side unbounded.
fn bound(r: &SpecReader<'_>, name: &str, v: &Value) -> Result<(f64, f64), SignalError> {
    let side = |x: &Value, inf: f64| match x {
        Value::Null => Some(inf),
        x => x.as_f64(),
    };
    match v.as_array().map(Vec::as_slice) {
        Some([lo, hi]) => match (side(lo, f64::NEG_INFINITY), side(hi, f64::INFINITY)) {
            (Some(lo), Some(hi)) => Ok((lo, hi)),
            _ => Err(r.invalid("bounds", format!("{name}: expected [lo, hi], found {v}"))),
        },
        _ => Err(r.invalid("bounds", format!("{name}: expected [lo, hi], found {v}"))),
    }
}

/// Rows of entries: strings (expressions) or numbers.
fn matrix(r: &SpecReader<'_>, key: &str) -> Result<Vec<Vec<Entry>>, SignalError> {
    let expected = || {
        r.invalid(
            key,
            "expected an array of rows, each an array of expressions (strings) or numbers",
        )
    };
    let Some(Value::Array(rows)) = r.get(key) else {
        return Err(match r.get(key) {
            None => r.missing(key),
            Some(_) => expected(),
        });
    };
    rows.iter()
        .map(|row| {
            let Value::Array(row) = row else {
                return Err(expected());
            };
            row.iter()
                .map(|e| match e {
                    Value::String(s) => Ok(Entry::Text(s.clone())),
                    Value::Number(_) => Ok(Entry::Number(e.as_f64().unwrap_or(f64::NAN))),
                    _ => Err(expected()),
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::registry::SignalRegistry;
    use crate::testing::binary;
    use crate::Signal;
    use serde_json::json;

    fn msd() -> serde_json::Value {
        json!({
            "kind": "grey-box",
            "params": {"m": 1.0, "damp": 0.4, "k": 2.0},
            "bounds": {"m": [0.0, 1e3], "k": [0.0, null]},
            "a": [["0", "1"], ["-k/m", "-damp/m"]],
            "b": [[0], ["1/m"]],
            "c": [[1, 0]],
        })
    }

    #[test]
    fn builds_round_trips_and_names_the_parameters() {
        let input = binary(1, 4.0, 0.0, 30.0).unwrap().into();
        let reg = SignalRegistry::builtin();
        let s = reg.build(msd().as_object().unwrap(), Some(&input)).unwrap();
        assert_eq!(s.kind(), "grey-box");
        // Ordered by name.
        assert_eq!(s.param_names(), ["damp", "k", "m"]);
        assert_eq!(s.params(), [0.4, 2.0, 1.0]);
        let moved = s.with_params(&[0.5, 3.0, 2.0]).unwrap();
        let again = reg.build(&moved.spec(), Some(&input)).unwrap();
        assert_eq!(again.params(), [0.5, 3.0, 2.0]);
        assert_eq!(again.value(7.3), moved.value(7.3));
        assert_eq!(moved.spec()["bounds"]["k"], json!([0.0, null]));
        assert!(s.has_spectrum());
        assert!(s.with_params(&[0.4, 2.0, -1.0]).is_err());
    }

    /// A grey-box model with an input delay, a free response and an output offset (on its
    /// transfer function's route) against two independent routes: the plain model (the
    /// augmented realisation where the poles repeat) on the grid moved earlier by the delay,
    /// and the `tf` system with the same coefficients and keys; and the signal contract.
    #[test]
    fn delay_initial_state_and_offset_follow_the_tf_route() {
        use crate::testing::check_contract;
        use crate::SampleGrid;
        use jitterid_jitter::{Gaussian, JitterModel, UniformSum};
        let input = binary(5, 4.0, 0.0, 60.0).unwrap().into();
        let reg = SignalRegistry::builtin();
        let grid = SampleGrid::new(0.0, 0.5, 100).unwrap();
        let jitters: [Box<dyn JitterModel>; 2] = [
            Box::new(UniformSum::new(2, 0.25).unwrap()),
            Box::new(Gaussian::new(0.08).unwrap()),
        ];
        // Distinct poles, and a double pole (damp² = 4mk).
        for (m, damp, k) in [(1.0, 0.4, 2.0), (1.0, 2.0, 1.0)] {
            let mut plain = msd();
            plain["params"] = json!({"m": m, "damp": damp, "k": k});
            let mut delayed = plain.clone();
            delayed["delay"] = json!(0.7);
            let g = reg.build(plain.as_object().unwrap(), Some(&input)).unwrap();
            let d = reg
                .build(delayed.as_object().unwrap(), Some(&input))
                .unwrap();
            assert_eq!(d.param_names(), ["damp", "k", "m", "delay"]);
            let tf = json!({"kind": "tf", "num": [1.0 / m], "den": [1.0, damp / m, k / m],
                            "delay": 0.7, "initial": [0.3, -0.2], "origin": 0.0,
                            "offset": 1.5, "estimate_offset": true});
            let tf = reg.build(tf.as_object().unwrap(), Some(&input)).unwrap();
            let mut full = delayed.clone();
            full["initial"] = json!([0.3, -0.2]);
            full["origin"] = json!(0.0);
            full["offset"] = json!(1.5);
            full["estimate_offset"] = json!(true);
            let full = reg.build(full.as_object().unwrap(), Some(&input)).unwrap();
            assert_eq!(
                full.param_names(),
                [
                    "damp",
                    "k",
                    "m",
                    "delay",
                    "initial.0",
                    "initial.1",
                    "offset"
                ]
            );
            // The spec table rebuilds the same signal.
            let again = reg.build(&full.spec(), Some(&input)).unwrap();
            assert_eq!(again.params(), full.params());
            for jitter in &jitters {
                let j = jitter.as_ref();
                let shifted = g.expected_values(&grid.earlier(0.7), j);
                let ours = d.expected_values(&grid, j);
                let (m_full, m_tf) = (full.expected_values(&grid, j), tf.expected_values(&grid, j));
                let (s_full, s_tf) = (
                    full.expected_squares(&grid, j),
                    tf.expected_squares(&grid, j),
                );
                for k in 0..grid.len() {
                    assert!((ours[k] - shifted[k]).abs() < 1e-10, "k = {k}");
                    assert!((m_full[k] - m_tf[k]).abs() < 1e-10, "k = {k}");
                    assert!(
                        (s_full[k] - s_tf[k]).abs() < 1e-9 * (1.0 + s_tf[k]),
                        "k = {k}"
                    );
                }
                check_contract(&full, j, &grid, 3).unwrap();
            }
        }
    }

    #[test]
    fn refusals_name_the_key() {
        let input = binary(1, 4.0, 0.0, 30.0).unwrap().into();
        let reg = SignalRegistry::builtin();
        for (key, value, want) in [
            (
                "a",
                json!([["0", "1"], ["-k/mass", "-damp/m"]]),
                "unknown name \"mass\"",
            ),
            ("a", json!([["0", "1"], ["-k/m"]]), "row 2 has 1 entries"),
            ("b", json!([["1/m"]]), "expected 2 row(s)"),
            ("c", json!("1, 0"), "expected an array of rows"),
            (
                "params",
                json!({"m": -1.0, "damp": 0.4, "k": 2.0}),
                "outside its bounds",
            ),
            ("params", json!({"m": "one"}), "expected a number"),
            ("bounds", json!({"x": [0, 1]}), "not a parameter"),
            ("d", json!([["2*"]]), "cannot parse"),
        ] {
            let mut spec = msd();
            spec[key] = value;
            let e = reg
                .build(spec.as_object().unwrap(), Some(&input))
                .unwrap_err();
            assert_eq!(e.key(), Some(key), "{e}");
            assert!(e.to_string().contains(want), "{key}: {e}");
        }
    }
}
