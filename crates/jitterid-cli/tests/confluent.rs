//! Repeated poles and integrators through the real binary: `den = [1, 2, 1]`,
//! `den = [1, 1, 0]` (with `allow_unstable`, so that the search may cross the imaginary axis)
//! and repeated zpk poles are simulated and fitted; an unstable pole without the opt-in is
//! refused with the key named.

mod common;

use common::{jitterid, scratch_in, stderr};
use serde_json::Value;

fn experiment(system: &str) -> String {
    format!(
        r#"[sampling]
interval = 1.0
samples = 80
[input]
kind = "random-binary"
mean_dwell = 8.0
[system]
{system}
estimate = true
[jitter]
family = "uniform-sum"
n = 2
a = 0.3
[noise]
std = 0.01
"#
    )
}

/// Simulates one seeded record and fits it; every estimate within 5 of its standard errors of
/// the truth (for one record, a failure by chance has probability below `1e-6` per parameter;
/// a wrong response or gradient is off by far more).
/// Returns the directory holding the record `d.csv`.
fn simulate_and_fit(name: &str, system: &str, truth: &[f64]) -> std::path::PathBuf {
    let dir = scratch_in("jitterid-confluent", name);
    let exp = dir.join("exp.toml");
    std::fs::write(&exp, experiment(system)).unwrap();
    let data = dir.join("d.csv");
    let (exp, data) = (exp.to_str().unwrap(), data.to_str().unwrap());
    let o = jitterid()
        .args(["simulate", exp, "--out", data])
        .output()
        .unwrap();
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let o = jitterid()
        .args(["fit", exp, "--data", data, "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let fit: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(fit["converged"], Value::Bool(true), "{name}: {fit}");
    let params = fit["parameters"].as_array().unwrap();
    assert_eq!(params.len(), truth.len(), "{name}");
    for (p, want) in params.iter().zip(truth) {
        let (est, se) = (
            p["estimate"].as_f64().unwrap(),
            p["stderr"].as_f64().unwrap(),
        );
        assert!(
            (est - want).abs() <= 5.0 * se,
            "{name}: {} = {est} ± {se}, truth {want}",
            p["name"]
        );
    }
    dir
}

#[test]
fn double_pole_in_tf_form() {
    simulate_and_fit(
        "double-tf",
        "kind = \"tf\"\nnum = [1.0]\nden = [1.0, 2.0, 1.0]",
        &[1.0, 2.0, 1.0],
    );
}

#[test]
fn integrator_in_tf_form() {
    simulate_and_fit(
        "integrator-tf",
        "kind = \"tf\"\nnum = [1.0]\nden = [1.0, 1.0, 0.0]\nallow_unstable = true",
        &[1.0, 1.0, 0.0],
    );
}

/// Fits the record of `dir` with `system` as the model (the experiment's truth); the estimates.
fn fit_values(dir: &std::path::Path, system: &str) -> Vec<f64> {
    let exp = dir.join("fit.toml");
    std::fs::write(&exp, experiment(system)).unwrap();
    let data = dir.join("d.csv");
    let o = jitterid()
        .args([
            "fit",
            exp.to_str().unwrap(),
            "--data",
            data.to_str().unwrap(),
            "--json",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let fit: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(fit["converged"], Value::Bool(true), "{fit}");
    fit["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["estimate"].as_f64().unwrap())
        .collect()
}

/// A record of a double pole fitted in zpk form from two distinct real poles around it. At
/// the minimum the copies are nearly interchangeable (ill-conditioned standard errors), so the
/// check is against the same record fitted in tf form, whose minimum is the same model (a
/// start exactly at the coincidence is a symmetric saddle of the zpk parametrisation: the
/// two poles' gradients are equal there and a search stays on the diagonal): the expanded coefficients agree to the solvers'
/// relative cost tolerance (`~1e-6` relative in the parameters; `1e-4` leaves a margin, a wrong
/// response or gradient is off by percents).
#[test]
fn repeated_zpk_poles_agree_with_the_tf_fit() {
    let zpk = "kind = \"zpk\"\ngain = 0.5\nzeros = [-0.5]\npoles = [-0.7, -0.9]";
    let dir = simulate_and_fit(
        "double-zpk-tf",
        "kind = \"tf\"\nnum = [0.5, 0.25]\nden = [1.0, 1.6, 0.64]",
        &[0.5, 0.25, 1.6, 0.64],
    );
    let z = fit_values(&dir, zpk);
    let t = fit_values(
        &dir,
        "kind = \"tf\"\nnum = [0.5, 0.25]\nden = [1.0, 1.6, 0.64]",
    );
    let (gain, zero, p0, p1) = (z[0], z[1], z[2], z[3]);
    let expanded = [gain, -gain * zero, -(p0 + p1), p0 * p1];
    for (a, b) in expanded.iter().zip(&t) {
        assert!(
            (a - b).abs() <= 1e-4 * b.abs().max(0.1),
            "zpk {expanded:?} vs tf {t:?}"
        );
    }
}

#[test]
fn unstable_pole_needs_the_opt_in() {
    let dir = scratch_in("jitterid-confluent", "unstable");
    let exp = dir.join("exp.toml");
    std::fs::write(
        &exp,
        experiment("kind = \"tf\"\nnum = [1.0]\nden = [1.0, -0.1]"),
    )
    .unwrap();
    let data = dir.join("d.csv");
    let args = [
        "simulate",
        exp.to_str().unwrap(),
        "--out",
        data.to_str().unwrap(),
    ];
    let o = jitterid().args(args).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("den") && e.contains("stable"), "{e}");
}
