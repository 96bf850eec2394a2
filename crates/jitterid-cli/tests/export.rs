//! `fit --json` carries the covariance of the reported parameters and the fitted model in
//! zpk, transfer-function and state-space form; checked through the real binary against the
//! reported parameters.

mod common;

use common::{example, run, s, scratch, stderr, stdout};
use serde_json::Value;

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn fit_json_has_covariance_and_model_forms() {
    let dir = scratch("export-fit");
    let data = dir.join("d.csv");
    let exp = example("table2.toml");
    let o = run(&["simulate", &exp, "--out", s(&data)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&["fit", &exp, "--data", s(&data), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: Value = serde_json::from_str(&stdout(&o)).unwrap();

    let params = j["parameters"].as_array().unwrap();
    let p = params.len();
    let cov = j["covariance"].as_array().expect("covariance");
    assert_eq!(cov.len(), p);
    for (i, row) in cov.iter().enumerate() {
        let row = numbers(row);
        assert_eq!(row.len(), p);
        // Symmetric, and its diagonal is the square of the reported standard error.
        for (l, &c) in row.iter().enumerate() {
            assert!(close(c, cov[l][i].as_f64().unwrap()));
        }
        let se = params[i]["stderr"].as_f64().unwrap();
        assert!(close(row[i].sqrt(), se), "{} vs {se}", row[i].sqrt());
    }

    // G(s) = k (s − z0) / ((s − re)² + im²) from the reported parameters.
    let value = |name: &str| {
        params
            .iter()
            .find(|q| q["name"] == name)
            .unwrap_or_else(|| panic!("no parameter {name}: {params:?}"))["estimate"]
            .as_f64()
            .unwrap()
    };
    let (k, z0, re, im) = (
        value("gain"),
        value("zero0"),
        value("pole0.re"),
        value("pole0.im"),
    );
    let model = &j["model"];
    let num = numbers(&model["tf"]["num"]);
    let den = numbers(&model["tf"]["den"]);
    assert_eq!(num.len(), 2);
    assert!(close(num[0], k) && close(num[1], -k * z0), "{num:?}");
    assert_eq!(den.len(), 3);
    assert!(close(den[0], 1.0) && close(den[1], -2.0 * re));
    assert!(close(den[2], re * re + im * im), "{den:?}");

    assert!(close(model["zpk"]["gain"].as_f64().unwrap(), k));
    let pole = numbers(&model["zpk"]["poles"][0]);
    assert!((pole[0] - re).abs() < 1e-9 && (pole[1].abs() - im).abs() < 1e-9);
    let zero = numbers(&model["zpk"]["zeros"][0]);
    assert!((zero[0] - z0).abs() < 1e-9 && zero[1] == 0.0);

    // Controllable canonical form: first row −a, B = e1, C the remainder, D = 0.
    let ss = &model["ss"];
    assert_eq!(numbers(&ss["a"][0]), [-den[1], -den[2]]);
    assert_eq!(numbers(&ss["a"][1]), [1.0, 0.0]);
    assert_eq!(ss["b"], serde_json::json!([[1.0], [0.0]]));
    assert_eq!(numbers(&ss["c"][0]), num);
    assert_eq!(ss["d"], serde_json::json!([[0.0]]));
}
