//! Files only where the user meant, through the real binary: a path in an experiment file that
//! leaves the file's directory is refused (exit 2, one line naming the file, the line and the
//! key, nothing of the file quoted) by every subcommand that reads experiment files, unless
//! `--allow-paths-outside` is given.

mod common;

use common::{jitterid, s, scratch_in, stderr};
use std::path::Path;
use std::process::Output;

/// An experiment whose input is the CSV file `path` (on line 6), with the system estimated.
fn experiment_text(path: &str) -> String {
    format!(
        r#"[sampling]
interval = 1.0
samples = 60
[input]
kind = "csv"
path = {path:?}
[system]
kind = "zpk"
gain = 0.5
poles = [-0.5]
estimate = true
[jitter]
family = "gaussian"
sigma = 0.05
[noise]
std = 0.005
[select]
poles = [1, 1]
zeros = [0, 0]
families = ["gaussian"]
"#
    )
}

const INPUT: &str = "t,u\n0.0,0.0\n3.0,1.0\n17.5,0.0\n30.0,1.0\n50.0,0.0\n";

fn run(dir: &Path, args: &[&str]) -> Output {
    jitterid().current_dir(dir).args(args).output().unwrap()
}

/// Asserts exit 2 with the rule's one-line error about `e.toml` line 6.
fn assert_refused(o: &Output, what: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{what}: {err}");
    assert!(err.contains("e.toml:6: [input] path:"), "{what}: {err}");
    assert!(err.contains("--allow-paths-outside"), "{what}: {err}");
    assert!(!err.contains("root:"), "{what}: {err}");
}

#[test]
fn fit_refuses_etc_passwd_with_the_rules_error() {
    let d = scratch_in("jitterid-paths", "passwd");
    let exp = d.join("e.toml");
    std::fs::write(&exp, experiment_text("/etc/passwd")).unwrap();
    let o = run(&d, &["fit", s(&exp), "--data", "d.csv"]);
    assert_refused(&o, "fit");
    assert!(stderr(&o).contains("an absolute path"), "{}", stderr(&o));
    // Every subcommand that reads an experiment file applies the rule.
    for args in [
        &["simulate", s(&exp), "--out", "d.csv"][..],
        &["montecarlo", s(&exp), "--runs", "1"],
        &["select", s(&exp), "--data", "d.csv"],
        &["validate", s(&exp), "--data", "d.csv"],
    ] {
        assert_refused(&run(&d, args), args[0]);
    }
    assert!(!d.join("d.csv").exists());
    // A `..` path is refused in the same way.
    std::fs::write(&exp, experiment_text("../passwd/e.toml")).unwrap();
    let o = run(&d, &["fit", s(&exp), "--data", "d.csv"]);
    assert_refused(&o, "fit ..");
    assert!(stderr(&o).contains("`..`"), "{}", stderr(&o));
}

#[test]
fn the_flag_lets_a_path_outside_through() {
    let d = scratch_in("jitterid-paths", "allowed");
    let outside = d.join("inputs");
    let here = d.join("exp");
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::create_dir_all(&here).unwrap();
    let input = outside.join("u.csv");
    std::fs::write(&input, INPUT).unwrap();
    let exp = here.join("e.toml");
    std::fs::write(&exp, experiment_text(s(&input))).unwrap();
    let data = here.join("d.csv");

    let o = run(&d, &["simulate", s(&exp), "--out", s(&data)]);
    assert_refused(&o, "simulate");
    let flag = "--allow-paths-outside";
    let o = run(&d, &["simulate", s(&exp), "--out", s(&data), flag]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let o = run(&d, &["fit", s(&exp), "--data", s(&data)]);
    assert_refused(&o, "fit");
    let o = run(&d, &["fit", s(&exp), "--data", s(&data), flag, "--json"]);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "fit with {flag}: {}",
        stderr(&o)
    );
    // The other subcommands take the flag too (and get past the experiment file with it).
    for args in [
        &["montecarlo", s(&exp), "--runs", "1", "--json", flag][..],
        &["select", s(&exp), "--data", s(&data), "--json", flag],
        &["validate", s(&exp), "--data", s(&data), flag],
    ] {
        let o = run(&d, args);
        assert!(
            matches!(o.status.code(), Some(0 | 1)),
            "{}: {}",
            args[0],
            stderr(&o)
        );
    }
    // The same file by a relative path inside the experiment's directory needs no flag.
    std::fs::write(here.join("u.csv"), INPUT).unwrap();
    std::fs::write(&exp, experiment_text("u.csv")).unwrap();
    let o = run(&d, &["fit", s(&exp), "--data", s(&data), "--json"]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
}
