//! Runs the built `jitterid` binary on every example experiment and on bad input.

mod common;

use common::{files_in, run, s, scratch, stderr, stdout};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "jitterid {args:?} failed: {}",
        stderr(&o)
    );
    stdout(&o)
}

fn json(args: &[&str]) -> Value {
    let text = ok(args);
    serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("jitterid {args:?}: not JSON ({e}): {text}"))
}

fn examples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/experiments");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/experiments")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn the_examples_are_all_there() {
    let names: Vec<String> = examples()
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for want in [
        "table2.toml",
        "table1-uniform-n0-a0.5.toml",
        "table1-uniform-n0-a0.289.toml",
        "table1-uniform-n2-a0.5.toml",
        "table1-uniform-n2-a0.289.toml",
        "table1-gaussian-sigma0.167.toml",
        "table1-gaussian-sigma0.0962.toml",
        "ls-bias.toml",
        "sine.toml",
    ] {
        assert!(names.iter().any(|n| n == want), "missing example {want}");
    }
}

/// The method an example file names (`bcls` unless it says `method = "bj"` or `"ml"`).
fn method_of(exp: &Path) -> &'static str {
    let text = std::fs::read_to_string(exp).unwrap();
    ["bj", "ml"]
        .into_iter()
        .find(|m| text.contains(&format!("method = \"{m}\"")))
        .unwrap_or("bcls")
}

#[test]
fn simulate_then_fit_every_example() {
    let dir = scratch("round-trip");
    for exp in examples() {
        let stem = exp.file_stem().unwrap().to_string_lossy().into_owned();
        let data = dir.join(format!("{stem}.csv"));
        let report = ok(&[
            "simulate",
            s(&exp),
            "--seed",
            "7",
            "--out",
            s(&data),
            "--truth",
        ]);
        assert!(report.contains("samples"), "{report}");
        let text = std::fs::read_to_string(&data).unwrap();
        let header = text.lines().next().unwrap();
        assert!(header.starts_with("k,t,y"), "{header}");
        assert!(header.ends_with("tau,v"), "{header}");
        let fit = json(&["fit", s(&exp), "--data", s(&data), "--json"]);
        assert_eq!(fit["method"], method_of(&exp), "{stem}");
        assert!(fit["converged"].as_bool().unwrap(), "{stem}: {fit}");
        let params = fit["parameters"].as_array().unwrap();
        assert!(!params.is_empty(), "{stem}");
        for p in params {
            assert!(
                p["name"].is_string() && p["estimate"].is_number(),
                "{stem}: {p}"
            );
        }
        // The readable table has the same parameters.
        let table = ok(&["fit", s(&exp), "--data", s(&data)]);
        for p in params {
            assert!(table.contains(p["name"].as_str().unwrap()), "{table}");
        }
    }
    // The random-binary input went to the side file.
    assert!(dir.join("table2.input.csv").exists());
    assert!(!dir.join("sine.input.csv").exists());
}

#[test]
fn table2_fit_is_close_to_the_truth_and_plots() {
    let dir = scratch("table2-fit");
    let data = dir.join("d.csv");
    ok(&[
        "simulate",
        &example("table2.toml"),
        "--seed",
        "3",
        "--out",
        s(&data),
    ]);
    let figures = dir.join("figures");
    let plots = figures.join("fit");
    let fit = json(&[
        "fit",
        &example("table2.toml"),
        "--data",
        s(&data),
        "--json",
        "--plot",
        s(&figures),
    ]);
    let truth = [0.2, -0.5, -0.25, 0.3];
    let names = ["gain", "zero0", "pole0.re", "pole0.im"];
    let params = fit["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 4);
    for ((p, t), n) in params.iter().zip(truth).zip(names) {
        assert_eq!(p["name"], n);
        let e = p["estimate"].as_f64().unwrap();
        let se = p["stderr"].as_f64().unwrap();
        assert!((e - t).abs() < 5.0 * se, "{n}: {e} ± {se} vs {t}");
    }
    assert_eq!(
        files_in(&plots),
        [
            "bode.svg",
            "jitter-pdf.svg",
            "moment.svg",
            "residuals.svg",
            "spectrum.svg",
            "step.svg"
        ]
    );
    for f in files_in(&plots) {
        let svg = std::fs::read_to_string(plots.join(&f)).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{f}"
        );
        assert!(svg.contains("<polyline"), "{f} draws no curve");
    }
    let bode = std::fs::read_to_string(plots.join("bode.svg")).unwrap();
    assert!(bode.contains("naive LS") && bode.contains("bcls") && bode.contains("data Y/U"));
    // Naive LS on the same data, by the command-line override.
    let ls = json(&[
        "fit",
        &example("table2.toml"),
        "--data",
        s(&data),
        "--json",
        "--method",
        "ls",
    ]);
    assert_eq!(ls["method"], "ls");
}

#[test]
fn fit_reads_the_input_from_the_side_file_or_input_flag() {
    let dir = scratch("side-file");
    let data = dir.join("d.csv");
    ok(&["simulate", &example("table2.toml"), "--out", s(&data)]);
    let a = json(&["fit", &example("table2.toml"), "--data", s(&data), "--json"]);
    let moved = dir.join("other-name.csv");
    std::fs::rename(dir.join("d.input.csv"), &moved).unwrap();
    let o = run(&["fit", &example("table2.toml"), "--data", s(&data)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("d.input.csv"), "{}", stderr(&o));
    let b = json(&[
        "fit",
        &example("table2.toml"),
        "--data",
        s(&data),
        "--json",
        "--input",
        s(&moved),
    ]);
    assert_eq!(a["parameters"], b["parameters"]);
}

#[test]
fn simulate_is_montecarlo_realisation() {
    // The same seed and run index give the same record.
    let dir = scratch("seeded");
    let a = dir.join("a.csv");
    let b = dir.join("b.csv");
    let c = dir.join("c.csv");
    ok(&[
        "simulate",
        &example("table2.toml"),
        "--seed",
        "11",
        "--run",
        "2",
        "--out",
        s(&a),
    ]);
    ok(&[
        "simulate",
        &example("table2.toml"),
        "--seed",
        "11",
        "--run",
        "2",
        "--out",
        s(&b),
    ]);
    ok(&[
        "simulate",
        &example("table2.toml"),
        "--seed",
        "11",
        "--run",
        "3",
        "--out",
        s(&c),
    ]);
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    assert_eq!(read(&a), read(&b));
    assert_ne!(read(&a), read(&c));
}

#[test]
fn montecarlo_every_example() {
    for exp in examples() {
        let stem = exp.file_stem().unwrap().to_string_lossy().into_owned();
        // Table 1 profiles n over ten values per fit: fewer runs keep the debug build quick.
        let runs = if stem.starts_with("table1") { "2" } else { "4" };
        let j = json(&[
            "montecarlo",
            s(&exp),
            "--runs",
            runs,
            "--seed",
            "5",
            "--json",
        ]);
        assert_eq!(j["runs"].as_u64().unwrap().to_string(), runs, "{stem}");
        assert_eq!(j["method"], method_of(&exp), "{stem}");
        assert!(j["seconds"].as_f64().unwrap() >= 0.0);
        assert!(j["converged"].as_u64().unwrap() >= 1, "{stem}: {j}");
        let params = j["parameters"].as_array().unwrap();
        assert!(!params.is_empty());
        for p in params {
            for k in ["name", "true", "mean", "std", "se", "rmse"] {
                assert!(p.get(k).is_some(), "{stem}: {k} missing in {p}");
            }
        }
        if stem.starts_with("table1") {
            let names: Vec<&str> = params.iter().map(|p| p["name"].as_str().unwrap()).collect();
            assert_eq!(names, ["jitter.n", "jitter.a", "jitter.sigma"]);
            assert!(params[2]["true"].is_number());
            if stem.contains("gaussian") {
                assert!(params[0]["true"].is_null() && params[1]["true"].is_null());
            }
        }
    }
}

#[test]
fn table2_parameters_are_in_model_order() {
    let j = json(&[
        "montecarlo",
        &example("table2.toml"),
        "--runs",
        "2",
        "--json",
    ]);
    let names: Vec<&str> = j["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["gain", "zero0", "pole0.re", "pole0.im"]);
    let truth: Vec<f64> = j["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["true"].as_f64().unwrap())
        .collect();
    assert_eq!(truth, [0.2, -0.5, -0.25, 0.3]);
}

#[test]
fn montecarlo_does_not_depend_on_threads() {
    let one = json(&[
        "montecarlo",
        &example("table2.toml"),
        "--runs",
        "6",
        "--seed",
        "9",
        "--threads",
        "1",
        "--json",
    ]);
    let two = json(&[
        "montecarlo",
        &example("table2.toml"),
        "--runs",
        "6",
        "--seed",
        "9",
        "--threads",
        "2",
        "--json",
    ]);
    assert_eq!(one["parameters"], two["parameters"]);
    assert_eq!(one["converged"], two["converged"]);
}

#[test]
fn shards_merge_to_the_unsharded_study() {
    let dir = scratch("shards");
    let exp = example("table2.toml");
    let whole = json(&["montecarlo", &exp, "--runs", "7", "--seed", "4", "--json"]);
    let s0 = dir.join("s0.json");
    let s1 = dir.join("s1.json");
    ok(&[
        "montecarlo",
        &exp,
        "--runs",
        "7",
        "--seed",
        "4",
        "--json",
        "--shard",
        "0/2",
        "--out",
        s(&s0),
    ]);
    ok(&[
        "montecarlo",
        &exp,
        "--runs",
        "7",
        "--seed",
        "4",
        "--json",
        "--shard",
        "1/2",
        "--out",
        s(&s1),
    ]);
    let shard0: Value = serde_json::from_str(&std::fs::read_to_string(&s0).unwrap()).unwrap();
    assert_eq!(shard0["runs"], 3);
    assert_eq!(shard0["realizations"].as_array().unwrap().len(), 3);
    let merged = json(&["merge", s(&s1), s(&s0), "--json"]);
    assert_eq!(merged["parameters"], whole["parameters"]);
    assert_eq!(merged["runs"], 7);
    assert_eq!(merged["converged"], whole["converged"]);
    // A missing shard is an error.
    let o = run(&["merge", s(&s0)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("shard 1/2 is missing"),
        "{}",
        stderr(&o)
    );
    // The table form works too.
    assert!(ok(&["merge", s(&s0), s(&s1)]).contains("pole0.im"));
}

/// The wall time is the one thing that differs between two runs of the same study: by
/// default it is there (`seconds`, the keys unchanged), and `--no-timing` leaves it out, so that
/// the two runs' JSON (and a merge of their shards) are equal byte for byte.
#[test]
fn no_timing_makes_identical_studies_identical_bytes() {
    let exp = example("table2.toml");
    let args = ["montecarlo", &exp, "--runs", "3", "--seed", "5", "--json"];
    let timed = json(&args);
    assert!(
        timed["seconds"].as_f64().is_some_and(|s| s >= 0.0),
        "{timed}"
    );
    let with = |extra: &[&str]| {
        let mut v = args.to_vec();
        v.extend_from_slice(extra);
        ok(&v)
    };
    let (a, b) = (with(&["--no-timing"]), with(&["--no-timing"]));
    assert_eq!(a, b);
    let untimed: Value = serde_json::from_str(&a).unwrap();
    let mut keys: Vec<&String> = timed.as_object().unwrap().keys().collect();
    keys.retain(|k| *k != "seconds");
    assert_eq!(
        untimed.as_object().unwrap().keys().collect::<Vec<_>>(),
        keys
    );
    assert_eq!(untimed["parameters"], timed["parameters"]);
    // The table leaves the time out too.
    let table = |extra: &[&str]| {
        let mut v = vec!["montecarlo", &exp, "--runs", "3", "--seed", "5"];
        v.extend_from_slice(extra);
        ok(&v)
    };
    assert_eq!(table(&["--no-timing"]), table(&["--no-timing"]));
    // Shards: a merge of timed shards sums their times unless told not to; a merge of
    // untimed shards has none.
    let dir = scratch("no-timing");
    let shard = |i: &str, name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut v = vec!["montecarlo", &exp, "--runs", "3", "--seed", "5", "--json"];
        v.extend_from_slice(&["--shard", i, "--out", s(&out)]);
        v.extend_from_slice(extra);
        ok(&v);
        out
    };
    let (t0, t1) = (shard("0/2", "t0.json", &[]), shard("1/2", "t1.json", &[]));
    let (u0, u1) = (
        shard("0/2", "u0.json", &["--no-timing"]),
        shard("1/2", "u1.json", &["--no-timing"]),
    );
    assert!(json(&["merge", s(&t0), s(&t1), "--json"])["seconds"].is_f64());
    let m1 = ok(&["merge", s(&t0), s(&t1), "--json", "--no-timing"]);
    let m2 = ok(&["merge", s(&u0), s(&u1), "--json"]);
    assert_eq!(m1, m2);
    assert_eq!(m1, a);
}

#[test]
fn montecarlo_plots() {
    let dir = scratch("mc-plots");
    let p1 = dir.join("table2");
    ok(&[
        "montecarlo",
        &example("table2.toml"),
        "--runs",
        "4",
        "--plot",
        s(&p1),
    ]);
    assert_eq!(
        files_in(&p1.join("montecarlo")),
        ["bode.svg", "histograms.svg", "moment.svg"]
    );
    let p2 = dir.join("table1");
    ok(&[
        "montecarlo",
        &example("table1-uniform-n2-a0.5.toml"),
        "--runs",
        "2",
        "--plot",
        s(&p2),
    ]);
    let p2 = p2.join("montecarlo");
    assert_eq!(
        files_in(&p2),
        ["histograms.svg", "jitter-pdf.svg", "moment.svg"]
    );
    let h = std::fs::read_to_string(p2.join("histograms.svg")).unwrap();
    assert!(h.contains("jitter.sigma") && h.contains("<rect"));
}

/// A small Table-1-like experiment whose maximum-likelihood fit is quick in a debug build.
const SMALL_ML: &str = r#"[sampling]
interval = 1.0
samples = 40
[input]
kind = "random-binary"
mean_dwell = 4.0
[system]
kind = "zpk"
gain = 1.0
poles = [-2.0]
[jitter]
family = "uniform-sum"
n = 0
a = 0.4
estimate = true
n_range = [0, 0]
[noise]
std = 0.01
[estimate]
method = "ml"
"#;

#[cfg(feature = "ml")]
#[test]
fn ml_fits() {
    let dir = scratch("ml");
    let exp = dir.join("ml.toml");
    std::fs::write(&exp, SMALL_ML).unwrap();
    let data = dir.join("d.csv");
    ok(&["simulate", s(&exp), "--seed", "2", "--out", s(&data)]);
    let fit = json(&["fit", s(&exp), "--data", s(&data), "--json"]);
    assert_eq!(fit["method"], "ml");
    assert!(fit["converged"].as_bool().unwrap(), "{fit}");
    let p = fit["parameters"].as_array().unwrap();
    let names: Vec<&str> = p.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["jitter.n", "jitter.a", "jitter.sigma"]);
    let (a, se) = (
        p[1]["estimate"].as_f64().unwrap(),
        p[1]["stderr"].as_f64().unwrap(),
    );
    assert!((a - 0.4).abs() < 5.0 * se, "{a} ± {se}");
    // The same data by BCLS, through the command-line override.
    let b = json(&[
        "fit",
        s(&exp),
        "--data",
        s(&data),
        "--json",
        "--method",
        "bcls",
    ]);
    assert_eq!(b["method"], "bcls");
}

#[cfg(not(feature = "ml"))]
#[test]
fn ml_is_accepted_in_files_but_not_available() {
    let dir = scratch("ml");
    let exp = dir.join("ml.toml");
    std::fs::write(&exp, SMALL_ML).unwrap();
    let data = dir.join("d.csv");
    ok(&["simulate", s(&exp), "--out", s(&data)]);
    for args in [
        vec!["fit", s(&exp), "--data", s(&data)],
        vec!["fit", s(&exp), "--data", s(&data), "--method", "ml"],
        vec!["montecarlo", s(&exp), "--runs", "2"],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = stderr(&o);
        assert_eq!(e.trim_end().lines().count(), 1, "{e}");
        assert!(e.contains("maximum likelihood is not available"), "{e}");
    }
}

#[test]
fn help_and_version() {
    for sub in [
        &[][..],
        &["simulate"],
        &["fit"],
        &["montecarlo"],
        &["merge"],
        &["design"],
    ] {
        let mut args: Vec<&str> = sub.to_vec();
        args.push("--help");
        let out = ok(&args);
        assert!(out.contains("Usage"), "{out}");
    }
    assert!(ok(&["--version"]).starts_with("jitterid "));
    let o = run(&["fit", "x.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(stderr(&o).trim_end().lines().count(), 1, "{}", stderr(&o));
}

/// Experiments that exercise the other kinds, families, noise models and solvers.
const KINDS: &[(&str, &str, &[&str])] = &[
    (
        "tf-multisine-laplace",
        r#"[sampling]
interval = 0.5
samples = 120
start = 1.0
[input]
kind = "multisine"
frequencies = [0.05, 0.13, 0.31]
amplitudes = [1.0, 0.5, 0.5]
[system]
kind = "tf"
num = [1.0]
den = [1.0, 1.2, 1.0]
estimate = true
[jitter]
family = "laplace"
scale = 0.05
estimate = true
[noise]
std = 0.01
estimate = true
[estimate]
solver = "nelder-mead"
max_iterations = 3000
"#,
        &["b0", "a1", "a0", "jitter.b", "noise.std"],
    ),
    (
        "piecewise-two-point-band",
        r#"[sampling]
interval = 1.0
samples = 60
[input]
kind = "piecewise"
times = [0.0, 10.0, 25.0, 40.0]
values = [1.0, -1.0, 0.5, 0.0]
[system]
kind = "zpk"
gain = 1.0
poles = [-0.5, -1.5]
estimate = true
[jitter]
family = "two-point"
d = 0.1
[noise]
std = 0.01
[estimate]
frequencies = { min = 0.0, max = 0.3 }
solver = "gauss-newton"
multistart = 2
multistart_radius = 0.3
"#,
        &["gain", "pole0", "pole1"],
    ),
    (
        "csv-input-shifted-exponential",
        r#"[sampling]
interval = 1.0
samples = 60
[input]
kind = "csv"
path = "u.csv"
[system]
kind = "zpk"
gain = 0.5
poles = [-0.5]
estimate = true
[jitter]
family = "exponential"
mean = 0.1
offset = -0.1
estimate = true
[noise]
std = 0.005
"#,
        &["gain", "pole0", "jitter.offset", "jitter.mean"],
    ),
    (
        "bj-arma",
        r#"[sampling]
interval = 1.0
samples = 100
[input]
kind = "random-binary"
mean_dwell = 4.0
[system]
kind = "zpk"
gain = 1.0
poles = [-1.0]
estimate = true
[jitter]
family = "gaussian"
sigma = 0.1
[noise]
std = 0.02
model = "arma"
d = [-0.7]
estimate = true
[estimate]
method = "bj"
frequencies = [0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4]
"#,
        &["gain", "pole0", "noise.d1", "noise.std"],
    ),
];

#[test]
fn other_kinds_families_noise_models_and_solvers() {
    let dir = scratch("kinds");
    std::fs::write(
        dir.join("u.csv"),
        "t,u\n0.0,0.0\n3.0,1.0\n17.5,0.0\n30.0,1.0\n50.0,0.0\n",
    )
    .unwrap();
    for (name, text, names) in KINDS {
        let exp = dir.join(format!("{name}.toml"));
        std::fs::write(&exp, text).unwrap();
        let data = dir.join(format!("{name}.csv"));
        ok(&["simulate", s(&exp), "--out", s(&data)]);
        // Names are checked here, not convergence (a Laplace width estimated on data with
        // little jitter runs to its bound), so an unconverged fit is accepted.
        let fit = json(&[
            "fit",
            s(&exp),
            "--data",
            s(&data),
            "--json",
            "--accept-unconverged",
        ]);
        let got: Vec<&str> = fit["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].as_str().unwrap())
            .collect();
        assert_eq!(&got, names, "{name}");
        let mc = json(&[
            "montecarlo",
            s(&exp),
            "--runs",
            "2",
            "--json",
            "--accept-unconverged",
        ]);
        let got: Vec<&str> = mc["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["name"].as_str().unwrap())
            .collect();
        assert_eq!(&got, names, "{name}");
    }
}

// ---------------------------------------------------------------------------------------------
// Bad input: exit status 2, one line naming the file and the line or key, no output left.

const GOOD: &str = r#"[sampling]
interval = 1.0
samples = 50

[input]
kind = "random-binary"
mean_dwell = 8.0

[system]
kind = "zpk"
gain = 0.2
zeros = [-0.5]
poles = [[-0.25, 0.3]]
estimate = true

[jitter]
family = "uniform-sum"
n = 2
a = 0.3

[noise]
std = 0.01
"#;

/// Runs `simulate` on an experiment text; asserts failure with one line containing `want`, and
/// that the output directory stayed empty.
fn bad_experiment(name: &str, text: &str, want: &[&str]) {
    let dir = scratch(&format!("bad-exp-{name}"));
    let exp = dir.join("exp.toml");
    std::fs::write(&exp, text).unwrap();
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    let data = out_dir.join("data.csv");
    let o = run(&["simulate", s(&exp), "--out", s(&data)]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {e}");
    assert_eq!(e.trim_end().lines().count(), 1, "{name}: not one line: {e}");
    assert!(e.starts_with("error: "), "{name}: {e}");
    assert!(e.contains("exp.toml"), "{name}: file not named: {e}");
    for w in want {
        assert!(e.contains(w), "{name}: `{w}` not in: {e}");
    }
    assert!(
        files_in(&out_dir).is_empty(),
        "{name}: left {:?}",
        files_in(&out_dir)
    );
}

#[test]
fn the_good_experiment_is_good() {
    let dir = scratch("good");
    let exp = dir.join("exp.toml");
    std::fs::write(&exp, GOOD).unwrap();
    ok(&["simulate", s(&exp), "--out", s(&dir.join("d.csv"))]);
}

#[test]
fn bad_experiment_files() {
    bad_experiment(
        "malformed",
        &GOOD.replace("[system]", "[system"),
        &["exp.toml:9:"],
    );
    bad_experiment(
        "unknown-key",
        &GOOD.replace("gain = 0.2", "gian = 0.2"),
        &["exp.toml:11:", "gian", "did you mean `gain`"],
    );
    bad_experiment(
        "unknown-section",
        &format!("{GOOD}\n[estimat]\nmethod = \"ls\"\n"),
        &["estimat"],
    );
    bad_experiment(
        "key-of-other-kind",
        &GOOD.replace("gain = 0.2", "gain = 0.2\nnum = [1.0]"),
        &["exp.toml:12:", "[system] num", "zpk"],
    );
    bad_experiment(
        "wrong-type",
        &GOOD.replace("samples = 50", "samples = \"50\""),
        &["exp.toml:3:", "samples"],
    );
    bad_experiment(
        "wrong-type-float",
        &GOOD.replace("samples = 50", "samples = 50.5"),
        &["exp.toml:3:", "samples"],
    );
    bad_experiment(
        "missing-value",
        &GOOD.replace("gain = 0.2\n", ""),
        &["exp.toml:9:", "[system] gain", "missing"],
    );
    bad_experiment(
        "missing-section",
        &GOOD.replace("[sampling]\ninterval = 1.0\nsamples = 50\n", ""),
        &["[sampling]"],
    );
    bad_experiment(
        "nan",
        &GOOD.replace("gain = 0.2", "gain = nan"),
        &["exp.toml:11:", "gain", "finite"],
    );
    bad_experiment(
        "negative",
        &GOOD.replace("interval = 1.0", "interval = -1.0"),
        &["exp.toml:2:", "interval", "> 0"],
    );
    bad_experiment(
        "unstable",
        &GOOD.replace("[[-0.25, 0.3]]", "[[0.25, 0.3]]"),
        &["exp.toml:13:", "poles", "stable"],
    );
    // Structural integrators: more than the poles at the origin, or more than the poles.
    bad_experiment(
        "integrators-at-origin",
        &GOOD.replace("estimate = true\n", "estimate = true\nintegrators = 1\n"),
        &[
            "exp.toml:15:",
            "integrators",
            "`integrators` = 1",
            "0 of them",
        ],
    );
    bad_experiment(
        "integrators-too-many",
        &GOOD.replace("estimate = true\n", "estimate = true\nintegrators = 3\n"),
        &["exp.toml:15:", "integrators", "[0, 2]", "found 3"],
    );
    bad_experiment(
        "bad-pair",
        &GOOD.replace("[[-0.25, 0.3]]", "[[-0.25, -0.3]]"),
        &["exp.toml:13:", "poles", "im > 0"],
    );
    bad_experiment(
        "unknown-family",
        &GOOD.replace("uniform-sum", "uniform"),
        &["exp.toml:17:", "family", "uniform-sum"],
    );
    bad_experiment(
        "unknown-kind",
        &GOOD.replace("\"zpk\"", "\"ss\""),
        &["exp.toml:10:", "kind"],
    );
    bad_experiment(
        "bad-method",
        &format!("{GOOD}\n[estimate]\nmethod = \"mle\"\n"),
        &["exp.toml:25:", "method"],
    );
    bad_experiment(
        "bad-frequencies",
        &format!("{GOOD}\n[estimate]\nfrequencies = {{ min = 0.1, maks = 0.2 }}\n"),
        &["exp.toml:25:", "frequencies", "maks"],
    );
    bad_experiment("not-utf8", "[sampling]\ninterval = \u{0}\n", &["exp.toml"]);
    bad_experiment("empty", "", &["[sampling]"]);
    bad_experiment("input-for-sinusoid", "[sampling]\ninterval = 1.0\nsamples = 8\n[system]\nkind = \"sinusoid\"\namplitude = 1.0\nfrequency = 0.1\n[input]\nkind = \"sine\"\nfrequency = 0.1\n", &["[input]"]);
    // A file that does not exist.
    let dir = scratch("bad-exp-missing-file");
    let o = run(&[
        "simulate",
        s(&dir.join("nope.toml")),
        "--out",
        s(&dir.join("d.csv")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("nope.toml: cannot read: file does not exist"),
        "{}",
        stderr(&o)
    );
    assert!(files_in(&dir).is_empty());
}

/// Runs `fit --plot` on a data text; asserts failure with one line containing `want`, and no
/// figure written.
fn bad_data(name: &str, csv: &str, want: &[&str]) {
    let dir = scratch(&format!("bad-data-{name}"));
    let exp = dir.join("exp.toml");
    std::fs::write(
        &exp,
        GOOD.replace(
            "kind = \"random-binary\"\nmean_dwell = 8.0",
            "kind = \"sine\"\nfrequency = 0.05",
        ),
    )
    .unwrap();
    let data = dir.join("data.csv");
    std::fs::write(&data, csv).unwrap();
    let plots = dir.join("figs");
    let o = run(&["fit", s(&exp), "--data", s(&data), "--plot", s(&plots)]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {e}");
    assert_eq!(e.trim_end().lines().count(), 1, "{name}: not one line: {e}");
    assert!(e.contains("data.csv"), "{name}: file not named: {e}");
    for w in want {
        assert!(e.contains(w), "{name}: `{w}` not in: {e}");
    }
    assert!(o.stdout.is_empty(), "{name}: printed {}", stdout(&o));
    assert!(
        files_in(&plots).is_empty(),
        "{name}: left {:?}",
        files_in(&plots)
    );
}

/// `text` with its (1-based) line `n` replaced.
fn with_line(text: &str, n: usize, new: &str) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == n {
                new.to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

fn good_csv(n: usize) -> String {
    let mut s = String::from("k,t,y\n");
    for k in 0..n {
        s.push_str(&format!("{k},{k}.0,{}\n", (k as f64 * 0.3).sin()));
    }
    s
}

#[test]
fn bad_data_files() {
    let good = good_csv(50);
    // The good file fits (the sine input keeps the example free of side files).
    {
        let dir = scratch("good-data");
        let exp = dir.join("exp.toml");
        std::fs::write(
            &exp,
            GOOD.replace(
                "kind = \"random-binary\"\nmean_dwell = 8.0",
                "kind = \"sine\"\nfrequency = 0.05",
            ),
        )
        .unwrap();
        let data = dir.join("data.csv");
        std::fs::write(&data, &good).unwrap();
        ok(&["fit", s(&exp), "--data", s(&data)]);
    }
    bad_data(
        "header",
        &good.replacen("k,t,y", "k,t,x", 1),
        &["data.csv:1:", "header", "`y`"],
    );
    bad_data(
        "no-header",
        &good.replacen("k,t,y\n", "", 1),
        &["data.csv:1:", "header"],
    );
    bad_data(
        "non-numeric",
        &with_line(&good, 7, "5,5.0,abc"),
        &["data.csv:7:", "column `y`", "number", "abc"],
    );
    bad_data(
        "nan",
        &with_line(&good, 5, "3,3.0,NaN"),
        &["data.csv:5:", "column `y`", "finite"],
    );
    bad_data(
        "unequal-columns",
        &with_line(&good, 6, "4,4.0"),
        &["data.csv:6:", "expected 3 cells"],
    );
    bad_data(
        "too-few-rows",
        &good_csv(49),
        &["49 data rows", "expected 50"],
    );
    bad_data(
        "wrong-times",
        &with_line(&good, 9, "7,7.5,0.1"),
        &["data.csv:9:", "column `t`"],
    );
    bad_data(
        "duplicate-column",
        &good.replacen("k,t,y", "k,y,y", 1),
        &["data.csv:1:", "twice"],
    );
    bad_data("empty", "", &["empty"]);
    // A data file that does not exist.
    let dir = scratch("bad-data-missing");
    let o = run(&[
        "fit",
        &example("sine.toml"),
        "--data",
        s(&dir.join("none.csv")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("none.csv: cannot read: file does not exist"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn no_partial_output_when_the_target_cannot_be_written() {
    let dir = scratch("unwritable");
    let o = run(&[
        "simulate",
        &example("table2.toml"),
        "--out",
        s(&dir.join("no/such/dir/d.csv")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(stderr(&o).trim_end().lines().count(), 1);
    assert!(files_in(&dir).is_empty());
}
