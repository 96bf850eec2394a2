//! Experiments read with edits (the library side of the command line's `--set` and of
//! `[sampling]` from the data file): the edited document is validated as a file, an edit's
//! error names it, and a `t` column off a uniform grid is a typed error naming its line.

use jitterid::jitter::JitterModel;
use jitterid_study::experiment::{self, Override, Purpose, ReadOptions};
use jitterid_study::{Registries, StudyErrorKind};
use std::path::{Path, PathBuf};

const TEXT: &str = r#"[input]
kind = "piecewise"
times = [0.0, 4.0, 9.5]
values = [1.0, -1.0, 0.5]

[system]
kind = "zpk"
gain = 1.0
poles = [-1.0]

[jitter]
family = "uniform-sum"
n = 1
a = 0.2
"#;

fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("jitterid-study-edits")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn parse(options: &ReadOptions) -> Result<experiment::Experiment, jitterid_study::StudyError> {
    experiment::parse_edited(
        &Registries::builtin(),
        "e.toml",
        TEXT,
        Path::new("."),
        Purpose::Simulate,
        options,
    )
}

fn sets(args: &[&str]) -> Vec<Override> {
    args.iter().map(|a| Override::parse(a).unwrap()).collect()
}

#[test]
fn edits_build_the_edited_experiment_and_name_themselves_in_errors() {
    let dir = scratch("sampling");
    let data = dir.join("d.csv");
    // 30 samples from 2.5 s every 0.25 s.
    let rows: Vec<String> = (0..30)
        .map(|k| format!("{},{}", 2.5 + 0.25 * k as f64, (k as f64).sin()))
        .collect();
    std::fs::write(&data, format!("t,y\n{}\n", rows.join("\n"))).unwrap();
    let options = ReadOptions {
        overrides: sets(&["jitter.family=gaussian", "jitter.sigma=0.05"]),
        data: Some(data.clone()),
        ..ReadOptions::default()
    };
    let exp = parse(&options).unwrap();
    assert_eq!(exp.jitter.truth.family(), "gaussian");
    assert_eq!(exp.jitter.truth.std_dev(), 0.05);
    assert_eq!(
        (exp.grid.len(), exp.grid.start(), exp.grid.interval()),
        (30, 2.5, 0.25)
    );
    // A bad edited value: the edit is named instead of a line.
    let bad = ReadOptions {
        overrides: sets(&["system.gain=0"]),
        data: Some(data.clone()),
        ..ReadOptions::default()
    };
    let e = parse(&bad).unwrap_err().to_string();
    assert!(
        e.starts_with("e.toml (--set system.gain=0): [system] gain"),
        "{e}"
    );
    // Row 7 of the data (line 8) taken 0.1 s late: a typed error naming the line.
    let mut late = rows.clone();
    late[6] = format!("{},{}", 2.5 + 0.25 * 6.0 + 0.1, 0.0);
    std::fs::write(&data, format!("t,y\n{}\n", late.join("\n"))).unwrap();
    let e = parse(&options).unwrap_err();
    assert_eq!(e.kind(), StudyErrorKind::NotUniformGrid);
    assert!(e.message().contains("d.csv:8: column `t`: 4.1"), "{e}");
    // Without edits and data the file reads as before: its [sampling] is required.
    let e = parse(&ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("missing section [sampling]"), "{e}");
}
