//! The jitter families that reach the command line through the library's registry alone:
//! periodic jitter and an independent sum (the dual-Dirac model), each from its example
//! experiment file, through the real binary — simulate, fit with the family estimated, and a
//! small seeded Monte Carlo study whose mean is unbiased.

mod common;

use common::{example, jitterid, scratch_in};
use serde_json::Value;

fn ok(args: &[&str]) -> String {
    let o = jitterid().args(args).output().unwrap();
    assert!(
        o.status.success(),
        "jitterid {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn json(args: &[&str]) -> Value {
    let text = ok(args);
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{args:?}: not JSON ({e}): {text}"))
}

/// Simulates one record, fits it with the family estimated, and checks the fit converged
/// with the expected parameter names, each estimate finite.
fn simulate_and_fit(name: &str, names: &[&str]) {
    let d = scratch_in("jitterid-families", name);
    let data = d.join("d.csv");
    let exp = example(&format!("{name}.toml"));
    ok(&[
        "simulate",
        &exp,
        "--out",
        data.to_str().unwrap(),
        "--seed",
        "3",
    ]);
    let f = json(&["fit", &exp, "--data", data.to_str().unwrap(), "--json"]);
    assert_eq!(f["converged"], true, "{name}: {f}");
    let params = f["parameters"].as_array().unwrap();
    let got: Vec<&str> = params.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(got, names, "{name}");
    for p in params {
        assert!(p["estimate"].as_f64().unwrap().is_finite(), "{name}: {p}");
    }
}

/// A seeded Monte Carlo study of `runs` realisations: every estimated parameter's mean lies
/// within 3 standard errors of the truth. The standard error is the study's own
/// `se = std/√n` over the converged runs, so the bound is that of an unbiased estimator's
/// mean (a two-sided 99.7 % band per parameter); the seed is fixed, so the test is exact.
fn unbiased(name: &str, runs: &str) {
    let j = json(&[
        "montecarlo",
        &example(&format!("{name}.toml")),
        "--runs",
        runs,
        "--seed",
        "11",
        "--json",
    ]);
    let converged = j["converged"].as_u64().unwrap();
    assert!(
        converged * 10 >= runs.parse::<u64>().unwrap() * 9,
        "{name}: {j}"
    );
    for p in j["parameters"].as_array().unwrap() {
        let (truth, mean, se) = (
            p["true"].as_f64().unwrap(),
            p["mean"].as_f64().unwrap(),
            p["se"].as_f64().unwrap(),
        );
        assert!(se > 0.0, "{name}: {p}");
        assert!(
            (mean - truth).abs() <= 3.0 * se,
            "{name}: {} mean {mean} is {:.2} standard errors from the truth {truth}",
            p["name"],
            (mean - truth).abs() / se
        );
    }
}

#[test]
fn periodic_jitter_from_a_file_simulates_and_fits() {
    simulate_and_fit("periodic", &["jitter.amplitude"]);
}

#[test]
fn periodic_jitter_montecarlo_is_unbiased() {
    unbiased("periodic", "32");
}

#[test]
fn dual_dirac_sum_from_a_file_simulates_and_fits() {
    simulate_and_fit("dual-dirac", &["jitter.terms.0.sigma", "jitter.terms.1.d"]);
}

#[test]
fn dual_dirac_sum_montecarlo_is_unbiased() {
    unbiased("dual-dirac", "32");
}
