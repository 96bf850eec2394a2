//! Several inputs through the binary (`[[input]]`, `[[system]]`): a two-input record simulated
//! by the tool is fitted by BCLS and ML with every parameter within its standard error's
//! reach, the files carry one column per input, `validate` tests every input, `fit --json`'s
//! `model` has one transfer function per input and one state-space model with a column of `B`
//! per input, a Monte Carlo is unbiased, and bad files exit 2 naming what is wrong.

mod common;

use common::{example, param, run, s, scratch_in, stderr, stdout};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The truth of `examples/experiments/two-input.toml`, by parameter name.
const TRUTH: [(&str, f64); 6] = [
    ("torque.b0", 0.5),
    ("torque.a0", 0.5),
    ("brake.gain", 0.2),
    ("brake.zero0", -0.5),
    ("brake.pole0.re", -0.25),
    ("brake.pole0.im", 0.3),
];

/// Simulates run `run_no` of the two-input example into `dir`: the data file.
fn simulated(dir: &Path, run_no: &str) -> PathBuf {
    let data = dir.join("d.csv");
    let o = run(&[
        "simulate",
        &example("two-input.toml"),
        "--run",
        run_no,
        "--out",
        s(&data),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    data
}

fn json_of(args: &[&str]) -> Value {
    let o = run(args);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap()
}

#[test]
fn a_two_input_record_is_fitted_and_exported_per_input() {
    let dir = scratch_in("jitterid-multi-input", "fit");
    let exp = example("two-input.toml");
    let data = simulated(&dir, "3");
    // One data column per input, and one side file with both realisations.
    let head = std::fs::read_to_string(&data).unwrap();
    assert!(head.starts_with("k,t,y,torque,brake\n"), "{}", &head[..40]);
    let side = std::fs::read_to_string(dir.join("d.input.csv")).unwrap();
    assert!(side.starts_with("t,torque,brake\n"), "{}", &side[..30]);
    for method in ["bcls", "ml"] {
        let fit = json_of(&[
            "fit",
            &exp,
            "--data",
            s(&data),
            "--method",
            method,
            "--json",
        ]);
        assert_eq!(fit["converged"], true, "{method}: {fit}");
        for (name, truth) in TRUTH {
            let (e, se) = param(&fit, name);
            // The reported standard errors are the Monte Carlo spread's within 15 %
            // (docs/reproduction.md): 4 of them leave a chance of about 6e-5 per parameter.
            assert!(se > 0.0, "{method} {name}: se {se}");
            assert!(
                (e - truth).abs() < 4.0 * se,
                "{method} {name}: {e} ± {se}, truth {truth}"
            );
        }
        let model = &fit["model"];
        let inputs = model["inputs"].as_array().unwrap();
        assert_eq!(inputs.len(), 2, "{model}");
        assert_eq!(inputs[0]["name"], "torque");
        assert_eq!(inputs[1]["name"], "brake");
        // torque → y is b0/(s + a0): its exported tf is the fitted coefficients.
        let (b0, _) = param(&fit, "torque.b0");
        assert_eq!(inputs[0]["tf"]["num"][0].as_f64(), Some(b0));
        // One realisation of both: 3 states, a column of B and D per input, and its
        // transfer function from each input is that input's.
        let ss = &model["ss"];
        assert_eq!(ss["a"].as_array().unwrap().len(), 3);
        assert!(ss["b"]
            .as_array()
            .unwrap()
            .iter()
            .all(|r| r.as_array().unwrap().len() == 2));
        assert_eq!(ss["d"][0].as_array().unwrap().len(), 2);
    }
    let v = json_of(&["validate", &exp, "--data", s(&data), "--json"]);
    let tests = v["estimation"]["input_correlations"]
        .as_array()
        .or_else(|| v["input_correlations"].as_array())
        .unwrap_or_else(|| panic!("no input_correlations in {v}"));
    let names: Vec<&str> = tests.iter().map(|t| t["input"].as_str().unwrap()).collect();
    assert_eq!(names, ["torque", "brake"]);
}

/// A wrong model of one channel is seen by the cross-correlation with that input: the brake
/// channel fitted as a first-order system leaves its dynamics in the residuals.
#[test]
fn validate_names_the_input_whose_channel_is_wrong() {
    let dir = scratch_in("jitterid-multi-input", "wrong-channel");
    let data = simulated(&dir, "1");
    let text = std::fs::read_to_string(example("two-input.toml")).unwrap();
    let wrong = text.replacen(
        "kind = \"zpk\"\ngain = 0.2\nzeros = [-0.5]\npoles = [[-0.25, 0.3]]",
        "kind = \"tf\"\nnum = [0.2]\nden = [1.0, 0.5]",
        1,
    );
    assert_ne!(wrong, text);
    let exp = dir.join("wrong.toml");
    std::fs::write(&exp, wrong).unwrap();
    let v = json_of(&["validate", s(&exp), "--data", s(&data), "--json"]);
    let tests = v["estimation"]["input_correlations"]
        .as_array()
        .or_else(|| v["input_correlations"].as_array())
        .unwrap_or_else(|| panic!("no input_correlations in {v}"));
    let p = |i: usize| tests[i]["test"]["p_value"].as_f64().unwrap();
    assert!(p(1) < 1e-3, "brake's test should reject: {}", tests[1]);
}

/// A seeded Monte Carlo of 48 records: every parameter's mean within 3 of its Monte Carlo
/// standard errors of the truth (BCLS is consistent on every channel).
#[test]
fn a_two_input_monte_carlo_is_unbiased() {
    let mc = json_of(&[
        "montecarlo",
        &example("two-input.toml"),
        "--runs",
        "48",
        "--seed",
        "11",
        "--json",
    ]);
    assert_eq!(mc["converged"], 48, "{mc}");
    for p in mc["parameters"].as_array().unwrap() {
        let (mean, truth, se) = (
            p["mean"].as_f64().unwrap(),
            p["true"].as_f64().unwrap(),
            p["se"].as_f64().unwrap(),
        );
        assert!(
            (mean - truth).abs() < 3.0 * se,
            "{}: mean {mean}, truth {truth}, Monte Carlo se {se}",
            p["name"]
        );
    }
}

/// Runs `jitterid simulate` on the two-input example with its text edited by `edit`; the exit
/// status must be 2 and stderr is returned.
fn refused(name: &str, edit: impl Fn(&str) -> String) -> String {
    refused_in("two-input.toml", name, edit)
}

/// [`refused`] for the example file `file`.
fn refused_in(file: &str, name: &str, edit: impl Fn(&str) -> String) -> String {
    let dir = scratch_in("jitterid-multi-input", name);
    let text = std::fs::read_to_string(example(file)).unwrap();
    let edited = edit(&text);
    assert_ne!(edited, text, "{name}: the edit changed nothing");
    let exp = dir.join("e.toml");
    std::fs::write(&exp, edited).unwrap();
    let o = run(&["simulate", s(&exp), "--out", s(&dir.join("d.csv"))]);
    assert_eq!(o.status.code(), Some(2), "{name}: {}", stdout(&o));
    stderr(&o)
}

#[test]
fn bad_multi_input_files_exit_2_naming_the_problem() {
    // One [[system]] too few.
    let e = refused("counts", |t| {
        let i = t.rfind("[[system]]").unwrap();
        let j = t[i..].find("[jitter]").unwrap() + i;
        format!("{}{}", &t[..i], &t[j..])
    });
    assert!(
        e.contains("2 [[input]] table(s) and 1 [[system]] table(s)"),
        "{e}"
    );
    // Two inputs with one name.
    let e = refused("names", |t| {
        t.replacen("name = \"brake\"", "name = \"torque\"", 1)
    });
    assert!(
        e.contains("[input] name") && e.contains("already the name"),
        "{e}"
    );
    // A name that is a column of the files.
    let e = refused("reserved", |t| {
        t.replacen("name = \"brake\"", "name = \"tau\"", 1)
    });
    assert!(e.contains("[input] name") && e.contains("\"tau\""), "{e}");
    // A channel without an input.
    let e = refused("sinusoid", |t| {
        t.replacen(
            "kind = \"tf\"\nnum = [0.5]\nden = [1.0, 0.5]",
            "kind = \"sinusoid\"\namplitude = 1.0\nfrequency = 0.1",
            1,
        )
    });
    assert!(
        e.contains("[system] kind") && e.contains("has no input"),
        "{e}"
    );
}

/// The two-input example with `select` appended to it, in `dir`.
fn with_select(dir: &Path, select: &str) -> String {
    let text = std::fs::read_to_string(example("two-input.toml")).unwrap();
    let exp = dir.join("e.toml");
    std::fs::write(&exp, format!("{text}\n[select]\n{select}\n")).unwrap();
    s(&exp).to_string()
}

/// `select` over each input's order on a seeded two-input record: the joint candidates of
/// (1 or 2 poles) for torque × (1 pole, or 2 poles and a zero) for brake, and the true pair
/// (torque 1/0, brake 2/1) ranks first.
#[test]
fn select_recovers_each_input_s_order() {
    let dir = scratch_in("jitterid-multi-input", "select");
    let data = simulated(&dir, "3");
    let exp = with_select(
        &dir,
        "families = [\"gaussian\"]\norders = { torque = [[1, 0], [2, 0]], brake = [[1, 0], [2, 1]] }",
    );
    let sel = json_of(&["select", &exp, "--data", s(&data), "--json"]);
    let candidates = sel["candidates"].as_array().unwrap();
    assert_eq!(candidates.len(), 4, "{sel}");
    let best = &sel["best"];
    assert_eq!(best["converged"], true, "{best}");
    assert_eq!(
        best["orders"]["torque"],
        serde_json::json!([1, 0]),
        "{best}"
    );
    assert_eq!(best["orders"]["brake"], serde_json::json!([2, 1]), "{best}");
    assert_eq!(
        (best["poles"].as_u64(), best["zeros"].as_u64()),
        (Some(3), Some(1))
    );
    assert!(best["estimates"]["torque.a0"].is_number(), "{best}");
    // The table names each input's order (one candidate, to keep the test short).
    let one = with_select(
        &dir,
        "families = [\"none\"]\norders = { torque = [[1, 0]], brake = [[2, 1]] }",
    );
    let o = run(&["select", &one, "--data", s(&data)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("torque 1/0, brake 2/1"),
        "{}",
        stdout(&o)
    );
}

/// Bad multi-input grids exit 2 naming the key: an unknown input, too many candidates, an
/// `orders` for a single input, a channel select cannot carry.
#[test]
fn bad_multi_input_grids_exit_2_naming_the_key() {
    let dir = scratch_in("jitterid-multi-input", "select-bad");
    let data = simulated(&dir, "0");
    let refused = |select: &str| {
        let exp = with_select(&dir, select);
        let o = run(&["select", &exp, "--data", s(&data)]);
        assert_eq!(o.status.code(), Some(2), "{select}: {}", stdout(&o));
        stderr(&o)
    };
    let e = refused("orders = { wheel = [[1, 0]] }");
    assert!(
        e.contains("[select] orders") && e.contains("`wheel`"),
        "{e}"
    );
    let e = refused("poles = [1, 4]\nzeros = [0, 3]\nfamilies = [\"none\", \"gaussian\"]");
    assert!(
        e.contains("[select] orders") && e.contains("at most 64"),
        "{e}"
    );
    let e = refused("orders = { torque = [[0, 0]] }");
    assert!(e.contains("[select] orders") && e.contains("torque"), "{e}");
    let one = dir.join("one.toml");
    let text = std::fs::read_to_string(example("offset.toml")).unwrap();
    std::fs::write(
        &one,
        format!("{text}\n[select]\norders = {{ u = [[1, 0]] }}\n"),
    )
    .unwrap();
    let o = run(&["select", s(&one), "--data", s(&data)]);
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    assert!(stderr(&o).contains("[select] orders"), "{}", stderr(&o));
    let text = std::fs::read_to_string(example("two-input.toml")).unwrap();
    let delayed = text.replacen("den = [1.0, 0.5]", "den = [1.0, 0.5]\ndelay = 0.5", 1);
    let exp = dir.join("delayed.toml");
    std::fs::write(
        &exp,
        format!("{delayed}\n[select]\nfamilies = [\"none\"]\n"),
    )
    .unwrap();
    let o = run(&["select", s(&exp), "--data", s(&data)]);
    assert_eq!(o.status.code(), Some(2), "{}", stdout(&o));
    assert!(stderr(&o).contains("[[system]] delay"), "{}", stderr(&o));
}

/// `fit --init auto` of the two-input example: the multi-input initializer's start, far from
/// nothing but the record, converges to the optimum the fit from the truth reaches (to the
/// solver's tolerance, well inside a hundredth of each standard error).
#[test]
fn init_auto_reaches_the_fit_from_the_truth() {
    let dir = scratch_in("jitterid-multi-input", "init-auto");
    let data = simulated(&dir, "5");
    let exp = example("two-input.toml");
    let from_truth = json_of(&["fit", &exp, "--data", s(&data), "--json"]);
    let auto = json_of(&["fit", &exp, "--data", s(&data), "--init", "auto", "--json"]);
    assert_eq!(auto["converged"], true, "{auto}");
    for (name, _) in TRUTH {
        let (a, se) = param(&from_truth, name);
        let (b, _) = param(&auto, name);
        assert!(
            (a - b).abs() < 0.01 * se,
            "{name}: {a} from the truth, {b} from auto (se {se})"
        );
    }
}

/// The worked example (`docs/walkthrough-inputs.md`): one grey-box model with a column of `B`
/// per input, its four physical parameters shared by both inputs' responses, and the
/// operating point, all recovered within 4 reported standard errors; the export is the model's
/// own `A, B, C, D`.
#[test]
fn a_grey_box_with_a_column_per_input_shares_its_parameters() {
    let dir = scratch_in("jitterid-multi-input", "heated-room");
    let exp = example("heated-room.toml");
    let data = dir.join("room.csv");
    let o = run(&["simulate", &exp, "--out", s(&data)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let fit = json_of(&["fit", &exp, "--data", s(&data), "--json"]);
    assert_eq!(fit["converged"], true, "{fit}");
    let names: Vec<&str> = fit["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["C_air", "C_wall", "R_aw", "R_wo", "offset"]);
    for (name, truth) in [
        ("C_air", 2.0),
        ("C_wall", 10.0),
        ("R_aw", 1.0),
        ("R_wo", 2.0),
        ("offset", 20.0),
    ] {
        let (e, se) = param(&fit, name);
        assert!(
            (e - truth).abs() < 4.0 * se,
            "{name}: {e} ± {se}, truth {truth}"
        );
    }
    let ss = &fit["model"]["ss"];
    // B = [[1/C_air, 0], [0, 1/(R_wo C_wall)]]: two states, a column per input.
    let (c_air, _) = param(&fit, "C_air");
    assert_eq!(ss["a"].as_array().unwrap().len(), 2, "{ss}");
    assert!(
        (ss["b"][0][0].as_f64().unwrap() - 1.0 / c_air).abs() < 1e-12,
        "{ss}"
    );
    assert_eq!(ss["b"][0][1].as_f64(), Some(0.0), "{ss}");
    assert_eq!(ss["b"][1][0].as_f64(), Some(0.0), "{ss}");
    // A B with one column too few for the two inputs is refused at its key.
    let e = refused_in("heated-room.toml", "b-columns", |t| {
        t.replacen(
            "b = [[\"1/C_air\", 0], [0, \"1/(R_wo*C_wall)\"]]",
            "b = [[\"1/C_air\"], [0]]",
            1,
        )
    });
    assert!(
        e.contains("[system] b") && e.contains("expected 2 entries"),
        "{e}"
    );
}

/// `validate --bode` of the two-input example writes each input's frequency response, the
/// columns of one input's after `input`: at the lowest frequency each magnitude is its true
/// transfer function's within 2 of its band's σ (the band is ±2σ, so within the band), and the
/// two inputs' responses differ as their systems do.
#[test]
fn validate_bode_writes_one_response_per_input() {
    let dir = scratch_in("jitterid-multi-input", "bode");
    let data = simulated(&dir, "3");
    let bode = dir.join("b.csv");
    let exp = example("two-input.toml");
    let o = run(&["validate", &exp, "--data", s(&data), "--bode", s(&bode)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(&bode).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("input,f_hz,omega_rad_s,magnitude_db,phase_deg,magnitude_db_lo,magnitude_db_hi,phase_deg_lo,phase_deg_hi")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 400, "200 frequencies per input");
    let first = |input: &str| rows.iter().find(|r| r[0] == input).unwrap().clone();
    let num = |r: &[&str], i: usize| r[i].parse::<f64>().unwrap();
    // |G(i2πf)| of the truth at f = 1/(NT) = 1/400 Hz.
    let w = std::f64::consts::TAU / 400.0;
    let torque = 0.5 / (w * w + 0.25f64).sqrt();
    let brake = {
        let n = (0.2 * 0.2 * (w * w + 0.25)).sqrt();
        let (re, im) = (0.1525 - w * w, 0.5 * w);
        n / (re * re + im * im).sqrt()
    };
    for (input, truth) in [("torque", torque), ("brake", brake)] {
        let r = first(input);
        let (db, lo, hi) = (num(&r, 3), num(&r, 5), num(&r, 6));
        let want = 20.0 * truth.log10();
        assert!(lo < db && db < hi, "{input}: {r:?}");
        assert!(
            (db - want).abs() <= hi - lo,
            "{input}: {db} dB, truth {want} dB, band [{lo}, {hi}]"
        );
    }
}
