//! Files only where the user meant: a path written in an experiment file (`[input] path`) is
//! resolved against the experiment file's directory and refused if it leaves it (an absolute
//! path, `..`, a symbolic link leading out) unless the caller allows it ([`Paths::Anywhere`]);
//! a refused file is not read, and a CSV error quotes only a short, printable excerpt.

use jitterid_study::csvio;
use jitterid_study::experiment::{self, Paths, Purpose};
use jitterid_study::{StudyError, StudyErrorKind};
use std::path::{Path, PathBuf};

/// Content that must never appear in a message: the refused file's first line.
const SECRET: &str = "root:$6$saltsalt$hashhashhashhashhashhash:19000:0:99999:7:::";

/// A fresh directory for one test, holding `exp/` (the experiment's directory, with a good
/// input `exp/u.csv`) and, beside it, `outside/secret.csv` (a file the experiment must not
/// reach).
fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("jitterid-study-paths")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("exp/data")).unwrap();
    std::fs::create_dir_all(d.join("outside")).unwrap();
    let good = "t,u\n0.0,0.0\n3.0,1.0\n17.5,0.0\n30.0,1.0\n50.0,0.0\n";
    std::fs::write(d.join("exp/u.csv"), good).unwrap();
    std::fs::write(d.join("exp/data/u.csv"), good).unwrap();
    std::fs::write(d.join("outside/u.csv"), good).unwrap();
    std::fs::write(
        d.join("outside/secret.csv"),
        format!("{SECRET}\ndaemon:*:19000:0:99999:7:::\n"),
    )
    .unwrap();
    d
}

/// An experiment whose input is the CSV file `path` (as written in the file: line 6).
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
[jitter]
family = "gaussian"
sigma = 0.1
"#
    )
}

/// Writes the experiment `exp/e.toml` naming `path` and reads it under `paths`.
fn read(dir: &Path, path: &str, paths: Paths) -> Result<experiment::Experiment, StudyError> {
    let file = dir.join("exp/e.toml");
    std::fs::write(&file, experiment_text(path)).unwrap();
    experiment::read_with(&file, Purpose::Simulate, paths)
}

/// Asserts that `e` is the rule's refusal: one line, of kind `PathOutside`, naming the file,
/// the line and the key, quoting nothing of the refused file.
fn assert_refused(e: &StudyError, why: &str) {
    let m = e.message();
    assert_eq!(e.kind(), StudyErrorKind::PathOutside, "{m}");
    assert!(!m.contains('\n'), "{m}");
    assert!(m.contains("e.toml:6: [input] path:"), "{m}");
    assert!(m.contains(why), "{m}");
    assert!(m.contains("--allow-paths-outside"), "{m}");
    assert!(!m.contains("root:") && !m.contains("daemon"), "{m}");
}

#[test]
fn an_absolute_path_is_refused() {
    let d = scratch("absolute");
    let secret = d.join("outside/secret.csv");
    let e = read(&d, secret.to_str().unwrap(), Paths::Inside).unwrap_err();
    assert_refused(&e, "an absolute path");
    // Even one that points back inside the directory: the rule is about what is written.
    let inside = d.join("exp/u.csv");
    let e = read(&d, inside.to_str().unwrap(), Paths::Inside).unwrap_err();
    assert_refused(&e, "an absolute path");
    // The probe's file: refused before it is opened (whether or not it exists or is readable).
    let e = read(&d, "/etc/shadow", Paths::Inside).unwrap_err();
    assert_refused(&e, "an absolute path");
}

#[test]
fn a_parent_component_is_refused() {
    let d = scratch("parent");
    let e = read(&d, "../outside/secret.csv", Paths::Inside).unwrap_err();
    assert_refused(&e, "`..`");
    // Also when it comes back inside: `data/../u.csv`.
    let e = read(&d, "data/../u.csv", Paths::Inside).unwrap_err();
    assert_refused(&e, "`..`");
}

#[cfg(unix)]
#[test]
fn a_symbolic_link_leading_out_is_refused() {
    let d = scratch("link");
    std::os::unix::fs::symlink(d.join("outside/secret.csv"), d.join("exp/link.csv")).unwrap();
    let e = read(&d, "link.csv", Paths::Inside).unwrap_err();
    assert_refused(&e, "symbolic link");
    // A linked directory leading out is refused as well.
    std::os::unix::fs::symlink(d.join("outside"), d.join("exp/elsewhere")).unwrap();
    let e = read(&d, "elsewhere/u.csv", Paths::Inside).unwrap_err();
    assert_refused(&e, "symbolic link");
    // A link that stays inside is fine.
    std::os::unix::fs::symlink(d.join("exp/data/u.csv"), d.join("exp/same.csv")).unwrap();
    read(&d, "same.csv", Paths::Inside).unwrap();
}

#[test]
fn a_path_inside_the_directory_is_read() {
    let d = scratch("inside");
    for p in ["u.csv", "./u.csv", "data/u.csv", "data/./u.csv"] {
        let exp = read(&d, p, Paths::Inside).unwrap_or_else(|e| panic!("{p}: {e}"));
        assert!(matches!(
            exp.inputs[0].spec,
            experiment::InputSpec::Known(jitterid::signal::Input::Piecewise(_))
        ));
    }
    // A file that is not there is reported as missing (nothing to refuse, nothing read).
    let e = read(&d, "missing.csv", Paths::Inside).unwrap_err();
    assert_eq!(e.kind(), StudyErrorKind::Invalid);
    assert!(e.message().contains("file does not exist"), "{e}");
}

#[test]
fn the_caller_can_allow_paths_outside() {
    let d = scratch("allowed");
    let outside = d.join("outside/u.csv");
    read(&d, outside.to_str().unwrap(), Paths::Anywhere).unwrap();
    read(&d, "../outside/u.csv", Paths::Anywhere).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&outside, d.join("exp/link.csv")).unwrap();
        read(&d, "link.csv", Paths::Anywhere).unwrap();
    }
    // Allowed and read, a file that is not a CSV is still quoted by a short excerpt only.
    let e = read(&d, "../outside/secret.csv", Paths::Anywhere).unwrap_err();
    let m = e.message();
    assert!(m.contains("secret.csv:2:1"), "{m}");
    assert!(!m.contains("hashhash"), "{m}");
}

#[test]
fn text_without_a_file_resolves_against_the_directory_it_is_given() {
    let d = scratch("text");
    let dir = d.join("exp");
    let parse = |path: &str, paths: Paths| {
        experiment::parse_with(
            &jitterid_study::Registries::builtin(),
            "<string>",
            &experiment_text(path),
            &dir,
            Purpose::Simulate,
            paths,
        )
    };
    parse("u.csv", Paths::Inside).unwrap();
    let e = parse("../outside/u.csv", Paths::Inside).unwrap_err();
    assert_eq!(e.kind(), StudyErrorKind::PathOutside, "{e}");
    assert!(e.message().starts_with("<string>:6: [input] path:"), "{e}");
    parse("../outside/u.csv", Paths::Anywhere).unwrap();
    // `parse` (no rule given) keeps the rule.
    let e = experiment::parse(
        "<string>",
        &experiment_text("/etc/passwd"),
        &dir,
        Purpose::Simulate,
    )
    .unwrap_err();
    assert_eq!(e.kind(), StudyErrorKind::PathOutside, "{e}");
}

#[test]
fn a_csv_error_quotes_a_short_printable_excerpt() {
    let long = format!("{SECRET}\u{1b}[31m\u{7}tail");
    // A header with one long name and a data row that is not a number.
    let text = format!("{long}\n{long}\n");
    let m = csvio::parse("d.csv", &text).unwrap_err().to_string();
    assert!(!m.contains('\u{1b}') && !m.contains('\u{7}'), "{m:?}");
    assert!(!m.contains("hashhash"), "{m}");
    // Every quoted excerpt is at most MAX_EXCERPT_CHARS characters of the file (before
    // escaping) and marked as cut.
    for quoted in m.split('`').skip(1).step_by(2) {
        let chars = quoted.trim_end_matches('…').chars().count();
        assert!(chars <= csvio::MAX_EXCERPT_CHARS, "{quoted:?} in {m}");
    }
    assert!(m.contains('…'), "{m}");
    // Control characters within the excerpt are escaped, not written.
    let m = csvio::parse("d.csv", "a\u{1b}b,c\n1\u{7},2\n")
        .unwrap_err()
        .to_string();
    assert!(m.contains("\\u{1b}") && m.contains("\\u{7}"), "{m}");
    assert!(!m.contains('\u{1b}') && !m.contains('\u{7}'), "{m:?}");
    assert_eq!(csvio::excerpt("short"), "short");
    assert_eq!(
        csvio::excerpt(&"x".repeat(100)),
        format!("{}…", "x".repeat(20))
    );
}

#[test]
fn an_experiment_file_is_read_only_if_regular() {
    #[cfg(unix)]
    {
        let e = experiment::read_text(Path::new("/dev/zero")).unwrap_err();
        assert!(e.message().contains("not a regular file"), "{e}");
    }
    let d = scratch("regular");
    let e = experiment::read_text(&d).unwrap_err();
    assert!(e.message().contains("not a regular file"), "{e}");
}
