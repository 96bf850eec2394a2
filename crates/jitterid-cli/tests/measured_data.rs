//! The guide `docs/measured-data.md`, run through the binary on the shipped files of
//! `examples/measured/`: the commands of the page, in its order, with every number and decision
//! it states checked, so that the page cannot go stale silently. The truth is read from the
//! generator, `truth.toml`.

mod common;

use common::{jitterid, param, scratch_in, stderr, stdout};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The guide's directory, copied into a scratch directory: its commands write `centred.csv`,
/// `fit.json` and `bode.csv` beside the shipped files.
fn guide_dir(name: &str) -> PathBuf {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/measured");
    let dir = scratch_in("jitterid-measured-data", name);
    for f in ["record.csv", "switches.csv", "model.toml", "truth.toml"] {
        std::fs::copy(shipped.join(f), dir.join(f)).unwrap();
    }
    dir
}

/// Runs `jitterid args…` in `dir`, as the page does from `examples/measured/`.
fn run(dir: &Path, args: &[&str]) -> Output {
    jitterid().current_dir(dir).args(args).output().unwrap()
}

/// Runs and parses JSON; exit status `status` required.
fn json(dir: &Path, args: &[&str], status: i32) -> Value {
    let o = run(dir, args);
    assert_eq!(o.status.code(), Some(status), "{args:?}: {}", stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap_or_else(|e| panic!("{args:?}: {e}"))
}

/// The page's `awk` line: `y − offset`, printed with 17 significant digits (the same `f64`).
fn centred(dir: &Path, offset: f64) {
    let text = std::fs::read_to_string(dir.join("record.csv")).unwrap();
    let mut out = vec![text.lines().next().unwrap().to_string()];
    for l in text.lines().skip(1) {
        let c: Vec<&str> = l.split(',').collect();
        let y: f64 = c[1].parse().unwrap();
        out.push(format!("{},{},{}", c[0], y - offset, c[2]));
    }
    std::fs::write(dir.join("centred.csv"), out.join("\n") + "\n").unwrap();
}

/// The offset the note names, and the status and cause lines of the first fit.
#[test]
fn the_first_fit_names_the_offset_and_says_it_stopped() {
    let dir = guide_dir("offset");
    let o = run(&dir, &["fit", "model.toml", "--data", "record.csv"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines[1].starts_with("stopped: converged, but the residual spectrum is not flat"),
        "{text}"
    );
    assert!(!text.contains("NOT converged"), "{text}");
    let cause = lines[2]
        .strip_prefix("likely cause: an output offset of about ")
        .unwrap_or_else(|| panic!("{text}"));
    let offset: f64 = cause.split(' ').next().unwrap().parse().unwrap();
    // The page subtracts the note's value to four decimals, 0.3024; the bias was 0.3.
    assert_eq!(format!("{offset:.4}"), "0.3024", "{text}");
    assert!((offset - 0.3).abs() < 0.003, "{offset}");
    assert!(
        text.contains("note: the output probably has an offset the model lacks, about 3.0242e-1"),
        "{text}"
    );
    // The grid came from the record: 400 samples from 1200 s every 0.5 s, with no [sampling].
    let model = std::fs::read_to_string(dir.join("model.toml")).unwrap();
    assert!(!model
        .lines()
        .any(|l| l.trim_start().starts_with("[sampling]")));
    let v = json(
        &dir,
        &["validate", "model.toml", "--data", "record.csv", "--json"],
        0,
    );
    assert_eq!(v["estimation"]["samples"], 400);
    // A row off the grid is refused with its line.
    let text = std::fs::read_to_string(dir.join("record.csv")).unwrap();
    let bad: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 41 {
                l.replacen("1220.0", "1220.3", 1)
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(dir.join("bad.csv"), bad.join("\n") + "\n").unwrap();
    let o = run(&dir, &["fit", "model.toml", "--data", "bad.csv"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("bad.csv:42: column `t`: 1220.3 is not on the uniform grid t0 + kT"),
        "{}",
        stderr(&o)
    );
}

/// The input's switch times against its samples held: the note, and the jitter that absorbs
/// the timing error (0.55 s against 0.11 s, on the centred record).
#[test]
fn the_held_input_is_noted_and_inflates_the_jitter() {
    let dir = guide_dir("input");
    let o = run(
        &dir,
        &[
            "fit",
            "model.toml",
            "--data",
            "record.csv",
            "--set",
            "input.path=record.csv",
        ],
    );
    let text = stdout(&o);
    assert!(
        text.contains(
            "note: all 58 switches of the input inside the record lie on the sampling grid t0 + kT"
        ),
        "{text}"
    );
    centred(&dir, 0.3024);
    let held = json(
        &dir,
        &[
            "fit",
            "model.toml",
            "--data",
            "centred.csv",
            "--set",
            "input.path=centred.csv",
            "--json",
        ],
        1,
    );
    let switches = json(
        &dir,
        &["fit", "model.toml", "--data", "centred.csv", "--json"],
        0,
    );
    let (s_held, _) = param(&held, "jitter.sigma");
    let (s_true, _) = param(&switches, "jitter.sigma");
    assert_eq!(format!("{s_held:.2}"), "0.55");
    assert_eq!(format!("{s_true:.2}"), "0.11");
    assert!(switches.get("notes").is_none(), "{switches}");
}

/// Select → fit → validate → export on the centred record, with the page's numbers, and the
/// likelihood fit against the generator.
#[cfg(feature = "ml")]
#[test]
fn select_fit_validate_export_recover_the_generator() {
    let dir = guide_dir("workflow");
    centred(&dir, 0.3024);
    // The BCLS fit of the page.
    let bcls = json(
        &dir,
        &["fit", "model.toml", "--data", "centred.csv", "--json"],
        0,
    );
    assert_eq!(format!("{:.6}", param(&bcls, "b0").0), "1.996856");
    assert_eq!(format!("{:.6}", param(&bcls, "jitter.sigma").1), "0.052707");
    // Selection: two poles, no zero, Gaussian; the screen alone prefers no jitter by 5 BIC
    // units, the exact likelihood puts Gaussian 320 ahead of two-point and 431 of none.
    let sel = json(
        &dir,
        &["select", "model.toml", "--data", "centred.csv", "--json"],
        0,
    );
    let best = &sel["best"];
    assert_eq!(
        (&best["poles"], &best["zeros"], &best["family"]),
        (&Value::from(2), &Value::from(0), &Value::from("gaussian")),
        "{sel}"
    );
    let finalist = |family: &str| {
        sel["candidates"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["family"] == family && c["ranked_by"] == "exact-ml-bic")
            .unwrap_or_else(|| panic!("no {family} finalist: {sel}"))
            .clone()
    };
    let (g, t, n) = (
        finalist("gaussian"),
        finalist("two-point"),
        finalist("none"),
    );
    let bic = |c: &Value, key: &str| c[key].as_f64().unwrap();
    let screen = bic(&g, "bcls_criterion") - bic(&n, "bcls_criterion");
    assert_eq!(format!("{screen:.0}"), "5");
    assert_eq!(
        format!("{:.0}", bic(&t, "criterion") - bic(&g, "criterion")),
        "320"
    );
    assert_eq!(
        format!("{:.0}", bic(&n, "criterion") - bic(&g, "criterion")),
        "431"
    );
    // The page's table has both columns.
    let o = run(&dir, &["select", "model.toml", "--data", "centred.csv"]);
    assert!(stdout(&o).contains("screen BCLS BIC      final ML BIC"));
    // Another family through --set.
    let two = run(
        &dir,
        &[
            "fit",
            "model.toml",
            "--data",
            "centred.csv",
            "--method",
            "ml",
            "--set",
            "jitter.family=two-point",
            "--set",
            "jitter.d=0.1",
        ],
    );
    assert!(two.status.success(), "{}", stderr(&two));
    // The likelihood fit: every parameter within one standard error of the generator, the
    // jitter's standard error nine times smaller than BCLS's.
    let ml = json(
        &dir,
        &[
            "fit",
            "model.toml",
            "--data",
            "centred.csv",
            "--method",
            "ml",
            "--json",
        ],
        0,
    );
    std::fs::write(dir.join("fit.json"), ml.to_string()).unwrap();
    let truth: toml::Table = std::fs::read_to_string(dir.join("truth.toml"))
        .unwrap()
        .parse()
        .unwrap();
    let num = |k: &str, i: usize| truth["system"][k][i].as_float().unwrap();
    let expected = [
        ("b0", num("num", 0)),
        ("a1", num("den", 1)),
        ("a0", num("den", 2)),
        ("jitter.sigma", truth["jitter"]["sigma"].as_float().unwrap()),
        ("noise.std", truth["noise"]["std"].as_float().unwrap()),
    ];
    for (name, want) in expected {
        let (got, se) = param(&ml, name);
        assert!(
            (got - want).abs() < se,
            "{name}: {got} ± {se} against {want}"
        );
    }
    let ratio = param(&bcls, "jitter.sigma").1 / param(&ml, "jitter.sigma").1;
    assert_eq!(format!("{ratio:.0}"), "9");
    // Validate the saved model: both tests pass, fit 92.06 %.
    let validate = [
        "validate",
        "model.toml",
        "--data",
        "centred.csv",
        "--model",
        "fit.json",
        "--set",
        "estimate.method=ml",
    ];
    let v = json(
        &dir,
        &[&validate[..], &["--bode", "bode.csv", "--json"]].concat(),
        0,
    );
    assert_eq!(
        format!("{:.2}", v["fit_percent"]["estimation"].as_f64().unwrap()),
        "92.06"
    );
    assert_eq!(v["whiteness"]["passed"], true);
    assert_eq!(v["cross_correlation"]["passed"], true);
    assert!(dir.join("bode.csv").exists());
    let table = run(&dir, &validate);
    assert!(stdout(&table).contains("fit percent         92.06 %"));
    // Export: the transfer function and its poles.
    let tf = &ml["model"]["tf"];
    assert_eq!(format!("{:.4}", tf["num"][0].as_f64().unwrap()), "2.0059");
    assert_eq!(format!("{:.4}", tf["den"][1].as_f64().unwrap()), "1.2042");
    assert_eq!(format!("{:.4}", tf["den"][2].as_f64().unwrap()), "1.0010");
    let pole = &ml["model"]["zpk"]["poles"][0];
    assert_eq!(
        format!(
            "{:.3} {:.3}",
            pole[0].as_f64().unwrap(),
            pole[1].as_f64().unwrap().abs()
        ),
        "-0.602 0.799"
    );
}

/// The page's other way: the offset estimated with the system (`--set
/// output.estimate_offset=true`, the key the note names) converges where the fit without it
/// stopped, finds the sensor's bias of 0.3 within its standard error, and leaves no note.
#[test]
fn the_offset_estimated_with_the_system_is_the_sensor_bias() {
    let dir = guide_dir("offset-estimated");
    let first = stdout(&run(&dir, &["fit", "model.toml", "--data", "record.csv"]));
    assert!(
        first.contains("--set output.estimate_offset=true"),
        "{first}"
    );
    let v = json(
        &dir,
        &[
            "fit",
            "model.toml",
            "--data",
            "record.csv",
            "--set",
            "output.estimate_offset=true",
            "--json",
        ],
        0,
    );
    let (est, se) = param(&v, "offset");
    assert!((est - 0.3).abs() < 3.0 * se, "offset {est} ± {se}");
    assert!(v["notes"]["offset"].is_null(), "{v}");
}
