//! What a script may rely on, through the real binary: outputs that never replace a device and
//! appear together or not at all, shards that merge only with their own study, exit statuses,
//! and error lines a person can read.

mod common;

use common::{bin, files_in as names_in, run, s, scratch, stderr, stdout};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the binary with `args` from the directory `cwd`.
fn run_in(cwd: &Path, args: &[&str]) -> Output {
    bin()
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Asserts the exit status; returns stdout.
fn status(args: &[&str], code: i32) -> String {
    let o = run(args);
    assert_eq!(
        o.status.code(),
        Some(code),
        "jitterid {args:?}: {}",
        stderr(&o)
    );
    stdout(&o)
}

/// Asserts exit status 2 with one error line containing every `want`; returns the line.
fn refused(args: &[&str], want: &[&str]) -> String {
    let o = run(args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "jitterid {args:?}: {e}");
    assert_eq!(e.trim_end().lines().count(), 1, "not one line: {e}");
    for w in want {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    e
}

/// A small random-binary experiment (with a side file) that simulates and fits quickly.
const SMALL: &str = r#"[sampling]
interval = 1.0
samples = 64
[input]
kind = "random-binary"
mean_dwell = 6.0
[system]
kind = "zpk"
gain = 1.0
poles = [-0.5]
estimate = true
[jitter]
family = "gaussian"
sigma = 0.1
[noise]
std = 0.01
[estimate]
method = "ls"
"#;

fn small(dir: &Path) -> PathBuf {
    let p = dir.join("small.toml");
    std::fs::write(&p, SMALL).unwrap();
    p
}

// ---------------------------------------------------------------------------------------------
// Output safety

#[cfg(unix)]
fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

#[cfg(unix)]
fn is_fifo(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(path)
        .map(|m| m.file_type().is_fifo())
        .unwrap_or(false)
}

/// Reads a FIFO to its end on another thread (a writer blocks until there is a reader).
#[cfg(unix)]
fn drain(path: &Path) -> std::thread::JoinHandle<String> {
    let p = path.to_path_buf();
    std::thread::spawn(move || std::fs::read_to_string(p).unwrap())
}

#[cfg(unix)]
#[test]
fn a_fifo_given_to_out_is_written_through_not_replaced() {
    let dir = scratch("fifo");
    let exp = small(&dir);
    let fifo = dir.join("pipe.csv");
    mkfifo(&fifo);
    let reader = drain(&fifo);
    let report = status(&["simulate", s(&exp), "--out", s(&fifo)], 0);
    let data = reader.join().unwrap();
    assert!(data.starts_with("k,t,y,u\n"), "{data:.80}");
    assert_eq!(data.lines().count(), 65);
    assert!(is_fifo(&fifo), "the FIFO was replaced");
    // No side file beside a pipe (for /dev/null that would be /dev/null.input.csv).
    assert_eq!(names_in(&dir), ["pipe.csv", "small.toml"]);
    assert!(report.contains("not written"), "{report}");
    // The JSON of montecarlo goes through a FIFO too.
    let reader = drain(&fifo);
    status(
        &[
            "montecarlo",
            s(&exp),
            "--runs",
            "2",
            "--json",
            "--out",
            s(&fifo),
        ],
        0,
    );
    let json: Value = serde_json::from_str(&reader.join().unwrap()).unwrap();
    assert_eq!(json["runs"], 2);
    assert!(is_fifo(&fifo));
}

/// A FIFO that no process reads does not block the command for ever: after a short wait it is
/// an error (status 2, one line), and the FIFO stays. The result says the wait ended: the
/// message is the one the command gives when its wait for a reader runs out (a command that
/// blocked would never exit, and the harness, not a clock in the test, would stop it).
#[cfg(unix)]
#[test]
fn a_fifo_without_a_reader_is_refused_not_waited_for_ever() {
    let dir = scratch("fifo-no-reader");
    let exp = small(&dir);
    let fifo = dir.join("pipe.csv");
    mkfifo(&fifo);
    refused(
        &["simulate", s(&exp), "--out", s(&fifo)],
        &["pipe.csv", "no process is reading"],
    );
    assert!(is_fifo(&fifo));
    assert_eq!(names_in(&dir), ["pipe.csv", "small.toml"]);
}

/// A character device given to `--out` (a null device made for the test with `mknod`, which
/// needs root, so the machine's `/dev/null` is never at stake) stays a device and has no side
/// file written beside it. Where `mknod` is not allowed, the FIFO test above covers the path.
#[cfg(unix)]
#[test]
fn a_character_device_given_to_out_stays_a_device() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("char-device");
    let exp = small(&dir);
    let null = dir.join("null");
    let made = Command::new("mknod")
        .args([s(&null), "c", "1", "3"])
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|st| st.success());
    if !made {
        eprintln!("mknod not permitted here (not root): character-device case not run");
        return;
    }
    let report = status(&["simulate", s(&exp), "--out", s(&null)], 0);
    assert!(report.contains("not written"), "{report}");
    let kind = std::fs::symlink_metadata(&null).unwrap().file_type();
    assert!(kind.is_char_device(), "the device was replaced");
    assert_eq!(names_in(&dir), ["null", "small.toml"]);
}

#[cfg(unix)]
#[test]
fn a_symlink_given_to_out_is_followed_and_kept() {
    let dir = scratch("symlink");
    let exp = small(&dir);
    let real = dir.join("real.csv");
    std::fs::write(&real, "old").unwrap();
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    status(&["simulate", s(&exp), "--out", s(&link)], 0);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read_to_string(&real)
        .unwrap()
        .starts_with("k,t,y,u\n"));
    // The side file is named after the name given, where `fit --data link.csv` looks for it.
    assert!(dir.join("link.input.csv").is_file());
    // A link to a FIFO: written through, link and FIFO stay.
    let fifo = dir.join("pipe");
    mkfifo(&fifo);
    let via = dir.join("via");
    std::os::unix::fs::symlink(&fifo, &via).unwrap();
    let reader = drain(&fifo);
    status(&["simulate", s(&exp), "--out", s(&via)], 0);
    assert!(reader.join().unwrap().starts_with("k,t,y,u\n"));
    assert!(is_fifo(&fifo));
    assert!(std::fs::symlink_metadata(&via)
        .unwrap()
        .file_type()
        .is_symlink());
    // A link to nothing is refused, and left alone.
    let dangling = dir.join("dangling.csv");
    std::os::unix::fs::symlink(dir.join("nothing"), &dangling).unwrap();
    refused(
        &["simulate", s(&exp), "--out", s(&dangling)],
        &["dangling.csv", "symbolic link"],
    );
    assert!(!dir.join("nothing").exists());
}

#[test]
fn a_directory_given_to_out_is_refused() {
    let dir = scratch("out-dir");
    let exp = small(&dir);
    let target = dir.join("d.csv");
    std::fs::create_dir(&target).unwrap();
    refused(
        &["simulate", s(&exp), "--out", s(&target)],
        &["d.csv", "is a directory"],
    );
    assert!(target.is_dir());
    assert_eq!(names_in(&dir), ["d.csv", "small.toml"]);
}

#[test]
fn simulate_writes_data_and_side_file_together_or_neither() {
    let dir = scratch("all-or-nothing-simulate");
    let exp = small(&dir);
    let data = dir.join("d.csv");
    std::fs::write(&data, "previous").unwrap();
    std::fs::create_dir(dir.join("d.input.csv")).unwrap();
    refused(
        &["simulate", s(&exp), "--out", s(&data)],
        &["d.input.csv", "is a directory"],
    );
    assert_eq!(std::fs::read_to_string(&data).unwrap(), "previous");
    // No temporary is left behind.
    assert_eq!(names_in(&dir), ["d.csv", "d.input.csv", "small.toml"]);
}

#[test]
fn montecarlo_writes_json_and_figures_together_or_neither() {
    let dir = scratch("all-or-nothing-montecarlo");
    let exp = small(&dir);
    let figs = dir.join("figs");
    let with_out = |out: &Path| -> Vec<String> {
        [
            "montecarlo",
            s(&exp),
            "--runs",
            "2",
            "--plot",
            s(&figs),
            "--out",
            s(out),
        ]
        .map(String::from)
        .to_vec()
    };
    let args = with_out(&dir.join("nodir/r.json"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&args, &["nodir", "does not exist"]);
    assert!(!figs.exists(), "left {:?}", names_in(&figs));
    assert_eq!(names_in(&dir), ["small.toml"]);
    // With a writable target both appear.
    let args = with_out(&dir.join("r.json"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    status(&args, 0);
    assert!(dir.join("r.json").is_file());
    assert!(!names_in(&figs).is_empty());
}

// ---------------------------------------------------------------------------------------------
// Shard identity

/// Writes shard `i/2` of a 6-run study of `exp` to `out`, run from `cwd`.
fn shard(cwd: &Path, exp: &str, i: u32, out: &str, extra: &[&str]) {
    let part = format!("{i}/2");
    let mut args = vec![
        "montecarlo",
        exp,
        "--runs",
        "6",
        "--seed",
        "5",
        "--json",
        "--shard",
        &part,
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    let o = run_in(cwd, &args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn write_json(p: &Path, v: &Value) {
    std::fs::write(p, serde_json::to_string_pretty(v).unwrap()).unwrap();
}

/// Two good shards of the small study in `dir` (the first written by relative paths from `dir`,
/// the second by absolute paths).
fn two_shards(dir: &Path) -> (PathBuf, PathBuf) {
    let exp = small(dir);
    shard(dir, "small.toml", 0, "s0.json", &[]);
    let s1 = dir.join("s1.json");
    shard(dir, s(&exp), 1, s(&s1), &[]);
    (dir.join("s0.json"), s1)
}

#[test]
fn the_same_experiment_by_two_paths_merges() {
    let dir = scratch("merge-two-paths");
    let (s0, s1) = two_shards(&dir);
    let whole = status(
        &[
            "montecarlo",
            s(&dir.join("small.toml")),
            "--runs",
            "6",
            "--seed",
            "5",
            "--json",
        ],
        0,
    );
    let whole: Value = serde_json::from_str(&whole).unwrap();
    let o = run_in(&dir, &["merge", "s0.json", s(&s1), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let merged: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(merged["parameters"], whole["parameters"]);
    assert_eq!(merged["terminations"], whole["terminations"]);
    assert_eq!(merged["fingerprint"], whole["fingerprint"]);
    let shard0 = read_json(&s0);
    assert_eq!(shard0["fingerprint"].as_str().unwrap().len(), 64);
    assert!(shard0["program"].as_str().unwrap().starts_with("jitterid "));
}

#[test]
fn shards_of_an_edited_experiment_do_not_merge() {
    let dir = scratch("merge-edited");
    for (name, from, to) in [
        (
            "gain-and-poles",
            "gain = 1.0\npoles = [-0.5]",
            "gain = 2.0\npoles = [-0.25]",
        ),
        ("samples-and-noise", "samples = 64\n", "samples = 70\n"),
        ("noise", "std = 0.01", "std = 0.02"),
    ] {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        let exp = small(&d);
        shard(&d, s(&exp), 0, s(&d.join("s0.json")), &[]);
        let text = SMALL.replace(from, to);
        assert_ne!(text, SMALL);
        std::fs::write(&exp, text).unwrap();
        shard(&d, s(&exp), 1, s(&d.join("s1.json")), &[]);
        refused(
            &["merge", s(&d.join("s0.json")), s(&d.join("s1.json"))],
            &["s1.json", "another study", "experiment (fingerprint"],
        );
    }
}

#[test]
fn shards_of_other_seeds_methods_or_run_counts_do_not_merge() {
    let dir = scratch("merge-identity");
    let (s0, s1) = two_shards(&dir);
    let exp = dir.join("small.toml");
    let other = dir.join("other.json");
    let o = run(&[
        "montecarlo",
        s(&exp),
        "--runs",
        "6",
        "--seed",
        "6",
        "--json",
        "--shard",
        "1/2",
        "--out",
        s(&other),
    ]);
    assert!(o.status.success());
    refused(&["merge", s(&s0), s(&other)], &["other.json", "seed"]);
    shard(&dir, s(&exp), 1, s(&other), &["--method", "bcls"]);
    refused(&["merge", s(&s0), s(&other)], &["other.json", "method"]);
    // A hand-edited version or run count is named.
    let mut v = read_json(&s1);
    v["program"] = Value::from("jitterid 0.0.1");
    write_json(&other, &v);
    refused(&["merge", s(&s0), s(&other)], &["program version", "0.0.1"]);
    let mut v = read_json(&s1);
    v["shard"]["runs_total"] = Value::from(8);
    write_json(&other, &v);
    refused(&["merge", s(&s0), s(&other)], &["run count"]);
}

/// Merging `s0` with an edit of `s1` is refused with every `want` in the message.
fn edited_shard_is_refused(dir: &Path, name: &str, edit: impl Fn(&mut Value), want: &[&str]) {
    let (s0, s1) = (dir.join("s0.json"), dir.join("s1.json"));
    let mut v = read_json(&s1);
    edit(&mut v);
    let bad = dir.join(format!("{name}.json"));
    write_json(&bad, &v);
    let e = refused(&["merge", s(&s0), s(&bad)], want);
    assert!(e.contains(&format!("{name}.json")), "{name}: {e}");
    // Values are printed as values, never as Rust's `Some(…)`/`None`.
    assert!(!e.contains("Some(") && !e.contains("None"), "{name}: {e}");
}

#[test]
fn hand_edited_shards_do_not_merge() {
    let dir = scratch("merge-edited-shards");
    two_shards(&dir);
    edited_shard_is_refused(
        &dir,
        "no-fingerprint",
        |v| {
            v.as_object_mut().unwrap().remove("fingerprint");
        },
        &["no `fingerprint`"],
    );
    edited_shard_is_refused(
        &dir,
        "true-value",
        |v| v["parameters"][0]["true"] = Value::from(3.0),
        &["true value", "gain", "is 3, not 1 as in"],
    );
    edited_shard_is_refused(
        &dir,
        "short",
        |v| {
            v["realizations"][0]["values"].as_array_mut().unwrap().pop();
        },
        &["run 3", "expected 2 values", "found 1"],
    );
    edited_shard_is_refused(
        &dir,
        "long",
        |v| {
            v["realizations"][1]["values"]
                .as_array_mut()
                .unwrap()
                .push(Value::from(1.0))
        },
        &["run 4", "found 3"],
    );
    edited_shard_is_refused(
        &dir,
        "null-values",
        |v| v["realizations"][0]["values"] = Value::Null,
        &["not a shard file"],
    );
    edited_shard_is_refused(
        &dir,
        "null-mean",
        |v| v["parameters"][0]["mean"] = Value::Null,
        &["summary of `gain`", "(mean none stored, 1", "computed)"],
    );
    edited_shard_is_refused(
        &dir,
        "huge",
        |v| v["realizations"][0]["values"][0] = Value::from(1e308),
        &["summary of `gain`", "edited"],
    );
    edited_shard_is_refused(
        &dir,
        "null-value",
        |v| v["realizations"][2]["values"][1] = Value::Null,
        &["summary of `pole0`", "edited"],
    );
    edited_shard_is_refused(
        &dir,
        "converged",
        |v| v["converged"] = Value::from(0),
        &["`converged` says 0"],
    );
    edited_shard_is_refused(
        &dir,
        "missing-run",
        |v| {
            v["realizations"].as_array_mut().unwrap().pop();
        },
        &["expected 3 realisations", "found 2"],
    );
    edited_shard_is_refused(
        &dir,
        "renumbered",
        |v| v["realizations"][0]["run"] = Value::from(0),
        &["realisation 0 is run 0, expected run 3"],
    );
}

// ---------------------------------------------------------------------------------------------
// Exit statuses

#[test]
fn fit_exits_1_when_it_does_not_converge() {
    let dir = scratch("exit-fit");
    let exp = small(&dir);
    let data = dir.join("d.csv");
    status(&["simulate", s(&exp), "--out", s(&data)], 0);
    let fit = ["fit", s(&exp), "--data", s(&data)];
    assert!(status(&fit, 0).contains("converged ("));
    let limited = [&fit[..], &["--max-iterations", "1"]].concat();
    let out = status(&limited, 1);
    assert!(out.contains("NOT converged"), "{out}");
    let json: Value =
        serde_json::from_str(&status(&[&limited[..], &["--json"]].concat(), 1)).unwrap();
    assert_eq!(json["converged"], false);
    status(&[&limited[..], &["--accept-unconverged"]].concat(), 0);
    refused(
        &[&fit[..], &["--max-iterations", "0"]].concat(),
        &["--max-iterations", "at least 1"],
    );
}

#[test]
fn montecarlo_reports_terminations_and_exits_1_when_no_fit_converged() {
    let dir = scratch("exit-montecarlo");
    let exp = small(&dir);
    let mc = ["montecarlo", s(&exp), "--runs", "3"];
    let table = status(&mc, 0);
    assert!(table.contains("3 converged"), "{table}");
    assert!(table.contains("terminations: 3 × "), "{table}");
    let json: Value = serde_json::from_str(&status(&[&mc[..], &["--json"]].concat(), 0)).unwrap();
    let reasons = json["terminations"].as_object().unwrap();
    assert_eq!(
        reasons.values().map(|c| c.as_u64().unwrap()).sum::<u64>(),
        3
    );
    let none = [&mc[..], &["--max-iterations", "1", "--json"]].concat();
    let json: Value = serde_json::from_str(&status(&none, 1)).unwrap();
    assert_eq!(json["converged"], 0);
    let reasons = json["terminations"].as_object().unwrap();
    assert_eq!(reasons.len(), 1, "{reasons:?}");
    let (reason, count) = reasons.iter().next().unwrap();
    assert_eq!(count, 3);
    assert!(reason.contains("iteration"), "{reason}");
    status(&[&none[..], &["--accept-unconverged"]].concat(), 0);
}

// ---------------------------------------------------------------------------------------------
// Readable errors

/// An experiment whose input is a sine, so a data file needs no side file.
fn sine_input(dir: &Path) -> PathBuf {
    let p = dir.join("sine-input.toml");
    std::fs::write(
        &p,
        SMALL.replace(
            "kind = \"random-binary\"\nmean_dwell = 6.0",
            "kind = \"sine\"\nfrequency = 0.05",
        ),
    )
    .unwrap();
    p
}

fn data_lines(n: usize) -> Vec<String> {
    let mut v = vec!["k,t,y".to_string()];
    v.extend((0..n).map(|k| format!("{k},{k}.0,{}", (k as f64 * 0.3).sin())));
    v
}

#[test]
fn a_data_file_with_200004_columns_gives_a_short_error() {
    let dir = scratch("wide");
    let exp = sine_input(&dir);
    let header: Vec<String> = (0..200_004).map(|i| format!("c{i}")).collect();
    let data = dir.join("wide.csv");
    std::fs::write(&data, format!("{}\n1,2\n", header.join(","))).unwrap();
    let e = refused(
        &["fit", s(&exp), "--data", s(&data)],
        &["wide.csv:2:4:", "expected 200004 cells"],
    );
    assert!(e.len() < 500, "{} bytes", e.len());
    // A header without `y` is named briefly too.
    std::fs::write(
        &data,
        format!("{}\n", header.join(",")) + &"1,".repeat(200_003) + "1\n",
    )
    .unwrap();
    let e = refused(
        &["fit", s(&exp), "--data", s(&data)],
        &["wide.csv:1:", "`y`"],
    );
    assert!(e.len() < 500, "{} bytes", e.len());
}

#[test]
fn data_files_with_cr_line_endings_are_read() {
    let dir = scratch("cr");
    let exp = sine_input(&dir);
    let lines = data_lines(64);
    let lf = dir.join("lf.csv");
    std::fs::write(&lf, lines.join("\n") + "\n").unwrap();
    let cr = dir.join("cr.csv");
    std::fs::write(&cr, lines.join("\r") + "\r").unwrap();
    let a: Value =
        serde_json::from_str(&status(&["fit", s(&exp), "--data", s(&lf), "--json"], 0)).unwrap();
    let b: Value =
        serde_json::from_str(&status(&["fit", s(&exp), "--data", s(&cr), "--json"], 0)).unwrap();
    assert_eq!(a["parameters"], b["parameters"]);
    // A problem in a CR-only file is named by its line and column.
    let mut bad = lines.clone();
    bad[5] = "4,4.0,oops".into();
    std::fs::write(&cr, bad.join("\r")).unwrap();
    refused(
        &["fit", s(&exp), "--data", s(&cr)],
        &["cr.csv:6:7:", "column `y`", "oops"],
    );
}

#[test]
fn simulate_never_writes_samples_that_are_not_numbers() {
    let dir = scratch("non-finite-samples");
    let exp = dir.join("tiny-pole.toml");
    // A pole of magnitude 1e-300 with a random-binary input used to give NaN samples.
    std::fs::write(&exp, SMALL.replace("poles = [-0.5]", "poles = [-1e-300]")).unwrap();
    let data = dir.join("d.csv");
    refused(
        &["simulate", s(&exp), "--out", s(&data)],
        &["tiny-pole.toml"],
    );
    assert_eq!(names_in(&dir), ["tiny-pole.toml"]);
}

// ---------------------------------------------------------------------------------------------
// Bounded work

/// A budget of zero seconds is spent at the first check: the fit stops there and says why (the
/// reason is asserted, never a duration).
#[test]
fn a_fit_that_spends_its_wall_clock_budget_says_so() {
    let dir = scratch("time-limit");
    let exp = small(&dir);
    let data = dir.join("d.csv");
    status(&["simulate", s(&exp), "--out", s(&data)], 0);
    let fit = [
        "fit",
        s(&exp),
        "--data",
        s(&data),
        "--json",
        "--time-limit",
        "0",
    ];
    let json: Value = serde_json::from_str(&status(&fit, 1)).unwrap();
    assert_eq!(json["converged"], false);
    assert_eq!(json["termination"], "wall-clock budget spent");
    let mc = [
        "montecarlo",
        s(&exp),
        "--runs",
        "2",
        "--json",
        "--time-limit",
        "0",
    ];
    let json: Value = serde_json::from_str(&status(&mc, 1)).unwrap();
    assert_eq!(json["terminations"]["wall-clock budget spent"], 2);
    for bad in ["--time-limit=-1", "--time-limit=inf", "--time-limit=NaN"] {
        refused(
            &["fit", s(&exp), "--data", s(&data), bad],
            &["--time-limit", "seconds"],
        );
    }
}

/// Maximum likelihood with the system estimated on all-zero data used to run for minutes
/// without a word; constant data are now refused at once with their reason (bad input).
#[cfg(feature = "ml")]
#[test]
fn ml_on_all_zero_data_is_refused_with_its_reason() {
    let dir = scratch("ml-zero");
    let exp = small(&dir);
    let data = dir.join("zero.csv");
    status(&["simulate", s(&exp), "--out", s(&data)], 0);
    let mut text = String::from("k,y\n");
    for k in 0..64 {
        text.push_str(&format!("{k},0\n"));
    }
    std::fs::write(&data, text).unwrap();
    let o = run(&[
        "fit",
        s(&exp),
        "--data",
        s(&data),
        "--method",
        "ml",
        "--json",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{} {err}", stdout(&o));
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("constant"), "{err}");
}
