//! `jitterid validate` through the real binary: the JSON verdicts and the frequency-response
//! CSV of a fitted model, and bad input named with exit status 2.

mod common;

use common::{example, run, s, scratch, stderr, stdout};
use serde_json::Value;

#[test]
fn validate_reports_verdicts_and_refuses_bad_input() {
    let dir = scratch("validate");
    let (data, other, fit) = (dir.join("d.csv"), dir.join("v.csv"), dir.join("fit.json"));
    let exp = example("table2.toml");
    assert!(run(&["simulate", &exp, "--out", s(&data)]).status.success());
    assert!(run(&["simulate", &exp, "--run", "1", "--out", s(&other)])
        .status
        .success());
    let o = run(&["fit", &exp, "--data", s(&data), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::write(&fit, stdout(&o)).unwrap();
    let bode = dir.join("b.csv");
    let o = run(&[
        "validate",
        &exp,
        "--data",
        s(&data),
        "--model",
        s(&fit),
        "--validation",
        s(&other),
        "--bode",
        s(&bode),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: Value = serde_json::from_str(&stdout(&o)).unwrap();
    // Data simulated from the fitted experiment: a good fit, white residuals.
    assert!(
        j["fit_percent"]["estimation"].as_f64().unwrap() > 80.0,
        "{j}"
    );
    assert!(
        j["fit_percent"]["validation"].as_f64().unwrap() > 80.0,
        "{j}"
    );
    assert_eq!(j["whiteness"]["passed"], true);
    assert_eq!(j["cross_correlation"]["passed"], true);
    let csv = std::fs::read_to_string(&bode).unwrap();
    assert!(csv.starts_with("f_hz,omega_rad_s,magnitude_db,phase_deg,magnitude_db_lo"));
    assert_eq!(csv.lines().count(), 201);

    // A model of another system: parameters renamed.
    let wrong = dir.join("wrong.json");
    std::fs::write(
        &wrong,
        stdout(&run(&["fit", &exp, "--data", s(&data), "--json"])).replace("\"gain\"", "\"k\""),
    )
    .unwrap();
    let validate = |model: &std::path::Path, validation: Option<&std::path::Path>| {
        let mut args = vec![
            "validate",
            exp.as_str(),
            "--data",
            s(&data),
            "--model",
            s(model),
        ];
        if let Some(v) = validation {
            args.extend(["--validation", s(v)]);
        }
        run(&args)
    };
    let refused = |o: std::process::Output, needle: &str| {
        assert_eq!(o.status.code(), Some(2));
        assert!(stderr(&o).contains(needle), "{}", stderr(&o));
    };
    refused(validate(&wrong, None), "do not match");
    // Malformed JSON.
    std::fs::write(&wrong, "{").unwrap();
    refused(validate(&wrong, None), "fit --json");
    // A validation record with another T, and one too short.
    let short = dir.join("short.csv");
    std::fs::write(&short, "t,y\n0,1\n2,2\n4,3\n").unwrap();
    refused(validate(&fit, Some(&short)), "too short");
    let rows: String = (0..40)
        .map(|k| format!("{},{}\n", 2.0 * k as f64, k))
        .collect();
    std::fs::write(&short, format!("t,y\n{rows}")).unwrap();
    refused(validate(&fit, Some(&short)), "interval");
}
