//! The input's level `[input] level` through the binary: a record simulated around an input
//! level (a tank draining at an unknown rate) is fitted and the level recovered within its
//! standard error beside the output offset; a known level gives the fit of the same record
//! with its input written as the deviation `u − u₀`; `select` and `fit --init auto` carry it;
//! the confounded and the meaningless cases exit 2 naming the key.

mod common;

use common::{example, example_with, param, run, s, scratch_in, simulate_text, stderr, stdout};
use serde_json::Value;

/// Simulates run `run_no` of `exp` into `dir` (`d.csv`, and the input's side file
/// `d.input.csv`) and fits it; the fit's JSON.
fn simulate_and_fit(dir: &std::path::Path, exp: &str, run_no: &str, extra: &[&str]) -> Value {
    common::simulate_and_fit_in(dir, exp, run_no, extra)
}

#[test]
fn a_simulated_level_is_recovered_beside_the_offset() {
    let dir = scratch_in("jitterid-level", "recovered");
    let exp = example("input-level.toml");
    let fit = simulate_and_fit(&dir, &exp, "2", &[]);
    assert_eq!(fit["converged"], true, "{fit}");
    // 4 standard errors: a chance of about 6e-5 per parameter for an unbiased estimate whose
    // standard error is the spread's (docs/reproduction.md, the models case input-level).
    for (name, truth) in [("b0", 1.0), ("a1", 1.0), ("level", 0.5), ("offset", 1.5)] {
        let (est, se) = param(&fit, name);
        assert!(se > 0.0, "{name}: se {se}");
        assert!(
            (est - truth).abs() < 4.0 * se,
            "{name}: {est} ± {se}, truth {truth}"
        );
    }
    let (level, _) = param(&fit, "level");
    assert_eq!(
        fit["model"]["level"].as_f64(),
        Some(level),
        "{}",
        fit["model"]
    );
    let o = run(&["fit", &exp, "--data", s(&dir.join("d.csv"))]);
    assert!(
        stdout(&o).contains("y = y0 + G(s)(u - u0)"),
        "{}",
        stdout(&o)
    );
}

/// The same record fitted twice: with the level known, and with no level and the input's side
/// file rewritten as the deviation `u − u₀` (each level moved, the final row that ends the
/// input kept at 0, since the deviation is 0 outside the input's span). Both are the response
/// to the same input, so the fits agree to rounding.
#[test]
fn a_known_level_is_the_fit_on_the_deviation() {
    let dir = scratch_in("jitterid-level", "deviation");
    let known = dir.join("known.toml");
    let text = std::fs::read_to_string(example("input-level.toml"))
        .unwrap()
        .replace("estimate_level = true", "estimate_level = false");
    std::fs::write(&known, &text).unwrap();
    let fit = simulate_and_fit(&dir, s(&known), "3", &[]);
    let side = std::fs::read_to_string(dir.join("d.input.csv")).unwrap();
    let rows: Vec<&str> = side.lines().skip(1).collect();
    let mut shifted = String::from("t,u\n");
    for (i, row) in rows.iter().enumerate() {
        let (t, u) = row.split_once(',').unwrap();
        let u: f64 = u.parse().unwrap();
        let v = if i + 1 == rows.len() { u } else { u - 0.5 };
        shifted.push_str(&format!("{t},{v:?}\n"));
    }
    std::fs::write(dir.join("deviation.csv"), shifted).unwrap();
    let plain = dir.join("plain.toml");
    let text = text
        .replace(
            "kind = \"random-binary\"\nmean_dwell = 3.0\nlow = 0.0\nhigh = 1.0\n",
            "kind = \"csv\"\npath = \"deviation.csv\"\n",
        )
        .replace("level = 0.5", "")
        .replace("estimate_level = false", "");
    std::fs::write(&plain, text).unwrap();
    let o = run(&["fit", s(&plain), "--data", s(&dir.join("d.csv")), "--json"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let other: Value = serde_json::from_str(&stdout(&o)).unwrap();
    for name in ["b0", "a1", "offset"] {
        let ((a, se), (b, _)) = (param(&fit, name), param(&other, name));
        assert!((a - b).abs() < 1e-9 * se.max(1.0), "{name}: {a} vs {b}");
    }
}

/// `select` carries an estimated level into every candidate (a stable plant, no offset):
/// the true order wins and the level is recovered.
#[test]
fn select_carries_the_level_into_every_candidate() {
    let dir = scratch_in("jitterid-level", "select");
    let text = std::fs::read_to_string(example("offset.toml"))
        .unwrap()
        .replace("[output]", "[unused]")
        .replace("estimate_offset = true", "")
        .replace("offset = 1.5", "")
        .replace("[unused]", "");
    let text = text.replacen(
        "[input]\n",
        "[input]\nlevel = 0.3\nestimate_level = true\n",
        1,
    );
    let sel = common::select_poles_1_to_2(&dir, &text, "4");
    let best = &sel["best"];
    assert_eq!(
        (best["poles"].as_u64(), best["zeros"].as_u64()),
        (Some(2), Some(1)),
        "{best}"
    );
    let fit = simulate_and_fit(&dir, s(&dir.join("e.toml")), "4", &[]);
    let (_, se) = param(&fit, "level");
    let u0 = best["estimates"]["level"].as_f64().unwrap();
    assert!((u0 - 0.3).abs() < 4.0 * se, "level {u0} ± {se}");
    for c in sel["candidates"].as_array().unwrap() {
        if c["failure_kind"].is_null() {
            assert!(c["estimates"]["level"].is_number(), "{c}");
        }
    }
}

#[test]
fn init_auto_fits_the_deviation_and_reaches_the_same_optimum() {
    common::init_auto_reaches_the_truth_s_optimum(
        "jitterid-level",
        "input-level.toml",
        &[
            ("num = [1.0]", "num = [0.05]"),
            ("den = [1.0, 1.0, 0.0]", "den = [1.0, 8.0, 0.0]"),
            ("level = 0.5 ", "level = 0.3 "),
        ],
        &["b0", "a1", "level", "offset"],
    );
}

/// `simulate` of `text`: exit 2, one line holding every one of `expect`, no data written.
fn refused_text(name: &str, text: &str, expect: &[&str]) {
    common::refused_text("jitterid-level-door", name, text, expect);
}

fn refused(name: &str, from: &str, to: &str, expect: &[&str]) {
    refused_text(name, &example_with("input-level.toml", from, to), expect);
}

#[test]
fn bad_levels_exit_2_naming_the_key() {
    refused(
        "nan",
        "level = ",
        "level = nan",
        &["[input] level", "finite"],
    );
    refused("string", "level = ", "level = \"0.4\"", &["[input] level"]);
    refused(
        "flag",
        "estimate_level",
        "estimate_level = 1",
        &["[input] estimate_level"],
    );
    refused_text(
        "known system",
        &std::fs::read_to_string(example("input-level.toml"))
            .unwrap()
            .replace("estimate = true", "estimate = false")
            .replace("estimate_offset = true", "estimate_offset = false"),
        &["[input] estimate_level", "estimate = true"],
    );
    // Without the integrator the level is a constant in the output, as the offset is.
    let stable = std::fs::read_to_string(example("input-level.toml"))
        .unwrap()
        .replace("den = [1.0, 1.0, 0.0]", "den = [1.0, 1.0, 0.5]")
        .replace("integrators = 1", "");
    refused_text(
        "confounded",
        &stable,
        &[
            "[input] estimate_level",
            "confounded",
            "[output] estimate_offset",
        ],
    );
    // Either one alone is fine.
    for (from, to) in [
        ("estimate_offset = true", "estimate_offset = false"),
        ("estimate_level = true", "estimate_level = false"),
    ] {
        let (o, _) = simulate_text("jitterid-level-door", "alone", &stable.replace(from, to));
        assert!(o.status.success(), "{from}: {}", stderr(&o));
    }
    // A sine is on at all times: an integrator's response to its level has no steady state.
    let sine = std::fs::read_to_string(example("input-level.toml"))
        .unwrap()
        .replace(
            "kind = \"random-binary\"\nmean_dwell = 3.0\nlow = 0.0\nhigh = 1.0\n",
            "kind = \"sine\"\nfrequency = 0.05\n",
        );
    refused_text("sine", &sine, &["[input] level", "integrator"]);
}

/// Two inputs whose systems settle, both levels estimated: each is a constant in the output.
#[test]
fn two_settling_levels_are_confounded() {
    let text = std::fs::read_to_string(example("two-input.toml")).unwrap();
    let mut inputs = text.split("[[input]]\n");
    let head = inputs.next().unwrap().to_string();
    let rest: Vec<String> = inputs
        .map(|t| format!("[[input]]\nlevel = 0.2\nestimate_level = true\n{t}"))
        .collect();
    let text = head + &rest.concat();
    refused_text(
        "two levels",
        &text,
        &["[[input]] 2", "estimate_level", "confounded"],
    );
    // One of them known: fine.
    let one = text.replacen("estimate_level = true", "estimate_level = false", 1);
    let (o, _) = simulate_text("jitterid-level-door", "one level", &one);
    assert!(o.status.success(), "{}", stderr(&o));
}
