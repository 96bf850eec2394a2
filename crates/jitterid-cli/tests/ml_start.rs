//! Where a likelihood fit starts, through the binary: from a start in another basin of the
//! likelihood, `fit --method ml --init experiment-only` stops at a local optimum and is
//! reported as not converged with the reason (exit 1); the default starts at the BCLS estimate
//! and reaches the optimum of a fit started at the truth (a bad `--init` value: `init_auto.rs`).

mod common;

use common::{example, run as jitterid};
use std::path::Path;

/// The example experiment's text.
fn text() -> String {
    std::fs::read_to_string(example("ml-start.toml")).unwrap()
}

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

#[test]
fn a_likelihood_fit_does_not_report_a_local_optimum_as_converged() {
    let dir = tempfile::tempdir().unwrap();
    let s = |p: &Path| p.display().to_string();
    let truth = dir.path().join("truth.toml");
    std::fs::write(&truth, text()).unwrap();
    let wrong_text = text()
        .replace("gain = 2.0", "gain = -2.0")
        .replace("poles = [[-1.0, 2.0]]", "poles = [[-3.0, 0.3]]");
    assert_ne!(wrong_text, text());
    let wrong = dir.path().join("wrong.toml");
    std::fs::write(&wrong, &wrong_text).unwrap();
    let data = dir.path().join("d.csv");
    assert!(
        jitterid(&["simulate", &s(&truth), "--seed", "3", "--out", &s(&data)])
            .status
            .success()
    );
    let fit = |exp: &Path, extra: &[&str]| {
        let (exp, data) = (s(exp), s(&data));
        let mut args = vec!["fit", &exp, "--data", &data, "--method", "ml", "--json"];
        args.extend(extra);
        jitterid(&args)
    };
    let reference = fit(&truth, &["--init", "experiment-only"]);
    let reference = json(&reference);
    assert!(reference["converged"].as_bool().unwrap(), "{reference}");

    // The given start alone: a local optimum far below the reference's likelihood.
    let only = fit(&wrong, &["--init", "experiment-only"]);
    assert_eq!(only.status.code(), Some(1), "{}", json(&only));
    let only = json(&only);
    assert!(!only["converged"].as_bool().unwrap());
    let reason = only["termination"].as_str().unwrap();
    assert!(
        reason.contains("worse optimum") && reason.contains("--init experiment-only"),
        "{reason}"
    );
    let (local, best) = (
        only["cost"].as_f64().unwrap(),
        reference["cost"].as_f64().unwrap(),
    );
    assert!(local > best + 100.0, "{local} against {best}");

    // The default: BCLS first, the likelihood from its estimate, the reference's optimum.
    let default = fit(&wrong, &[]);
    assert!(default.status.success());
    let default = json(&default);
    assert!(default["converged"].as_bool().unwrap(), "{default}");
    assert!((default["cost"].as_f64().unwrap() - best).abs() < 1e-3);
    for (a, b) in default["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .zip(reference["parameters"].as_array().unwrap())
    {
        let (x, y) = (
            a["estimate"].as_f64().unwrap(),
            b["estimate"].as_f64().unwrap(),
        );
        let se = b["stderr"].as_f64().unwrap();
        assert!((x - y).abs() < 1e-3 * se, "{}: {x} against {y}", a["name"]);
    }
}
