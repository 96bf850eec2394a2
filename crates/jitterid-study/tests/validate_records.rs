//! `validate_records` (records in memory, as the Python package gives them) and `validate`
//! (records in files, as the command line gives them) are two doors to the same checks: on the
//! walkthrough's records, with the model fitted there or given as `fit --json`, their reports
//! are equal.

use jitterid_study::experiment::{self, Experiment, Purpose};
use jitterid_study::fit::{fit_json, fit_values, signal_of};
use jitterid_study::records::{read_data, read_input, read_input_on};
use jitterid_study::validate::{
    validate, validate_records, validation_grid, FitText, RecordSamples, ValidateOptions,
    MIN_VALIDATION_SAMPLES,
};
use jitterid_study::Watch;
use std::path::{Path, PathBuf};

fn walkthrough(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/walkthrough")
        .join(file)
}

/// The walkthrough's model fitted by BCLS (a few seconds in a debug build, where its
/// Box–Jenkins criterion takes longer).
fn model() -> Experiment {
    experiment::read(
        &walkthrough("model.toml"),
        Purpose::Estimate(Some(experiment::Method::BCLS)),
    )
    .unwrap()
}

/// A data file's record held in memory, named as the file names it.
fn in_memory(exp: &Experiment, file: &str, validation: bool) -> RecordSamples {
    let path = walkthrough(file);
    let table = jitterid_study::csvio::read(&path).unwrap();
    let y = table.column("y").unwrap().to_vec();
    let grid = if validation {
        validation_grid(exp, y.len(), table.optional("t"), &table.name, "validation").unwrap()
    } else {
        read_data(exp, &path).unwrap();
        exp.grid
    };
    let inputs = if validation {
        read_input_on(exp, &path, None, &grid).unwrap()
    } else {
        read_input(exp, &path, None).unwrap()
    };
    RecordSamples {
        name: table.name,
        grid,
        y,
        inputs,
    }
}

fn json(v: &jitterid_study::validate::Validation) -> serde_json::Value {
    serde_json::to_value(v.json()).unwrap()
}

#[test]
fn records_in_memory_validate_as_their_files_do() {
    let exp = model();
    let (data, check) = (walkthrough("estimation.csv"), walkthrough("validation.csv"));
    let from_files = validate(
        &exp,
        &data,
        &ValidateOptions {
            validation: Some(&check),
            ..ValidateOptions::default()
        },
        &Watch::none(),
    )
    .unwrap();
    let from_memory = validate_records(
        &exp,
        in_memory(&exp, "estimation.csv", false),
        Some(in_memory(&exp, "validation.csv", true)),
        None,
        ValidateOptions::default().level,
        &Watch::none(),
    )
    .unwrap();
    assert_eq!(json(&from_files), json(&from_memory));
    assert_eq!(from_files.covariance, from_memory.covariance);
}

#[test]
fn a_model_given_as_fit_json_validates_as_its_file_does() {
    let exp = model();
    let record = in_memory(&exp, "estimation.csv", false);
    let signal = signal_of(&exp, &record.inputs).unwrap();
    let f = fit_values(&exp, signal, record.y.clone(), "fit", &Watch::none()).unwrap();
    let text = serde_json::to_string(&fit_json(&f)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("fit.json");
    std::fs::write(&file, &text).unwrap();
    let from_file = validate(
        &exp,
        &walkthrough("estimation.csv"),
        &ValidateOptions {
            model: Some(&file),
            ..ValidateOptions::default()
        },
        &Watch::none(),
    )
    .unwrap();
    let given = FitText {
        text: &text,
        name: "fit",
    };
    let from_text =
        validate_records(&exp, record, None, Some(given), 0.01, &Watch::none()).unwrap();
    assert_eq!(json(&from_file), json(&from_text));
}

#[test]
fn a_short_validation_record_and_a_bad_level_are_refused_by_name() {
    let exp = model();
    let e = validation_grid(&exp, MIN_VALIDATION_SAMPLES - 1, None, "v", "validation").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("v: validation: 15 samples, too short"),
        "{e}"
    );
    let t: Vec<f64> = (0..20).map(|k| 0.5 * k as f64).collect();
    let e = validation_grid(&exp, 20, Some(&t), "v", "validation").unwrap_err();
    assert!(e.to_string().contains("interval T = 0.5"), "{e}");
    let record = in_memory(&exp, "estimation.csv", false);
    let e = validate_records(&exp, record, None, None, 1.5, &Watch::none()).unwrap_err();
    assert!(
        e.to_string().starts_with("level: expected a test level"),
        "{e}"
    );
}
