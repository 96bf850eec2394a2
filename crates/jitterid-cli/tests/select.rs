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
        ("families = [\"gaussian\", \"sum\"]", "families"),
        ("families = [\"mixture\"]", "families"),
        ("poles = [1, 150]", "poles"),
    ] {
        let exp = experiment(dir.path(), select);
        let out = jitterid(&["select", &exp, "--data", "/nonexistent.csv"]);
        assert_eq!(out.status.code(), Some(2), "{select}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(&format!("[select] {key}")), "{select}: {err}");
    }
}

/// `examples/experiments/dead-time.toml` (Table 2's system, input delayed by 1.5 s) with an
/// input history of 50 s before `t0` and `initial = "estimate"`, under `[select]`.
fn delayed_experiment(dir: &Path, name: &str, estimate: bool) -> String {
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/experiments/dead-time.toml"),
    )
    .unwrap()
    .replace("high = 1.0\n", "high = 1.0\nhistory = 50.0\n")
    .replace(
        "estimate = true\ndelay = 1.5",
        &format!("estimate = {estimate}\ninitial = \"estimate\"\ndelay = 1.5"),
    );
    assert!(base.contains("history = 50.0") && base.contains("initial = \"estimate\""));
    let path = dir.join(name);
    let select = "poles = [2, 2]\nzeros = [0, 1]\nfamilies = [\"gaussian\"]";
    std::fs::write(&path, format!("{base}\n[select]\n{select}\n")).unwrap();
    path.display().to_string()
}

fn json_of(out: &std::process::Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn candidates_carry_the_experiments_delay_and_initial_state() {
    let dir = tempfile::tempdir().unwrap();
    let exp = delayed_experiment(dir.path(), "estimated.toml", true);
    let data = dir.path().join("d.csv").display().to_string();
    assert!(jitterid(&["simulate", &exp, "--seed", "3", "--out", &data])
        .status
        .success());
    let v = json_of(&jitterid(&["select", &exp, "--data", &data, "--json"]));
    let best = &v["best"];
    // The truth: 2 poles, 1 zero. Without the delay a candidate spends a zero on its phase.
    assert_eq!(
        (best["poles"].as_u64(), best["zeros"].as_u64()),
        (Some(2), Some(1))
    );
    let est = &best["estimates"];
    for key in ["initial.0", "initial.1"] {
        assert!(est[key].is_f64(), "{key} in {est}");
    }
    // The independent route: `fit` of the file's own structure (BCLS, the jitter known)
    // estimates the delay with a standard error; the selection's estimate (exact ML, the
    // jitter's family Gaussian) is another estimate of the same 1.5 s, so both lie within a
    // few standard errors of it.
    let fit = json_of(&jitterid(&["fit", &exp, "--data", &data, "--json"]));
    let delay = fit["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "delay")
        .unwrap();
    let se = delay["stderr"].as_f64().unwrap();
    let d = est["delay"].as_f64().unwrap();
    assert!(se > 0.0 && se < 0.5, "delay stderr {se}");
    assert!((d - 1.5).abs() < 4.0 * se, "select's delay {d}, se {se}");

    // A known delay (the system's keys not estimated) delays the input: no `delay` parameter,
    // and the same order wins.
    let known = delayed_experiment(dir.path(), "known.toml", false);
    let v = json_of(&jitterid(&["select", &known, "--data", &data, "--json"]));
    let best = &v["best"];
    assert_eq!(
        (best["poles"].as_u64(), best["zeros"].as_u64()),
        (Some(2), Some(1))
    );
    assert!(best["estimates"].get("delay").is_none(), "{best}");
    assert!(best["estimates"]["initial.1"].is_f64(), "{best}");
}
