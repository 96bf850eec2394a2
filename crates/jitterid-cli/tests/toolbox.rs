//! What a toolbox user expects of the command line, through the real binary: `--set` edits of
//! any experiment key on every subcommand that reads one (the same numbers as the edited file),
//! `[sampling]` from the data file, the notes and status lines of `fit` on measured-data
//! mistakes (an input recorded on the sampling clock, an output offset), `validate`'s table,
//! `select`'s two criteria in two columns, and `validate --model` of a profiled jitter.

mod common;

use common::{example, run, s, scratch_in, stderr, stdout};
use serde_json::Value;
use std::path::{Path, PathBuf};

const GROUP: &str = "jitterid-toolbox";

/// Runs the binary and parses its JSON; `status` required.
fn json_with(args: &[&str], status: i32) -> Value {
    let o = run(args);
    assert_eq!(o.status.code(), Some(status), "{args:?}: {}", stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap_or_else(|e| panic!("{args:?}: {e}"))
}

fn json(args: &[&str]) -> Value {
    json_with(args, 0)
}

/// Asserts exit status 2 and a one-line error holding every one of `expect`.
fn refused(args: &[&str], expect: &[&str]) {
    let o = run(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(stdout(&o).is_empty(), "{args:?}: printed {}", stdout(&o));
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    for e in expect {
        assert!(err.contains(e), "{args:?}: expected {e:?} in {err}");
    }
}

/// A copy of the example `name` in `dir` with each `(from, to)` replaced once.
fn edited_example(dir: &Path, name: &str, edits: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(example(name)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{name} has no {from:?}");
        text = text.replacen(from, to, 1);
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A Table 2 record (seed 1) in `dir`: the data file and its input side file.
fn table2_record(dir: &Path) -> PathBuf {
    table2_run(dir, "d.csv", "0", &[])
}

/// Realisation `run` of Table 2 (seed 1) as `dir/name` with its side file, the experiment
/// edited by the `--set` arguments `set`.
fn table2_run(dir: &Path, name: &str, run_index: &str, set: &[&str]) -> PathBuf {
    let data = dir.join(name);
    let exp = example("table2.toml");
    let mut args = vec!["simulate", exp.as_str(), "--seed", "1", "--run", run_index];
    for x in set {
        args.extend(["--set", x]);
    }
    args.extend(["--out", s(&data)]);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    data
}

/// `--set` gives exactly the numbers of a file edited by hand, on `fit`, `simulate` and
/// `montecarlo`, and a family replaced by `--set jitter.family=…` drops the old family's keys.
#[test]
fn set_gives_the_numbers_of_the_edited_file() {
    let dir = scratch_in(GROUP, "set");
    let data = table2_record(&dir);
    let exp = example("table2.toml");
    let fit = |args: &[&str]| {
        let mut a = vec!["fit", exp.as_str(), "--data", s(&data), "--json"];
        a.extend(args);
        json(&a)
    };
    // A method through the file's key equals the --method flag, and differs from the default.
    let ls = fit(&["--set", "estimate.method=ls"]);
    assert_eq!(ls, fit(&["--method", "ls"]));
    assert_ne!(ls["parameters"], fit(&[])["parameters"]);
    // Another family and its key: the file edited by hand gives the same fit.
    let by_hand = edited_example(
        &dir,
        "table2.toml",
        &[(
            "family = \"uniform-sum\"\nn = 2\na = 0.28867513459481287  # 1/(2√3) s",
            "family = \"gaussian\"\nsigma = 0.1",
        )],
    );
    let gaussian = fit(&[
        "--set",
        "jitter.family=gaussian",
        "--set",
        "jitter.sigma=0.1",
    ]);
    let want = json(&["fit", s(&by_hand), "--data", s(&data), "--json"]);
    assert_eq!(gaussian, want);
    assert_ne!(gaussian["parameters"], fit(&[])["parameters"]);
    // simulate: the record's length from the override.
    let short = dir.join("short.csv");
    let o = run(&[
        "simulate",
        &exp,
        "--set",
        "sampling.samples=50",
        "--out",
        s(&short),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = std::fs::read_to_string(&short).unwrap().lines().count();
    assert_eq!(rows, 51);
    // montecarlo: an array value and a number, against the file edited by hand (the study's
    // fingerprint is of the parsed values, so it is equal too).
    let mc = |exp: &str, extra: &[&str]| {
        let mut a = vec![
            "montecarlo",
            exp,
            "--runs",
            "3",
            "--json",
            "--no-timing",
            "--threads",
            "1",
        ];
        a.extend(extra);
        let mut v = json(&a);
        v.as_object_mut().unwrap().remove("experiment");
        v
    };
    let by_hand = edited_example(
        &dir,
        "table2.toml",
        &[
            ("samples = 200", "samples = 120"),
            ("zeros = [-0.5]", "zeros = [-0.6]"),
        ],
    );
    let set = mc(
        &exp,
        &[
            "--set",
            "sampling.samples=120",
            "--set",
            "system.zeros=[-0.6]",
        ],
    );
    assert_eq!(set, mc(s(&by_hand), &[]));
    assert_ne!(set, mc(&exp, &[]));
}

/// A bad key or value is exit status 2 on every subcommand that reads an experiment file,
/// naming the edit and the key; lines the edits did not touch keep their numbers.
#[test]
fn a_bad_set_names_the_key_on_every_subcommand() {
    let dir = scratch_in(GROUP, "set-refused");
    let data = table2_record(&dir);
    let exp = example("table2.toml");
    let out = dir.join("never.csv");
    let commands: [Vec<&str>; 5] = [
        vec!["simulate", &exp, "--out", s(&out)],
        vec!["fit", &exp, "--data", s(&data)],
        vec!["montecarlo", &exp, "--runs", "1"],
        vec!["select", &exp, "--data", s(&data)],
        vec!["validate", &exp, "--data", s(&data)],
    ];
    for base in &commands {
        let with = |set: &[&'static str]| -> Vec<&str> {
            let mut a = base.clone();
            for x in set {
                a.extend(["--set", *x]);
            }
            a
        };
        refused(
            &with(&["jitter.family=gaussian", "jitter.sigma=-1"]),
            &["(--set jitter.sigma=-1): [jitter] sigma", "> 0"],
        );
        refused(
            &with(&["jitter.sigmaa=0.1"]),
            &["(--set jitter.sigmaa=0.1): [jitter]", "`sigmaa`"],
        );
        refused(&with(&["jitter"]), &["--set jitter: expected key=value"]);
        refused(
            &with(&["system.den=[1,2"]),
            &[
                "--set system.den=[1,2: key `system.den`",
                "not a TOML value",
            ],
        );
        refused(
            &with(&["sampling=3"]),
            &["--set sampling=3: key `sampling` is a table"],
        );
        refused(
            &with(&["system.gain=\"big\""]),
            &["(--set system.gain=\"big\"): [system] gain", "string"],
        );
    }
    assert!(!out.exists());
    // An edited value is named by its edit; an error about a line the edits left keeps the
    // file's line number (`poles` is on line 26 of table2.toml, after the line the edit of
    // `[input] history` adds).
    refused(
        &[
            "fit",
            &exp,
            "--data",
            s(&data),
            "--set",
            "system.poles=[[0.25, 0.3]]",
        ],
        &[
            "(--set system.poles=[[0.25, 0.3]]): [system] poles",
            "stable",
        ],
    );
    let unstable = edited_example(
        &dir,
        "table2.toml",
        &[("poles = [[-0.25, 0.3]]", "poles = [[0.25, 0.3]]")],
    );
    refused(
        &[
            "fit",
            s(&unstable),
            "--data",
            s(&data),
            "--set",
            "input.history=0",
        ],
        &["table2.toml:26: [system] poles"],
    );
}

/// `[sampling] samples`, `start` and `interval` left out are read from the data file: the same
/// fit as with the file's own; a `t` column off a uniform grid is refused naming its line.
#[test]
fn sampling_from_the_data_file() {
    let dir = scratch_in(GROUP, "sampling");
    let data = table2_record(&dir);
    let exp = example("table2.toml");
    let want = json(&["fit", &exp, "--data", s(&data), "--json"]);
    let no_sampling = edited_example(
        &dir,
        "table2.toml",
        &[
            ("interval = 1.0     # T (s)\n", ""),
            ("samples = 200      # N\n", ""),
            ("start = 0.0        # t0 (s)\n", ""),
        ],
    );
    let got = json(&["fit", s(&no_sampling), "--data", s(&data), "--json"]);
    assert_eq!(got, want);
    // Validate and select read the same grid.
    let v = json(&["validate", s(&no_sampling), "--data", s(&data), "--json"]);
    assert_eq!(v["estimation"]["samples"], 200);
    // A shorter record with the same file: its own length.
    let text = std::fs::read_to_string(&data).unwrap();
    let short = dir.join("short.csv");
    let lines: Vec<&str> = text.lines().collect();
    std::fs::write(&short, lines[..151].join("\n") + "\n").unwrap();
    std::fs::copy(dir.join("d.input.csv"), dir.join("short.input.csv")).unwrap();
    let f = json(&["fit", s(&no_sampling), "--data", s(&short), "--json"]);
    assert!(f["converged"].as_bool().unwrap(), "{f}");
    refused(
        &["fit", &exp, "--data", s(&short)],
        &["has 150 data rows, expected 200"],
    );
    // A record whose 41st sample was taken 0.3 s late: its line is named.
    let late: Vec<String> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| {
            if i == 41 {
                let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
                c[1] = "40.3".into();
                c.join(",")
            } else {
                (*l).to_string()
            }
        })
        .collect();
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, late.join("\n") + "\n").unwrap();
    std::fs::copy(dir.join("d.input.csv"), dir.join("bad.input.csv")).unwrap();
    refused(
        &["fit", s(&no_sampling), "--data", s(&bad)],
        &[
            "bad.csv:42: column `t`: 40.3 is not on the uniform grid",
            "should be 40",
        ],
    );
    // Without `t` the interval cannot be read: the message says so.
    let no_t: Vec<String> = lines
        .iter()
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            format!("{},{}", c[0], c[2])
        })
        .collect();
    let bare = dir.join("bare.csv");
    std::fs::write(&bare, no_t.join("\n") + "\n").unwrap();
    std::fs::copy(dir.join("d.input.csv"), dir.join("bare.input.csv")).unwrap();
    refused(
        &["fit", s(&no_sampling), "--data", s(&bare)],
        &["bare.csv: no column `t`", "[sampling] interval"],
    );
    // With the interval in the file, the row count alone sets the length.
    let f = json(&[
        "fit",
        s(&no_sampling),
        "--data",
        s(&bare),
        "--set",
        "sampling.interval=1.0",
        "--json",
    ]);
    assert_eq!(f, want);
}

/// The record of `data` with its input as the samples' `u` held between them (a zero-order
/// hold on the sampling clock), as an experiment reading it through `[input] kind = "csv"`.
fn held_input_experiment(dir: &Path, data: &Path) -> PathBuf {
    let text = std::fs::read_to_string(data).unwrap();
    let held: Vec<String> = text
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            format!("{},{}", c[1], c[3])
        })
        .collect();
    std::fs::write(dir.join("held.csv"), format!("t,u\n{}\n", held.join("\n"))).unwrap();
    edited_example(
        dir,
        "table2.toml",
        &[(
            "kind = \"random-binary\"\nmean_dwell = 8.0   # mean time between switches (s), exponentially distributed\nlow = 0.0\nhigh = 1.0",
            "kind = \"csv\"\npath = \"held.csv\"",
        )],
    )
}

/// An input on the sampling grid and an output offset are noted; the status line of a fit
/// stopped by the flatness check says `stopped: converged, but …` with the likely cause, never
/// `NOT converged (converged …`; a clean record has no note.
#[test]
fn notes_and_status_lines_on_measured_data_mistakes() {
    let dir = scratch_in(GROUP, "notes");
    let data = table2_record(&dir);
    let exp = example("table2.toml");
    let clean = run(&["fit", &exp, "--data", s(&data)]);
    assert!(clean.status.success(), "{}", stderr(&clean));
    assert!(!stdout(&clean).contains("note:"), "{}", stdout(&clean));
    let clean_json = json(&["fit", &exp, "--data", s(&data), "--json"]);
    assert!(clean_json.get("notes").is_none(), "{clean_json}");

    // The input as its sampled values held: every switch on the grid.
    let held = held_input_experiment(&dir, &data);
    let o = run(&["fit", s(&held), "--data", s(&data)]);
    let text = stdout(&o);
    assert!(
        text.contains("switches of the input inside the record lie on the sampling grid"),
        "{text}"
    );
    assert!(!text.contains("NOT converged (converged"), "{text}");
    let j = json_with(
        &["fit", s(&held), "--data", s(&data), "--json"],
        o.status.code().unwrap(),
    );
    assert!(
        j["notes"][0].as_str().unwrap().contains("sampling grid"),
        "{j}"
    );

    // An output offset of 0.05 (five times the noise): noted with its size, and the status
    // line says why the fit stopped.
    let text = std::fs::read_to_string(&data).unwrap();
    let mut shifted = vec![text.lines().next().unwrap().to_string()];
    for l in text.lines().skip(1) {
        let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
        let y: f64 = c[2].parse().unwrap();
        c[2] = format!("{}", y + 0.05);
        shifted.push(c.join(","));
    }
    let off = dir.join("off.csv");
    std::fs::write(&off, shifted.join("\n") + "\n").unwrap();
    std::fs::copy(dir.join("d.input.csv"), dir.join("off.input.csv")).unwrap();
    let o = run(&["fit", &exp, "--data", s(&off)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let text = stdout(&o);
    let status = text.lines().nth(1).unwrap();
    assert!(
        status.starts_with("stopped: converged, but the residual spectrum is not flat"),
        "{text}"
    );
    assert!(!text.contains("NOT converged"), "{text}");
    let cause = text.lines().nth(2).unwrap();
    assert!(
        cause.starts_with("likely cause: an output offset of about"),
        "{text}"
    );
    let size: f64 = cause
        .trim_start_matches("likely cause: an output offset of about ")
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((size - 0.05).abs() < 0.01, "{size}");
    let j = json_with(&["fit", &exp, "--data", s(&off), "--json"], 1);
    assert!(j["notes"][0].as_str().unwrap().contains("offset"), "{j}");
}

/// `validate` prints a table by default with the numbers of its JSON.
#[test]
fn validate_prints_a_table_with_the_json_numbers() {
    let dir = scratch_in(GROUP, "validate-table");
    let data = table2_record(&dir);
    let other = table2_run(&dir, "v.csv", "1", &[]);
    let exp = example("table2.toml");
    let args = [
        "validate",
        exp.as_str(),
        "--data",
        s(&data),
        "--validation",
        s(&other),
    ];
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let j = json(&[&args[..], &["--json"]].concat());
    let row = |name: &str| -> Vec<String> {
        let line = text
            .lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no row {name}: {text}"));
        line[name.len()..]
            .split("  ")
            .map(str::trim)
            .filter(|c| !c.is_empty())
            .map(str::to_string)
            .collect()
    };
    let header = text.lines().nth(1).unwrap();
    assert!(
        header.contains("estimation") && header.contains("validation"),
        "{text}"
    );
    for (i, record) in ["estimation", "validation"].iter().enumerate() {
        let r = &j[record];
        let percent = format!("{:.2} %", r["fit_percent"].as_f64().unwrap());
        assert_eq!(row("fit percent")[i], percent, "{text}");
        let verdict = if r["whiteness"]["passed"].as_bool().unwrap() {
            "passed"
        } else {
            "FAILED"
        };
        assert_eq!(row("whiteness")[i], verdict, "{text}");
        assert_eq!(row("samples")[i], r["samples"].to_string());
    }
    let stat = &row("  statistic")[0];
    let q = format!(
        "Q = {:.2}, χ²({})",
        j["estimation"]["whiteness"]["statistic"].as_f64().unwrap(),
        j["estimation"]["whiteness"]["dof"]
    );
    assert!(stat.starts_with(&q), "{stat} vs {q}");
}

/// `select`'s table: the screen's BCLS BIC for every candidate and the exact likelihood's for
/// the finalists, each in its own column, as in the JSON.
#[cfg(feature = "ml")]
#[test]
fn select_puts_the_two_criteria_in_two_columns() {
    let dir = scratch_in(GROUP, "select");
    let data = table2_record(&dir);
    let exp = example("table2.toml");
    // A small grid through --set: one and two poles, one zero at most, no jitter and Gaussian.
    let grid = [
        "--set",
        "select.poles=[1, 2]",
        "--set",
        "select.zeros=[0, 1]",
        "--set",
        "select.families=[\"none\", \"gaussian\"]",
    ];
    let args = [&["select", exp.as_str(), "--data", s(&data)][..], &grid[..]].concat();
    let o = run(&args);
    let text = stdout(&o);
    let j = json_with(&[&args[..], &["--json"]].concat(), o.status.code().unwrap());
    let header = text.lines().nth(1).unwrap();
    assert!(
        header.contains("screen BCLS BIC") && header.contains("final ML BIC"),
        "{text}"
    );
    assert!(!header.contains("ranked by"), "{text}");
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(2)
        .map(|l| l.split_whitespace().collect())
        .collect();
    let candidates = j["candidates"].as_array().unwrap();
    assert_eq!(rows.len(), candidates.len(), "{text}");
    let mut finalists = 0;
    for (r, c) in rows.iter().zip(candidates) {
        assert_eq!(r[2], c["family"].as_str().unwrap());
        let bcls = c["bcls_criterion"].as_f64().unwrap();
        assert_eq!(r[3], format!("{bcls:.4}"), "{text}");
        if c["ranked_by"] == "exact-ml-bic" {
            finalists += 1;
            let ml = c["criterion"].as_f64().unwrap();
            assert_eq!(r[4], format!("{ml:.4}"), "{text}");
        } else {
            assert_eq!(r[4], "–", "{text}");
        }
    }
    assert!(finalists >= 1, "{text}");
}

/// `validate --model` takes the fit of an estimated uniform sum profiled over `n_range`: the
/// checks equal those of the fit `validate` makes itself.
#[test]
fn validate_takes_a_profiled_uniform_sum_model() {
    let dir = scratch_in(GROUP, "profiled");
    let exp = example("table1-uniform-n0-a0.5.toml");
    let data = dir.join("d.csv");
    let o = run(&["simulate", &exp, "--seed", "3", "--out", s(&data)]);
    assert!(o.status.success(), "{}", stderr(&o));
    for range in ["[0, 9]", "[0, 0]"] {
        let set = format!("jitter.n_range={range}");
        let fit = run(&["fit", &exp, "--data", s(&data), "--json", "--set", &set]);
        assert!(fit.status.success(), "{}", stderr(&fit));
        let model = dir.join("fit.json");
        std::fs::write(&model, &fit.stdout).unwrap();
        let from_file = json(&[
            "validate",
            &exp,
            "--data",
            s(&data),
            "--model",
            s(&model),
            "--set",
            &set,
            "--json",
        ]);
        let fitted_here = json(&[
            "validate",
            &exp,
            "--data",
            s(&data),
            "--set",
            &set,
            "--json",
        ]);
        assert_eq!(
            from_file["fit_percent"], fitted_here["fit_percent"],
            "{range}"
        );
        assert_eq!(from_file["whiteness"], fitted_here["whiteness"], "{range}");
    }
    // A profiled order that is not a whole number is refused by name.
    let fit = run(&["fit", &exp, "--data", s(&data), "--json"]);
    let mut v: Value = serde_json::from_slice(&fit.stdout).unwrap();
    v["parameters"][0]["estimate"] = 1.5.into();
    let bad = dir.join("bad.json");
    std::fs::write(&bad, v.to_string()).unwrap();
    refused(
        &["validate", &exp, "--data", s(&data), "--model", s(&bad)],
        &["parameter jitter.n", "whole number"],
    );
}

/// Several `--data` files are fitted jointly: a record given twice gives the estimates of the
/// single fit and standard errors smaller by √2 (twice the information); records of different
/// lengths, starts and inputs fit together; what belongs to one record is refused.
#[test]
fn several_records_are_fitted_jointly() {
    let dir = scratch_in(GROUP, "joint");
    let data = table2_record(&dir);
    let exp = example("table2.toml");
    let copy = dir.join("copy.csv");
    std::fs::copy(&data, &copy).unwrap();
    std::fs::copy(dir.join("d.input.csv"), dir.join("copy.input.csv")).unwrap();
    let single = json(&["fit", &exp, "--data", s(&data), "--json"]);
    let twice = json(&[
        "fit",
        &exp,
        "--data",
        s(&data),
        "--data",
        s(&copy),
        "--json",
    ]);
    let params = |v: &Value| v["parameters"].as_array().unwrap().clone();
    for (a, b) in params(&single).iter().zip(params(&twice).iter()) {
        let (x, y) = (
            a["estimate"].as_f64().unwrap(),
            b["estimate"].as_f64().unwrap(),
        );
        assert!((x - y).abs() <= 1e-9 * x.abs(), "{a} {b}");
        let (sa, sb) = (a["stderr"].as_f64().unwrap(), b["stderr"].as_f64().unwrap());
        assert!((sa / sb - 2f64.sqrt()).abs() < 1e-6, "{a} {b}");
    }
    // A second record of 150 samples from 500 s, with its own input.
    let other = table2_run(
        &dir,
        "other.csv",
        "1",
        &["sampling.samples=150", "sampling.start=500"],
    );
    let both = ["fit", exp.as_str(), "--data", s(&data), "--data", s(&other)];
    let joint = json(&[&both[..], &["--json"]].concat());
    assert!(joint["converged"].as_bool().unwrap(), "{joint}");
    for (a, b) in params(&single).iter().zip(params(&joint).iter()) {
        assert!(
            b["stderr"].as_f64().unwrap() < a["stderr"].as_f64().unwrap(),
            "{a} {b}"
        );
    }
    // The other record's input is its own: with the first record's instead, the fit differs.
    std::fs::copy(dir.join("d.input.csv"), dir.join("other.input.csv")).unwrap();
    let status = run(&both).status.code().unwrap();
    let wrong = json_with(&[&both[..], &["--json"]].concat(), status);
    assert_ne!(wrong["parameters"], joint["parameters"]);
    let text = stdout(&run(&["fit", &exp, "--data", s(&data), "--data", s(&copy)]));
    let named = format!("fit of {} + {} with bcls", data.display(), copy.display());
    assert!(text.starts_with(&named), "{text}");
    let two = ["fit", exp.as_str(), "--data", s(&data), "--data", s(&copy)];
    refused(
        &[&two[..], &["--method", "ml"]].concat(),
        &[
            "a joint fit of 2 records with method ml",
            "first-moment method",
        ],
    );
    refused(
        &[&two[..], &["--plot", "figs"]].concat(),
        &["--plot: not with several --data"],
    );
    assert!(!Path::new("figs").exists());
}

/// The offset note's evidence on Table 2 records (noise 0.01): no note on eight records as
/// simulated, a note on each of the same records with an offset of two noise standard
/// deviations (0.02) added.
#[test]
fn the_offset_note_fires_on_an_offset_and_not_without_one() {
    let dir = scratch_in(GROUP, "offset-evidence");
    let exp = example("table2.toml");
    for r in 0..8 {
        let name = format!("d{r}.csv");
        let data = table2_run(&dir, &name, &r.to_string(), &[]);
        let clean = stdout(&run(&["fit", &exp, "--data", s(&data)]));
        assert!(!clean.contains("note:"), "run {r}: {clean}");
        let text = std::fs::read_to_string(&data).unwrap();
        let header = text.lines().next().unwrap();
        let iy = header.split(',').position(|c| c == "y").unwrap();
        let mut shifted = vec![header.to_string()];
        for l in text.lines().skip(1) {
            let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
            let y: f64 = c[iy].parse().unwrap();
            c[iy] = format!("{}", y + 0.02);
            shifted.push(c.join(","));
        }
        let off = dir.join(format!("o{r}.csv"));
        std::fs::write(&off, shifted.join("\n") + "\n").unwrap();
        std::fs::copy(
            dir.join(format!("d{r}.input.csv")),
            dir.join(format!("o{r}.input.csv")),
        )
        .unwrap();
        let noted = stdout(&run(&["fit", &exp, "--data", s(&off)]));
        assert!(
            noted.contains("note: the output probably has an offset"),
            "run {r}: {noted}"
        );
    }
}
