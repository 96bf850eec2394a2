//! The documented limits and the time budget from the command line: a size beyond a limit is
//! refused when the experiment is read (exit 2, one line naming the key and the limit), and a
//! spent `--time-limit` ends a fit or a selection as a reported outcome, not as a hang.

mod common;

use common::{example, example_with, s, scratch_in, simulate_text, stderr, stdout};

const GROUP: &str = "jitterid-limits";

/// Runs `simulate` on `text`; asserts exit 2 and a one-line error holding every `expect`.
fn refused(name: &str, text: &str, expect: &[&str]) {
    let (o, out) = simulate_text(GROUP, name, text);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert!(!out.exists(), "{name}: a refused experiment wrote its data");
    assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
    for e in expect {
        assert!(err.contains(e), "{name}: expected {e:?} in: {err}");
    }
}

/// Table 2 with its poles replaced by `n` repeated real poles at `p`.
fn repeated_poles(n: usize, p: f64) -> String {
    let poles = vec![format!("{p}"); n].join(", ");
    example_with("table2.toml", "poles", &format!("poles = [{poles}]"))
        .replace("zeros = [-0.5]", "zeros = []")
}

#[test]
fn more_poles_than_the_limit_are_refused_at_the_key() {
    refused(
        "poles",
        &repeated_poles(31, -0.3),
        &["[system]", "31 poles exceed the limit of 30 poles"],
    );
}

#[test]
fn a_sum_with_three_terms_with_a_density_is_refused() {
    let text = example_with(
        "table2.toml",
        "family = \"uniform-sum\"",
        "family = \"sum\"\nterms = [{family = \"gaussian\", sigma = 0.1}, {family = \"uniform-sum\", n = 0, a = 0.2}, {family = \"laplace\", scale = 0.1}]",
    )
    .replace("n = 2\n", "")
    .replace("a = 0.28867513459481287  # 1/(2√3) s\n", "");
    refused(
        "density-terms",
        &text,
        &[
            "[jitter] terms",
            "3 terms with a density exceed the limit of 2",
        ],
    );
}

#[test]
fn a_sum_of_more_terms_than_the_limit_is_refused() {
    let terms = ["{family = \"two-point\", d = 0.01}"; 9].join(", ");
    let text = example_with(
        "table2.toml",
        "family = \"uniform-sum\"",
        &format!("family = \"sum\"\nterms = [{terms}]"),
    )
    .replace("n = 2\n", "")
    .replace("a = 0.28867513459481287  # 1/(2√3) s\n", "");
    refused(
        "sum-terms",
        &text,
        &[
            "[jitter] terms",
            "9 terms exceed the limit of 8 terms of a sum",
        ],
    );
}

#[test]
fn a_multisine_of_more_tones_than_the_limit_is_refused() {
    let f: Vec<String> = (1..=1001).map(|k| format!("{}", 1e-4 * k as f64)).collect();
    let text = example_with(
        "table2.toml",
        "kind = \"random-binary\"",
        "kind = \"multisine\"",
    )
    .replace(
        "mean_dwell = 8.0",
        &format!("frequencies = [{}]", f.join(", ")),
    )
    .replace("low = 0.0\n", "")
    .replace("high = 1.0\n", "");
    refused(
        "tones",
        &text,
        &["[input]", "1001 tones exceed the limit of 1000 tones"],
    );
}

/// Twenty repeated poles: each evaluation of the first moment goes through the confluent
/// realisation (a matrix exponential per sample), so the search from a start away from the
/// truth takes tens of seconds; a limit of one second stops it between iterations (or, on a
/// slow machine, before the first: the outcome is the same stopped fit). The reason is
/// asserted, never a duration.
#[test]
fn a_spent_time_limit_ends_the_search_as_not_converged_without_standard_errors() {
    let (o, data) = simulate_text(GROUP, "mid-search", &repeated_poles(20, -0.3));
    assert!(o.status.success(), "simulate: {}", stderr(&o));
    let start = data.with_file_name("start.toml");
    std::fs::write(&start, repeated_poles(20, -0.4)).unwrap();
    let o = common::run(&[
        "fit",
        s(&start),
        "--data",
        s(&data),
        "--time-limit",
        "1",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(json["converged"], false, "{json}");
    assert_eq!(json["termination"], "wall-clock budget spent", "{json}");
    let params = json["parameters"].as_array().unwrap();
    assert!(
        params.iter().all(|p| p["stderr"].is_null()),
        "a stopped fit reports no standard errors: {json}"
    );
}

#[test]
fn a_selection_that_spends_its_time_limit_says_so() {
    let d = scratch_in(GROUP, "select-budget");
    let exp = d.join("e.toml");
    std::fs::write(
        &exp,
        std::fs::read_to_string(example("select.toml")).unwrap(),
    )
    .unwrap();
    let data = d.join("d.csv");
    let o = common::run(&["simulate", s(&exp), "--out", s(&data)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = common::run(&["select", s(&exp), "--data", s(&data), "--time-limit", "0"]);
    let err = stderr(&o);
    assert_ne!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("candidates was stopped: the time limit of 0 s was spent"),
        "{err}"
    );
}
