//! `jitterid validate` through the real binary: the JSON verdicts, the frequency-response CSV
//! and the figures of a fitted model, and bad input named with exit status 2.

mod common;

use common::{example, files_in, run, s, scratch, stderr, stdout};
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
    // A ragged covariance: refused by name, not read as a model without one.
    let mut m: Value =
        serde_json::from_str(&stdout(&run(&["fit", &exp, "--data", s(&data), "--json"]))).unwrap();
    m["covariance"][2].as_array_mut().unwrap().pop();
    std::fs::write(&wrong, m.to_string()).unwrap();
    refused(
        validate(&wrong, None),
        "covariance: row 3 has 3 entries, expected 4",
    );
    m["covariance"].as_array_mut().unwrap().pop();
    std::fs::write(&wrong, m.to_string()).unwrap();
    refused(validate(&wrong, None), "covariance: expected 4 rows");
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

/// Checks that `svg` is one `<svg>` element whose tags all close in order (the text is escaped,
/// so every `<` opens a tag).
fn assert_well_formed(name: &str, svg: &str) {
    assert!(
        svg.starts_with("<svg ") && svg.ends_with("</svg>\n"),
        "{name}"
    );
    let mut open: Vec<&str> = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find('<') {
        let end = rest[i..]
            .find('>')
            .unwrap_or_else(|| panic!("{name}: unclosed tag"));
        let tag = &rest[i + 1..i + end];
        rest = &rest[i + end + 1..];
        if let Some(closing) = tag.strip_prefix('/') {
            assert_eq!(
                open.pop(),
                Some(closing.trim()),
                "{name}: </{closing}> closes another tag"
            );
        } else if !tag.ends_with('/') {
            open.push(tag.split_whitespace().next().unwrap());
        }
    }
    assert!(open.is_empty(), "{name}: unclosed {open:?}");
}

/// The number of points of each polyline drawn in `color` (without a dash pattern).
fn solid_lines(svg: &str, color: &str) -> Vec<usize> {
    svg.lines()
        .filter(|l| l.starts_with("<polyline") && l.contains(&format!("stroke=\"{color}\"")))
        .filter(|l| !l.contains("stroke-dasharray"))
        .map(|l| {
            l.split("points=\"")
                .nth(1)
                .unwrap()
                .split_whitespace()
                .count()
        })
        .collect()
}

const BLUE: &str = "#1f77b4";
const RED: &str = "#d62728";

#[test]
fn validate_plot_draws_four_figures_written_with_the_other_outputs() {
    let dir = scratch("validate-plot");
    let (data, other) = (dir.join("d.csv"), dir.join("v.csv"));
    let exp = example("table2.toml");
    assert!(run(&["simulate", &exp, "--out", s(&data)]).status.success());
    assert!(run(&["simulate", &exp, "--run", "1", "--out", s(&other)])
        .status
        .success());
    let (figs, bode, out) = (dir.join("figs"), dir.join("b.csv"), dir.join("r.json"));
    let validate = |extra: &[&str], out: &std::path::Path, figs: &std::path::Path| {
        let mut args = vec!["validate", exp.as_str(), "--data", s(&data)];
        args.extend(extra);
        args.extend(["--bode", s(&bode), "--out", s(out), "--plot", s(figs)]);
        run(&args)
    };
    let o = validate(&["--validation", s(&other)], &out, &figs);
    assert!(o.status.success(), "{}", stderr(&o));
    // Each command's figures in a subfolder named after it.
    assert_eq!(files_in(&figs), ["validate"]);
    let figs = figs.join("validate");
    assert_eq!(
        files_in(&figs),
        ["bode.svg", "correlations.svg", "step.svg", "time.svg"]
    );
    let read = |f: &str| {
        let t = std::fs::read_to_string(figs.join(f)).unwrap();
        assert_well_formed(f, &t);
        t
    };
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();

    // Model vs data: one m_k line per record (200 samples each) over its 200 data points, the
    // fit percent in the legend.
    let time = read("time.svg");
    assert_eq!(solid_lines(&time, BLUE), [200, 200]);
    assert!(time.matches("<circle").count() >= 400);
    for record in ["estimation", "validation"] {
        let fit = j["fit_percent"][record].as_f64().unwrap();
        assert!(time.contains(&format!("fit {fit:.1} %")), "{record}");
    }

    // Correlations: autocorrelation (lags 1..=25) and cross-correlation (0..=25) of both
    // records, each with its two dashed 99 % bounds at ±bound.
    let corr = read("correlations.svg");
    let bounds = corr
        .lines()
        .filter(|l| l.starts_with("<polyline") && l.contains(RED) && l.contains("dasharray"))
        .count();
    assert_eq!(bounds, 8);
    let stems = corr.matches(r#"stroke-width="2"/><circle"#).count();
    assert_eq!(stems, 2 * (25 + 26));
    let bound = j["whiteness"]["bound"].as_f64().unwrap();
    assert!(corr.contains(&format!("99 % bounds ±{bound:.3}")));

    // Bode: magnitude and phase lines on the CSV's 200 frequencies, each with its band.
    let b = read("bode.svg");
    let rows = std::fs::read_to_string(&bode).unwrap().lines().count() - 1;
    assert_eq!(solid_lines(&b, BLUE), [rows, rows]);
    assert_eq!(b.matches("<path ").count(), 2);
    // Step response with its band.
    let st = read("step.svg");
    assert_eq!(solid_lines(&st, BLUE), [200]);
    assert_eq!(st.matches("<path ").count(), 1);

    // Without a validation record: one panel per figure row, the estimation record's.
    let one = dir.join("one");
    let o = validate(&[], &out, &one);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = std::fs::read_to_string(one.join("validate/time.svg")).unwrap();
    assert_eq!(solid_lines(&t, BLUE), [200]);
    assert!(!t.contains("validation record"));

    // A model without a covariance: the same curves, no bands, and a note that says so.
    let (fit, bare) = (dir.join("fit.json"), dir.join("bare"));
    let o = run(&["fit", &exp, "--data", s(&data), "--json"]);
    let mut m: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert!(m.as_object_mut().unwrap().remove("covariance").is_some());
    std::fs::write(&fit, m.to_string()).unwrap();
    let o = validate(&["--model", s(&fit)], &out, &bare);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["bode.svg", "step.svg"] {
        let t = std::fs::read_to_string(bare.join("validate").join(f)).unwrap();
        assert_well_formed(f, &t);
        assert_eq!(t.matches("<path ").count(), 0, "{f}");
        assert!(t.contains("no covariance, so no bands"), "{f}");
        assert!(!solid_lines(&t, BLUE).is_empty(), "{f}");
    }

    // An --out that cannot be written (a directory): nothing is written, no figure directory.
    let (late, blocked) = (dir.join("late"), dir.join("blocked"));
    std::fs::create_dir(&blocked).unwrap();
    let before = std::fs::read(&bode).unwrap();
    std::fs::remove_file(&bode).unwrap();
    let o = validate(&[], &blocked, &late);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("blocked"), "{}", stderr(&o));
    assert!(!late.exists() && !bode.exists());
    std::fs::write(&bode, before).unwrap();

    // A --plot target that is a regular file: refused by name, nothing written.
    let file = dir.join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    std::fs::remove_file(&out).unwrap();
    let o = validate(&[], &out, &file);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not-a-dir"), "{}", stderr(&o));
    assert!(!out.exists());
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

/// A system fitted with the free response from an unknown initial state: its Bode band comes
/// from the block of the system's own parameters (gain, zero, poles; `G` does not depend on
/// `initial.*`), checked against `G(s) = k (s − z)/((s − p)(s − p̄))` and its log-derivatives
/// written out here. A system with an input delay: its exported model and `--bode` CSV carry
/// the delay, and `--plot` draws its Bode and step figures.
#[test]
fn validate_bode_band_of_a_system_with_a_free_initial_response() {
    use jitterid::num_complex::Complex64;
    let dir = scratch("validate-initial");
    let (data, fit, bode) = (dir.join("d.csv"), dir.join("fit.json"), dir.join("b.csv"));
    let exp = example("initial-state.toml");
    assert!(run(&["simulate", &exp, "--out", s(&data)]).status.success());
    let o = run(&["fit", &exp, "--data", s(&data), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::write(&fit, stdout(&o)).unwrap();
    let m: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let names: Vec<&str> = (0..4)
        .map(|i| m["parameters"][i]["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["gain", "zero0", "pole0.re", "pole0.im"]);
    let th: Vec<f64> = (0..4)
        .map(|i| m["parameters"][i]["estimate"].as_f64().unwrap())
        .collect();
    let c = |i: usize, j: usize| m["covariance"][i][j].as_f64().unwrap();
    let figs = dir.join("figs");
    let args = ["--model", s(&fit), "--bode", s(&bode), "--plot", s(&figs)];
    let o = run(&[&["validate", exp.as_str(), "--data", s(&data)], &args[..]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(files_in(&figs.join("validate")).len(), 4);
    let csv = std::fs::read_to_string(&bode).unwrap();
    for row in csv.lines().skip(1).step_by(40) {
        let v: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
        let s_ = Complex64::new(0.0, v[1]);
        let (z, p) = (th[1], Complex64::new(th[2], th[3]));
        let g = th[0] * (s_ - z) / ((s_ - p) * (s_ - p.conj()));
        // ∂ ln G / ∂θ for θ = (k, z, Re p, Im p).
        let i = Complex64::i();
        let d = [
            Complex64::new(1.0 / th[0], 0.0),
            -1.0 / (s_ - z),
            1.0 / (s_ - p) + 1.0 / (s_ - p.conj()),
            i / (s_ - p) - i / (s_ - p.conj()),
        ];
        let grad: Vec<f64> = d
            .iter()
            .map(|x| 20.0 / std::f64::consts::LN_10 * x.re)
            .collect();
        let var: f64 = (0..4)
            .flat_map(|a| (0..4).map(move |b| (a, b)))
            .map(|(a, b)| grad[a] * c(a, b) * grad[b])
            .sum();
        let db = 20.0 * g.norm().log10();
        // Both routes are closed forms in double precision.
        assert!((v[2] - db).abs() < 1e-9, "{row}: {db}");
        assert!(
            (v[5] - v[2] - 2.0 * var.sqrt()).abs() < 1e-9 * (1.0 + var.sqrt()),
            "{row}"
        );
    }

    // A delayed system: `fit --json`'s model carries the delay, the `--bode` CSV is
    // `G(i2πf) e^{−i2πfD}` (G from the exported `tf`, written out here), and `--plot` adds the
    // Bode and step figures.
    let exp = example("dead-time.toml");
    assert!(run(&["simulate", &exp, "--out", s(&data)]).status.success());
    let o = run(&["fit", &exp, "--data", s(&data), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::write(&fit, stdout(&o)).unwrap();
    let m: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let delay = m["model"]["delay"].as_f64().expect("model.delay");
    let estimate = m["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "delay")
        .unwrap()["estimate"]
        .as_f64()
        .unwrap();
    assert_eq!(delay, estimate);
    let coefficients = |key: &str| -> Vec<f64> {
        m["model"]["tf"][key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (num, den) = (coefficients("num"), coefficients("den"));
    // The table says how the exported pieces combine.
    let o = run(&["fit", &exp, "--data", s(&data)]);
    assert!(
        stdout(&o).contains("model: G(s) e^(-sD) with input delay D = "),
        "{}",
        stdout(&o)
    );
    let polynomial =
        |c: &[f64], s: Complex64| c.iter().fold(Complex64::new(0.0, 0.0), |a, &x| a * s + x);
    let figs = dir.join("delayed");
    let args = ["--model", s(&fit), "--bode", s(&bode), "--plot", s(&figs)];
    let o = run(&[&["validate", exp.as_str(), "--data", s(&data)], &args[..]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        files_in(&figs.join("validate")),
        ["bode.svg", "correlations.svg", "step.svg", "time.svg"]
    );
    let csv = std::fs::read_to_string(&bode).unwrap();
    for row in csv.lines().skip(1).step_by(20) {
        let v: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
        let s_ = Complex64::new(0.0, v[1]);
        let h = polynomial(&num, s_) / polynomial(&den, s_) * (-s_ * delay).exp();
        assert!((v[2] - 20.0 * h.norm().log10()).abs() < 1e-9, "{row}");
        // The CSV's phase is unwrapped along the grid: arg H up to whole turns.
        let turns = (v[3] - h.arg().to_degrees()) / 360.0;
        assert!((turns - turns.round()).abs() < 1e-9, "{row}");
        // The band includes the delay's share (the phase band widens with f).
        assert!(v[7] > v[3] && v[6] < v[3], "{row}");
    }
}

/// `validate --input FILE` reads a record's input from a file of another name, as `fit` does;
/// the JSON carries each test's statistic, degrees of freedom, p-value and level, and the
/// verdict follows the p-value at `--level`; a level outside (0, 1) is refused with the flag
/// and the value named, exit status 2.
#[test]
fn validate_input_file_level_and_portmanteau_fields() {
    let dir = scratch("validate-input");
    let data = dir.join("d.csv");
    let exp = example("validate-one-pole.toml");
    let truth = example("validate-true.toml");
    assert!(run(&["simulate", &truth, "--out", s(&data)])
        .status
        .success());
    let moved = dir.join("u-elsewhere.csv");
    std::fs::rename(dir.join("d.input.csv"), &moved).unwrap();
    // Without the side file and without --input: the missing file is named.
    let o = run(&["validate", &exp, "--data", s(&data)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("d.input.csv"), "{}", stderr(&o));
    // With the input file given, at the default level and at a chosen one.
    let at_level = |level: Option<&str>| {
        let mut args = vec![
            "validate",
            exp.as_str(),
            "--data",
            s(&data),
            "--input",
            s(&moved),
            "--json",
        ];
        if let Some(l) = level {
            args.extend(["--level", l]);
        }
        run(&args)
    };
    let o = at_level(None);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(j["level"], 0.01);
    // A one-pole model of a 2-pole, 1-zero system: Ljung's S on the cross-correlation with the
    // input rejects it (on this record S ≈ 230 against 26 degrees of freedom).
    let c = &j["cross_correlation"];
    assert_eq!(c["test"], "ljung-s");
    assert_eq!(c["dof"], 26);
    let p = c["p_value"].as_f64().unwrap();
    assert!(p < 0.01, "{c}");
    assert_eq!(c["passed"], false);
    let w = &j["whiteness"];
    assert_eq!(w["test"], "ljung-box");
    assert_eq!(w["dof"], 25);
    assert!(w["statistic"].as_f64().unwrap() > 0.0);
    // The verdict is the p-value against the level: a level below the p-value passes.
    let o = at_level(Some(&format!("{:e}", p / 2.0)));
    assert!(o.status.success(), "{}", stderr(&o));
    let j: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(j["cross_correlation"]["passed"], true, "{j}");
    for bad in ["0", "1", "1.5", "-0.2", "NaN"] {
        let o = at_level(Some(bad));
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("--level") && e.contains(bad), "{bad}: {e}");
    }
}
