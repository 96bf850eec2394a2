//! `jitterid design` with the random binary input's levels free (`[design] low`, `high`)
//! through the real binary: the levels in the table and the JSON beside the file's own, the
//! written input at the designed levels (which `simulate` and `fit` take), and bad level
//! ranges refused with exit status 2 naming the key.

mod common;

use common::{example, run, s, scratch, stderr, stdout};

/// `jitterid design` of Table 2 (`N = 100` by a budget) with both levels free and a cheap
/// search (2 draws, 3 grid points), then `extra`.
fn levels_table2(extra: &[&str]) -> std::process::Output {
    let table2 = example("table2.toml");
    let mut args = vec![
        "design",
        table2.as_str(),
        "--set",
        "design.low=[-1.0, 0.0]",
        "--set",
        "design.high=[0.5, 1.5]",
        "--set",
        "design.draws=2",
        "--set",
        "design.grid=3",
        "--budget",
        "samples=100",
    ];
    args.extend_from_slice(extra);
    run(&args)
}

/// The designed levels are reported in the JSON and the table beside the file's own (0 and
/// 1), and the written input takes them: its values are the designed levels, and the written
/// experiment simulates and fits.
#[test]
fn designed_levels_are_reported_and_written() {
    let d = scratch("design-levels");
    let csv = d.join("designed.csv");
    let o = levels_table2(&["--write-input", s(&csv), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let (low, high) = (
        v["design"]["low"].as_f64().unwrap(),
        v["design"]["high"].as_f64().unwrap(),
    );
    assert!(
        (-1.0..=0.0).contains(&low) && (0.5..=1.5).contains(&high),
        "{v}"
    );
    assert_eq!(v["baseline"]["design"]["low"], 0.0);
    assert_eq!(v["baseline"]["design"]["high"], 1.0);
    let input = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = input.lines().collect();
    assert_eq!(rows[0], "t,u");
    // Every row but the last (level 0, ending the input) is at a designed level, both seen.
    let values: Vec<f64> = rows[1..rows.len() - 1]
        .iter()
        .map(|r| r.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert!(values.iter().all(|&u| u == low || u == high), "{values:?}");
    assert!(
        values.contains(&low) && values.contains(&high),
        "{values:?}"
    );
    let exp = d.join("designed.toml");
    let text = std::fs::read_to_string(&exp).unwrap();
    assert!(
        text.contains("between the designed levels") && text.contains("kind = \"csv\""),
        "{text}"
    );
    let data = d.join("d.csv");
    let o = run(&["simulate", s(&exp), "--seed", "3", "--out", s(&data)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = run(&["fit", s(&exp), "--data", s(&data), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // The table names the levels of both designs.
    let o = levels_table2(&[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains(&format!(
            "designed: mean_dwell = 8.000000 s, low = {low:.6}, high = {high:.6},"
        )) && text.contains("baseline: mean_dwell = 8.000000 s, low = 0.000000, high = 1.000000,"),
        "{text}"
    );
}

/// Bad level ranges exit 2 with one line naming the key; levels that can only be equal
/// (never switching) leave no feasible design, naming both keys.
#[test]
fn bad_level_ranges_exit_2_naming_the_key() {
    let cases: [(&[&str], &str); 4] = [
        (
            &["--set", "design.low=[1.0, -1.0]"],
            "[design] low: expected [min, max] of two finite levels with min <= max",
        ),
        (
            &["--set", "design.high=[0.0, 1e60]"],
            "[design] high: max: expected a magnitude of at most 1e50",
        ),
        (
            &["--set", "design.high=[0.0]"],
            "[design] high: expected [min, max]",
        ),
        (
            &[
                "--set",
                "design.low=[0.5, 0.5]",
                "--set",
                "design.high=[0.5, 0.5]",
                "--set",
                "design.draws=1",
                "--set",
                "design.grid=3",
            ],
            "[design] low, high: no feasible design in the given range",
        ),
    ];
    for (args, want) in cases {
        common::design_refused(args, want);
    }
}
