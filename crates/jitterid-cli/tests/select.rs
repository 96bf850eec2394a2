//! `jitterid select` through the binary: JSON shape, best-first ranking, and bad grids (exit 2).

use std::path::Path;
use std::process::Command;

fn jitterid(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_jitterid"))
        .args(args)
        .output()
        .expect("runs")
}

fn experiment(dir: &Path, select: &str) -> String {
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/experiments/table2.toml"),
    )
    .unwrap();
    let path = dir.join("exp.toml");
    std::fs::write(&path, format!("{base}\n[select]\n{select}\n")).unwrap();
    path.display().to_string()
}

#[test]
fn ranks_best_first_and_reports_validation_fit() {
    let dir = tempfile::tempdir().unwrap();
    let exp = experiment(
        dir.path(),
        "poles = [1, 2]\nzeros = [0, 1]\nfamilies = [\"none\", \"gaussian\"]",
    );
    let data = dir.path().join("d.csv").display().to_string();
    let val = dir.path().join("v.csv").display().to_string();
    assert!(jitterid(&["simulate", &exp, "--out", &data])
        .status
        .success());
    assert!(jitterid(&["simulate", &exp, "--run", "1", "--out", &val])
        .status
        .success());
    let out = jitterid(&[
        "select",
        &exp,
        "--data",
        &data,
        "--validation",
        &val,
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let c = v["candidates"].as_array().unwrap();
    assert_eq!(c.len(), 8);
    assert_eq!(v["best"], c[0]);
    // The truth of table2.toml has two poles and one zero.
    assert_eq!(
        (c[0]["poles"].as_u64(), c[0]["zeros"].as_u64()),
        (Some(2), Some(1))
    );
    for key in ["family", "criterion", "converged", "estimates"] {
        assert!(c[0].get(key).is_some(), "{key}");
    }
    assert!(c[0]["validation_fit_percent"].as_f64().unwrap() > 50.0);
    assert!(v["best_validation"].is_object());
}

#[test]
fn bad_grids_exit_2_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    for (select, key) in [
        ("poles = [3, 1]", "poles"),
        ("zeros = [2]", "zeros"),
        ("families = []", "families"),
        ("families = [\"cauchy\"]", "families"),
        ("poles = [1, 150]", "poles"),
    ] {
        let exp = experiment(dir.path(), select);
        let out = jitterid(&["select", &exp, "--data", "/nonexistent.csv"]);
        assert_eq!(out.status.code(), Some(2), "{select}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(&format!("[select] {key}")), "{select}: {err}");
    }
}
