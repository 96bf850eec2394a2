//! Validation at the door: values that cannot give finite samples, and type mistakes, are
//! refused by the real binary when the experiment is read, with the file, the line and the key
//! named, and exit status 2; nothing is written.

mod common;

use common::{example_with, simulate_text};
use std::path::PathBuf;
use std::process::Output;

/// The paper's Table 2 experiment with one line replaced.
fn table2_with(from: &str, to: &str) -> String {
    example_with("table2.toml", from, to)
}

/// Runs `simulate` on the experiment `text`, written to a fresh directory `name`; returns the
/// process output and the data file it was asked to write.
fn simulate(name: &str, text: &str) -> (Output, PathBuf) {
    simulate_text("jitterid-door", name, text)
}

/// Runs `simulate` on `text`; asserts exit status 2, no output file, and a one-line error
/// that holds every one of `expect`. Returns the error line.
fn refused(name: &str, text: &str, expect: &[&str]) -> String {
    let (o, out) = simulate(name, text);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{name}: expected exit 2, got {:?}: {err}",
        o.status
    );
    assert!(
        !out.exists(),
        "{name}: a refused experiment wrote {}",
        out.display()
    );
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{name}: not one line: {err}"
    );
    for e in expect {
        assert!(err.contains(e), "{name}: expected {e:?} in: {err}");
    }
    err
}

/// One regression test per case: `$name` replaces the line of Table 2 starting with `$from`
/// by `$to`, and the error must hold every one of `$expect`.
macro_rules! refused_at_the_door {
    ($($name:ident: $from:literal => $to:literal, [$($expect:literal),*];)*) => {
        $(
            #[test]
            fn $name() {
                refused(stringify!($name), &table2_with($from, $to), &[$($expect),*]);
            }
        )*
    };
}

refused_at_the_door! {
    a_huge_pole_is_refused_at_its_key: "poles" => "poles = [-1e300]", ["e.toml:26:", "[system] poles", "magnitude"];
    a_tiny_pole_is_refused_at_its_key: "poles" => "poles = [-1e-300]", ["e.toml:26:", "[system] poles", "magnitude"];
    a_subnormal_interval_is_refused: "interval" => "interval = 1e-320", ["e.toml:12:", "[sampling] interval", "1e-15"];
    a_subnormal_jitter_width_is_refused_at_its_key: "a = " => "a = 1e-320", ["e.toml:32:", "[jitter] a", "time scale"];
    a_zero_gain_is_refused: "gain" => "gain = 0", ["e.toml:24:", "[system] gain", "nonzero"];
    a_huge_zero_is_refused_at_its_key: "zeros" => "zeros = [-1e300]", ["e.toml:25:", "[system] zeros"];
    a_huge_level_is_refused_at_its_key: "high" => "high = 1e200", ["e.toml:20:", "[input] high"];
    an_array_of_tables_for_a_section_names_it: "[sampling]" => "[[sampling]]", ["e.toml:11:", "[[sampling]]", "expected one table [sampling]"];
    a_date_for_the_interval_names_the_key: "interval" => "interval = 1979-05-27T07:32:00Z", ["e.toml:12:", "[sampling] interval", "found the date 1979-05-27T07:32:00Z"];
    a_local_date_for_the_interval_names_the_key: "interval" => "interval = 1979-05-27", ["e.toml:12:", "[sampling] interval", "date"];
    a_table_where_a_number_is_expected_says_table: "gain" => "gain = { a = 1 }", ["e.toml:24:", "[system] gain", "invalid type: table"];
}

#[test]
fn a_transfer_function_with_an_integrator_like_pole_is_refused_at_den() {
    let text = table2_with(
        "kind = \"zpk\"",
        "kind = \"tf\"\nnum = [1.0]\nden = [1.0, 1e-300]",
    )
    .replace("gain = 0.2\n", "")
    .lines()
    .filter(|l| !l.starts_with("zeros") && !l.starts_with("poles"))
    .collect::<Vec<_>>()
    .join("\n");
    refused("tf", &text, &["[system] den", "pole 1"]);
}

#[test]
fn cr_only_line_endings_are_named() {
    let text = table2_with("title", "title = \"t\"").replace('\n', "\r");
    refused("cr-only", &text, &["e.toml:", "CR only"]);
}

#[test]
fn crlf_line_endings_are_read() {
    let (o, _) = simulate(
        "crlf",
        &table2_with("title", "title = \"t\"").replace('\n', "\r\n"),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn values_inside_the_range_still_simulate_finite_samples() {
    // The edges of the documented range: the slowest and fastest poles, the smallest gain.
    for (i, (from, to)) in [
        ("poles", "poles = [-5.1e-9]"), // |p|·NT = 1.02e-6 with N = 200, T = 1
        ("poles", "poles = [-9.9e5]"),  // |p|·T just under 1e6
        ("gain", "gain = 1e-50"),
        ("a = ", "a = 1.1e-9"),
    ]
    .iter()
    .enumerate()
    {
        let (o, out) = simulate(&format!("edge{i}"), &table2_with(from, to));
        assert!(
            o.status.success(),
            "{to}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let csv = std::fs::read_to_string(&out).unwrap();
        for row in csv.lines().skip(1) {
            for cell in row.split(',') {
                let x: f64 = cell.parse().unwrap();
                assert!(x.is_finite(), "{to}: cell {cell} in row {row}");
            }
        }
    }
}

/// The dual-Dirac example with one line replaced.
fn dual_dirac_with(from: &str, to: &str) -> String {
    example_with("dual-dirac.toml", from, to)
}

#[test]
fn a_bad_key_of_a_sum_term_is_named_at_its_line() {
    let text = dual_dirac_with("d = 0.3", "d = -0.3");
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with("d = -0.3"))
        .unwrap();
    refused(
        "term-key",
        &text,
        &[&format!("e.toml:{line}:"), "[jitter] terms.1.d"],
    );
}

#[test]
fn a_term_time_scale_outside_the_range_is_named_at_its_line() {
    let text = dual_dirac_with("sigma = 0.1", "sigma = 1e-300");
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with("sigma = 1e-300"))
        .unwrap();
    refused(
        "term-range",
        &text,
        &[
            &format!("e.toml:{line}:"),
            "[jitter] terms.0.sigma",
            "time scale",
        ],
    );
}

#[test]
fn an_unknown_system_kind_lists_the_registry_kinds_a_file_can_describe() {
    refused(
        "unknown-kind",
        &table2_with("kind = \"zpk\"", "kind = \"zpq\""),
        &[
            "e.toml:23:",
            "[system] kind",
            "unknown system kind \"zpq\"",
            "expected \"zpk\", \"tf\", \"sinusoid\" or \"grey-box\"",
        ],
    );
}

#[test]
fn a_registry_kind_whose_keys_a_file_cannot_hold_is_refused_with_those_keys() {
    // `pulse-response` is a signal registry kind; [system] has no keys for its coefficients
    // and pulse spacing, so the door names them (from the registry) instead of failing later.
    refused(
        "pulse-response",
        &table2_with("kind = \"zpk\"", "kind = \"pulse-response\""),
        &[
            "e.toml:23:",
            "[system] kind",
            "\"pulse-response\"",
            "takes coefficients, interval",
        ],
    );
}
