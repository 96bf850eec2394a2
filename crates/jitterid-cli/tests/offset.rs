//! The output offset `[output]` through the binary: a record simulated by the tool with an
//! offset is fitted and the offset recovered within the reported standard error; `validate`
//! and `fit --json`'s `model` carry it; bad `[output]` values exit 2 naming the key.

mod common;

use common::{example, example_with, param, run, s, scratch_in, stderr, stdout};
use serde_json::Value;

/// Simulates run `run_no` of `exp` into `dir` and fits it; the fit's JSON.
fn simulate_and_fit(dir: &std::path::Path, exp: &str, run_no: &str, extra: &[&str]) -> Value {
    common::simulate_and_fit_in(dir, exp, run_no, extra)
}

#[test]
fn a_simulated_offset_is_recovered_within_its_standard_error() {
    let dir = scratch_in("jitterid-offset", "recovered");
    let exp = example("offset.toml");
    let fit = simulate_and_fit(&dir, &exp, "2", &[]);
    assert_eq!(fit["converged"], true, "{fit}");
    let (est, se) = param(&fit, "offset");
    // The reported standard error is that of the Monte Carlo spread within 15 %
    // (docs/reproduction.md), so 4 standard errors leave a chance of about 6e-5 per run.
    assert!(se > 0.0 && se < 0.01, "se {se}");
    assert!(
        (est - 1.5).abs() < 4.0 * se,
        "offset {est} ± {se}, truth 1.5"
    );
    // The system's parameters are recovered as well (the offset does not take their place).
    let (e, se) = param(&fit, "pole0.im");
    assert!((e - 0.3).abs() < 4.0 * se, "pole0.im {e} ± {se}");
    // The export reports the offset beside the transfer function.
    assert_eq!(
        fit["model"]["offset"].as_f64(),
        Some(est),
        "{}",
        fit["model"]
    );
}

#[test]
fn the_naive_fit_sees_the_offset_only_through_the_note_and_the_offset_fit_has_none() {
    let dir = scratch_in("jitterid-offset", "note");
    let exp = example("offset.toml");
    let data = dir.join("d.csv");
    assert!(run(&["simulate", &exp, "--run", "1", "--out", s(&data)])
        .status
        .success());
    // Fitted without an offset the residuals' mean is flagged and the note names the key.
    let without = run(&[
        "fit",
        &exp,
        "--data",
        s(&data),
        "--set",
        "output.estimate_offset=false",
        "--set",
        "output.offset=0",
    ]);
    let text = stdout(&without);
    assert!(
        text.contains("[output] estimate_offset = true"),
        "{text}{}",
        stderr(&without)
    );
    let with = run(&["fit", &exp, "--data", s(&data)]);
    let text = stdout(&with);
    assert!(with.status.success(), "{text}{}", stderr(&with));
    assert!(!text.contains("offset the model lacks"), "{text}");
    assert!(text.contains("model: y = y0 + G(s)u"), "{text}");
}

#[test]
fn validate_uses_the_offset_in_its_residuals() {
    let dir = scratch_in("jitterid-offset", "validate");
    let exp = example("offset.toml");
    let data = dir.join("d.csv");
    assert!(run(&["simulate", &exp, "--run", "4", "--out", s(&data)])
        .status
        .success());
    let o = run(&["validate", &exp, "--data", s(&data), "--json"]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let text = v.to_string();
    // With the offset in the model the fit explains the record (a model without it would
    // leave the offset, 1.5, against a response of about 0.4 in the residuals).
    let fit_percent = find_number(&v, "fit_percent").unwrap_or_else(|| panic!("{text}"));
    assert!(fit_percent > 90.0, "{fit_percent}: {text}");
}

/// The first number at `key` anywhere in `v`.
fn find_number(v: &Value, key: &str) -> Option<f64> {
    match v {
        Value::Object(m) => m
            .get(key)
            .and_then(Value::as_f64)
            .or_else(|| m.values().find_map(|x| find_number(x, key))),
        Value::Array(a) => a.iter().find_map(|x| find_number(x, key)),
        _ => None,
    }
}

/// `simulate` of the offset example with one line replaced: exit 2, one line holding
/// every one of `expect`, no data written.
fn refused(name: &str, from: &str, to: &str, expect: &[&str]) {
    common::refused_text(
        "jitterid-offset-door",
        name,
        &example_with("offset.toml", from, to),
        expect,
    );
}

#[test]
fn bad_output_values_exit_2_naming_the_key() {
    refused(
        "nan",
        "offset = ",
        "offset = nan",
        &["[output] offset", "finite"],
    );
    refused("inf", "offset = ", "offset = -inf", &["[output] offset"]);
    refused(
        "huge",
        "offset = ",
        "offset = 1e60",
        &["[output] offset", "magnitude"],
    );
    refused(
        "string",
        "offset = ",
        "offset = \"1.5\"",
        &["[output] offset"],
    );
    refused(
        "flag",
        "estimate_offset",
        "estimate_offset = 1",
        &["[output] estimate_offset"],
    );
    refused(
        "unknown",
        "estimate_offset",
        "estimate_ofset = true",
        &["[output]", "estimate_ofset"],
    );
    refused(
        "known system",
        "estimate = true",
        "estimate = false",
        &["[output] estimate_offset", "[system] estimate = true"],
    );
}

#[test]
fn a_band_without_f_0_cannot_see_the_offset() {
    let text = example_with(
        "offset.toml",
        "frequencies",
        "frequencies = { min = 0.01, max = 0.2 }",
    );
    let dir = scratch_in("jitterid-offset-door", "band");
    let exp = dir.join("e.toml");
    std::fs::write(&exp, &text).unwrap();
    let data = dir.join("d.csv");
    assert!(run(&["simulate", s(&exp), "--out", s(&data)])
        .status
        .success());
    let o = run(&["fit", s(&exp), "--data", s(&data)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("[output] estimate_offset"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("f = 0"), "{}", stderr(&o));
}

#[test]
fn an_absent_output_table_changes_nothing() {
    // Table 2 with an `[output]` table that says what the default says: the same numbers.
    let dir = scratch_in("jitterid-offset", "absent");
    let plain = example("table2.toml");
    let explicit = dir.join("e.toml");
    let text = std::fs::read_to_string(&plain).unwrap() + "\n[output]\n";
    std::fs::write(&explicit, text).unwrap();
    let a = simulate_and_fit(&dir, &plain, "0", &[]);
    let b = simulate_and_fit(&dir, s(&explicit), "0", &[]);
    assert_eq!(a["parameters"], b["parameters"]);
    assert!(a["model"].get("offset").is_none());
}

#[test]
fn init_auto_starts_the_offset_from_the_record() {
    // Every start badly wrong, the offset at 0 against a truth of 1.5: the data-driven start
    // (the initializer's system, then mean(y) − mean(m_k) for the offset) reaches the fit
    // from the truth.
    common::init_auto_reaches_the_truth_s_optimum(
        "jitterid-offset",
        "offset.toml",
        &[
            ("gain = 0.2", "gain = 0.001"),
            ("zeros = [-0.5]", "zeros = [-0.01]"),
            ("poles = [[-0.25, 0.3]]", "poles = [[-3.0, 0.01]]"),
            ("offset = 1.5 ", "offset = 0.0 "),
        ],
        &["gain", "zero0", "pole0.re", "pole0.im", "offset"],
    );
}

/// `select` carries the estimated offset into every candidate: on a record of `offset.toml`
/// (y₀ = 1.5, 150 times the noise) the true order wins and its offset is recovered; the
/// candidates' parameters include it.
#[test]
fn select_carries_the_offset_into_every_candidate() {
    let dir = scratch_in("jitterid-offset", "select");
    let text = std::fs::read_to_string(example("offset.toml")).unwrap();
    let sel = common::select_poles_1_to_2(&dir, &text, "4");
    let best = &sel["best"];
    assert_eq!(
        (best["poles"].as_u64(), best["zeros"].as_u64()),
        (Some(2), Some(1)),
        "{best}"
    );
    // The offset's standard error on such a record is about 0.002 (the fit's, see above).
    let y0 = best["estimates"]["offset"].as_f64().unwrap();
    assert!((y0 - 1.5).abs() < 0.01, "offset {y0}");
    for c in sel["candidates"].as_array().unwrap() {
        if c["failure_kind"].is_null() {
            assert!(c["estimates"]["offset"].is_number(), "{c}");
        }
    }
}
