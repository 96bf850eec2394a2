//! Helpers shared by the command-line test files (each file is its own crate, and uses some
//! of them): run the built binary, scratch directories, example experiments.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The built `jitterid` binary.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_jitterid"))
}

/// Runs the binary with `args`.
pub fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("the binary runs")
}

/// Standard output as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A fresh, empty directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("jitterid-cli")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A path as `&str` for an argument list.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The names in a directory, sorted (none if it does not exist).
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The path of an example experiment file.
pub fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/experiments")
        .join(name)
        .display()
        .to_string()
}

/// A fresh, empty directory `name` of the test group `group`.
pub fn scratch_in(group: &str, name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(group)
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The built `jitterid` binary.
pub fn jitterid() -> Command {
    bin()
}

/// An example experiment file's text with its first line starting with `from` replaced.
pub fn example_with(name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(example(name)).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with(from))
        .unwrap_or_else(|| panic!("{name} has no line starting with {from:?}"));
    text.replacen(line, to, 1)
}

/// Runs `jitterid simulate` on the experiment `text`, written to a fresh scratch directory of
/// `group`: the process output and the data file it was asked to write.
pub fn simulate_text(group: &str, name: &str, text: &str) -> (Output, PathBuf) {
    let d = scratch_in(group, name);
    let exp = d.join("e.toml");
    std::fs::write(&exp, text).unwrap();
    let out = d.join("d.csv");
    let o = jitterid()
        .args(["simulate", s(&exp), "--out", s(&out)])
        .output()
        .unwrap();
    (o, out)
}

/// A fit's estimate and standard error of the parameter `name` (`fit --json`'s
/// `parameters`); the standard error is NaN where the fit reports none.
pub fn param(fit: &serde_json::Value, name: &str) -> (f64, f64) {
    let p = fit["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no {name} in {fit}"));
    (
        p["estimate"].as_f64().unwrap(),
        p["stderr"].as_f64().unwrap_or(f64::NAN),
    )
}

/// Simulates run `run_no` of the experiment file `exp` into `dir` (`d.csv`, with its side
/// files) and fits it with the arguments `extra` added: the fit's JSON.
pub fn simulate_and_fit_in(
    dir: &Path,
    exp: &str,
    run_no: &str,
    extra: &[&str],
) -> serde_json::Value {
    let data = dir.join("d.csv");
    let o = run(&["simulate", exp, "--run", run_no, "--out", s(&data)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut args = vec!["fit", exp, "--data", s(&data), "--json"];
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap()
}

/// `fit --init auto` of the example experiment `name` with every start made wrong by
/// `replacements` (each `(from, to)` in its text) reaches the fit from the truth on run 2 of
/// the example (in scratch directory `init-auto` of `group`): each of `names` within `1e-3` of
/// its standard error, far within it.
pub fn init_auto_reaches_the_truth_s_optimum(
    group: &str,
    name: &str,
    replacements: &[(&str, &str)],
    names: &[&str],
) {
    let dir = scratch_in(group, "init-auto");
    let truth = example(name);
    let wrong = replacements
        .iter()
        .fold(std::fs::read_to_string(&truth).unwrap(), |t, (from, to)| {
            t.replace(from, to)
        });
    let wrong_path = dir.join("wrong.toml");
    std::fs::write(&wrong_path, wrong).unwrap();
    let from_truth = simulate_and_fit_in(&dir, &truth, "2", &[]);
    let data = dir.join("d.csv");
    let o = run(&[
        "fit",
        s(&wrong_path),
        "--data",
        s(&data),
        "--init",
        "auto",
        "--json",
    ]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let auto: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    for name in names {
        let ((a, se), (b, _)) = (param(&from_truth, name), param(&auto, name));
        assert!((a - b).abs() < 1e-3 * se, "{name}: {a} vs {b} (± {se})");
    }
}

/// `jitterid design` of Table 2 with `args` exits 2 with one line that contains `want`.
pub fn design_refused(args: &[&str], want: &str) {
    let table2 = example("table2.toml");
    let mut all = vec!["design", table2.as_str()];
    all.extend_from_slice(args);
    let o = run(&all);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains(want), "{args:?}: expected {want:?} in {err}");
}

/// `simulate` of the experiment `text` (in scratch directory `name` of `group`): exit 2, one
/// line holding every one of `expect`, no data written.
pub fn refused_text(group: &str, name: &str, text: &str, expect: &[&str]) {
    let (o, out) = simulate_text(group, name, text);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert!(!out.exists(), "{name}");
    assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
    for e in expect {
        assert!(err.contains(e), "{name}: expected {e:?} in {err}");
    }
}

/// `select` on run `run_no` of the experiment `text` with `[select] poles = [1, 2]` appended,
/// written to `dir` (`e.toml`, the record `d.csv`): the selection's JSON.
pub fn select_poles_1_to_2(dir: &Path, text: &str, run_no: &str) -> serde_json::Value {
    let exp = dir.join("e.toml");
    std::fs::write(&exp, format!("{text}\n[select]\npoles = [1, 2]\n")).unwrap();
    let data = dir.join("d.csv");
    let o = run(&["simulate", s(&exp), "--run", run_no, "--out", s(&data)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&["select", s(&exp), "--data", s(&data), "--json"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap()
}
