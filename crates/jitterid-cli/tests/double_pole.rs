//! A double real pole in `zpk` form (`poles = [-0.5, -0.5]`), through the binary: estimated
//! through its quadratic factor, it fits like the same system written as `tf` — the same
//! estimates and standard errors, on records whose estimate is two real poles and on records
//! where it passes through the coincidence into a complex pair. (Two real poles as two
//! parameters stopped at the coincidence with no covariance: 16 of 16 records.)

mod common;

use common::{example, run as jitterid};
use serde_json::Value;
use std::path::Path;

fn json(out: &std::process::Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// The estimates and standard errors of a fit, in order.
fn numbers(fit: &Value, key: &str) -> Vec<f64> {
    fit["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p[key].as_f64().unwrap_or_else(|| panic!("{key}: {fit}")))
        .collect()
}

#[test]
fn a_zpk_double_pole_fits_like_its_tf_form() {
    let dir = tempfile::tempdir().unwrap();
    let s = |p: &Path| p.display().to_string();
    let zpk = std::path::PathBuf::from(example("double-pole.toml"));
    let text = std::fs::read_to_string(&zpk).unwrap();
    let tf_text = text
        .replace("kind = \"zpk\"", "kind = \"tf\"")
        .replace("gain = 1.0", "num = [1.0]")
        .replace("poles = [-0.5, -0.5]", "den = [1.0, 1.0, 0.25]");
    let tf = dir.path().join("tf.toml");
    std::fs::write(&tf, &tf_text).unwrap();
    let (mut real, mut complex) = (0, 0);
    for run in ["0", "1", "2", "3"] {
        let data = dir.path().join(format!("r{run}.csv"));
        let sim = jitterid(&["simulate", &s(&zpk), "--run", run, "--out", &s(&data)]);
        assert!(sim.status.success(), "{sim:?}");
        for method in ["bcls", "ml"] {
            let fit = |exp: &Path| {
                let (exp, data) = (s(exp), s(&data));
                json(&jitterid(&[
                    "fit", &exp, "--data", &data, "--method", method, "--json",
                ]))
            };
            let (z, t) = (fit(&zpk), fit(&tf));
            let names: Vec<&str> = z["parameters"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| p["name"].as_str().unwrap())
                .collect();
            assert_eq!(names, ["gain", "pole0.a1", "pole0.a0"]);
            assert!(z["converged"].as_bool().unwrap(), "run {run} {method}: {z}");
            assert!(!z["covariance"].is_null(), "run {run} {method}: {z}");
            // Both reach the same optimum of the same criterion in the same coordinates (b0
            // is the gain, a1 and a0 the factor's): equal to the optimiser's tolerance.
            for key in ["estimate", "stderr"] {
                for (a, b) in numbers(&z, key).iter().zip(numbers(&t, key)) {
                    assert!(
                        (a - b).abs() <= 1e-4 * b.abs(),
                        "run {run} {method} {key}: zpk {a} vs tf {b}"
                    );
                }
            }
            let e = numbers(&z, "estimate");
            if e[1] * e[1] < 4.0 * e[2] {
                complex += 1;
            } else {
                real += 1;
            }
        }
    }
    // The records cover both sides of the coincidence.
    assert!(real > 0 && complex > 0, "real {real}, complex {complex}");
}
