//! `jitterid design` of a multisine through the real binary: the designed tones in the JSON's
//! `design` object beside the file's own, the written experiment and DAC sequence round trip
//! through `simulate` and `fit`, and bad multisine keys exit 2 naming the key.

mod common;

use common::{example, run, s, scratch, stderr, stdout};

/// `jitterid design` of `design-multisine.toml` with four tones (a cheap search), then `extra`.
fn cheap(extra: &[&str]) -> std::process::Output {
    let file = example("design-multisine.toml");
    let mut args = vec!["design", file.as_str(), "--set", "design.tones=4"];
    args.extend_from_slice(extra);
    run(&args)
}

#[test]
fn multisine_design_json_reports_the_tones_beside_the_baseline() {
    let o = cheap(&["--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let m = &v["design"]["multisine"];
    let mut keys: Vec<&String> = m.as_object().unwrap().keys().collect();
    keys.sort();
    let want = [
        "amplitudes",
        "crest_factor",
        "frequencies",
        "phases",
        "power",
    ];
    assert_eq!(keys, want);
    // At most the four candidates: tones the design gives no power are left out.
    let n = m["frequencies"].as_array().unwrap().len();
    assert!((1..=4).contains(&n), "{m}");
    assert!(m["amplitudes"]
        .as_array()
        .unwrap()
        .iter()
        .all(|a| a.as_f64().unwrap() > 0.0));
    let own = &v["baseline"]["design"]["multisine"];
    assert_eq!(own["frequencies"].as_array().unwrap().len(), 4);
    let power = |m: &serde_json::Value| m["power"].as_f64().unwrap();
    assert!((power(m) - power(own)).abs() < 1e-12, "{m} {own}");
    assert!(v["design"]["interval"].as_f64() == Some(1.0) && v["design"]["samples"] == 200);
    // The text names the tones of both.
    let o = cheap(&[]);
    let text = stdout(&o);
    let designed = text
        .lines()
        .find(|l| l.starts_with("designed:"))
        .unwrap_or_default();
    let baseline = text
        .lines()
        .find(|l| l.starts_with("baseline:"))
        .unwrap_or_default();
    assert!(
        designed.contains(&format!(
            "samples = 200, multisine of {n} tones: power = 0.125000"
        )) && baseline.contains("samples = 200, multisine of 4 tones: power = 0.125000")
            && text.contains("frequency (Hz)"),
        "{text}"
    );
}

/// `--write-input` writes the experiment with the designed tones and the DAC sequence; the
/// experiment simulates and fits.
#[test]
fn the_written_multisine_round_trips_through_simulate_and_fit() {
    let d = scratch("design-multisine-write");
    let csv = d.join("designed.csv");
    let o = cheap(&["--write-input", s(&csv), "--dac-rate", "2.5", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let exp = d.join("designed.toml");
    let text = std::fs::read_to_string(&exp).unwrap();
    assert!(
        text.contains("kind = \"multisine\"") && !text.contains("\n[design]"),
        "{text}"
    );
    let dac = std::fs::read_to_string(&csv).unwrap();
    assert!(dac.starts_with("t,u"));
    assert_eq!(dac.lines().count(), 1 + 500, "200 s at 2.5 Hz");
    let data = d.join("d.csv");
    let o = run(&["simulate", s(&exp), "--seed", "3", "--out", s(&data)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = run(&["fit", s(&exp), "--data", s(&data), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let fit: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let (gain, se) = common::param(&fit, "gain");
    assert!((gain - 0.2).abs() < 5.0 * se, "gain {gain} ± {se}");
}

/// Bad multisine keys exit 2 with one line naming the key.
#[test]
fn bad_multisine_keys_exit_2_naming_the_key() {
    let cases: [(&[&str], &str); 5] = [
        (&["--set", "design.band=[0.01, 0.6]"], "[design] band"),
        (&["--set", "design.tones=0"], "[design] tones"),
        (&["--set", "design.power=0.0"], "[design] power"),
        (
            &["--set", "design.power=1.0", "--set", "design.peak=0.5"],
            "cannot hold the power",
        ),
        (&["--dac-rate", "0.5"], "--dac-rate 0.5"),
    ];
    for (args, want) in cases {
        let o = cheap(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(want), "{args:?}: expected {want:?} in {err}");
    }
    // A band with the paper's random binary input.
    let table2 = example("table2.toml");
    let o = run(&["design", &table2, "--set", "design.band=[0.01, 0.4]"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("[design] band"), "{}", stderr(&o));
}
