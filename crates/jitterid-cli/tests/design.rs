//! `jitterid design` through the real binary: the JSON's shape, the designed experiment no
//! worse than the file's own under the criterion, and bad designs refused with exit status 2
//! and the key named.

mod common;

use common::{example, run, s, scratch, stderr, stdout};

const DWELL: &str = "design.mean_dwell=[1.0, 40.0]";

/// `jitterid design` of Table 2 with the dwell free and a cheap search (2 draws, 3 grid
/// points), then `extra`.
fn cheap_table2(extra: &[&str]) -> std::process::Output {
    let table2 = example("table2.toml");
    let mut args = vec![
        "design",
        table2.as_str(),
        "--set",
        DWELL,
        "--set",
        "design.draws=2",
        "--set",
        "design.grid=3",
    ];
    args.extend_from_slice(extra);
    run(&args)
}

use common::design_refused as refused;

#[test]
fn design_json_has_the_contract_s_keys_and_improves_on_the_baseline() {
    let table2 = example("table2.toml");
    let o = run(&[
        "design",
        &table2,
        "--set",
        DWELL,
        "--set",
        "design.draws=4",
        "--set",
        "design.grid=5",
        "--criterion",
        "param:zero0",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(
        keys,
        ["baseline", "criterion", "derived", "design", "predicted"]
    );
    assert_eq!(v["criterion"], "param:zero0");
    // The static gain's std by the delta method, for both designs (the jitter is known: no σ).
    for d in [&v["derived"], &v["baseline"]["derived"]] {
        assert_eq!(d.as_array().unwrap().len(), 1, "{d}");
        assert_eq!(d[0]["name"], "static_gain");
        assert!(d[0]["std"].as_f64().unwrap() > 0.0, "{d}");
    }
    assert_eq!(v["baseline"]["design"]["mean_dwell"], 8.0);
    assert_eq!(v["design"]["interval"], 1.0);
    assert_eq!(v["design"]["samples"], 200);
    let std_of = |list: &serde_json::Value, name: &str| {
        list.as_array()
            .unwrap()
            .iter()
            .find(|e| e["name"] == name)
            .and_then(|e| e["std"].as_f64())
            .unwrap()
    };
    let designed = std_of(&v["predicted"], "zero0");
    let baseline = std_of(&v["baseline"]["predicted"], "zero0");
    assert!(
        designed > 0.0 && designed <= baseline,
        "{designed} against {baseline}"
    );
    // The table names both designs.
    let o = cheap_table2(&[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("designed: mean_dwell")
            && text.contains("baseline: mean_dwell = 8")
            && text.contains("static_gain"),
        "{text}"
    );
}

#[test]
fn bad_designs_exit_2_naming_the_key() {
    let cases: [(&[&str], &str); 4] = [
        (
            &["--set", "design.mean_dwell=[1e-9, 1e-8]"],
            "[design] mean_dwell: no feasible mean dwell",
        ),
        (
            &[
                "--set",
                "design.interval=[300.0, 400.0]",
                "--set",
                "design.hold=duration",
            ],
            "[design] interval: no feasible interval",
        ),
        (
            &["--set", DWELL, "--criterion", "e"],
            "--criterion: expected",
        ),
        (
            &[
                "--set",
                DWELL,
                "--criterion",
                "param:nope",
                "--set",
                "design.grid=3",
                "--set",
                "design.draws=1",
            ],
            "param:nope",
        ),
    ];
    for (args, want) in cases {
        refused(args, want);
    }
    let o = run(&["design", &example("ls-bias.toml")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no [design] section"), "{}", stderr(&o));
}

/// `--jitter-blind` adds the design made with the jitter ignored, its standard deviations
/// predicted under the true prior (what its user gets) and under the jitter-blind one (what
/// they expect): on the resonant example the jitter makes the blind design's promise too good
/// and its true criterion worse than the jitter-aware optimum's.
#[test]
fn jitter_blind_design_is_reported_beside_the_aware_one() {
    let resonant = example("design-resonant.toml");
    let args = [
        "design",
        resonant.as_str(),
        "--set",
        "design.draws=4",
        "--set",
        "design.grid=5",
        "--jitter-blind",
    ];
    let mut json = args.to_vec();
    json.push("--json");
    let o = run(&json);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let b = &v["jitter_blind"];
    let blind_dwell = b["design"]["mean_dwell"].as_f64().unwrap();
    let aware_dwell = v["design"]["mean_dwell"].as_f64().unwrap();
    assert!(
        blind_dwell < aware_dwell,
        "{blind_dwell} against {aware_dwell}"
    );
    let true_value = b["criterion_value"].as_f64().unwrap();
    let promised = b["criterion_value_blind"].as_f64().unwrap();
    assert!(promised < true_value, "{promised} against {true_value}");
    assert_eq!(b["predicted"].as_array().unwrap().len(), 3);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("jitter-blind: mean_dwell"), "{text}");
}

/// `--write-input` writes the designed input and the experiment that reads it; the existing
/// commands take that experiment: `simulate` writes a record of the designed `N`, `fit`
/// fits it.
#[test]
fn written_design_round_trips_through_simulate_and_fit() {
    let d = scratch("design-write-input");
    let csv = d.join("designed.csv");
    let o = cheap_table2(&[
        "--budget",
        "samples=150",
        "--write-input",
        s(&csv),
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["design"]["samples"], 150);
    let exp = d.join("designed.toml");
    let text = std::fs::read_to_string(&exp).unwrap();
    assert!(
        text.contains("kind = \"csv\"") && !text.contains("[design]"),
        "{text}"
    );
    let input = std::fs::read_to_string(&csv).unwrap();
    assert!(input.starts_with("t,u"), "{input}");
    let data = d.join("d.csv");
    let o = run(&["simulate", s(&exp), "--seed", "3", "--out", s(&data)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rows = std::fs::read_to_string(&data).unwrap().lines().count();
    assert_eq!(rows, 151, "a header and the designed 150 samples");
    let o = run(&["fit", s(&exp), "--data", s(&data), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let fit: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let (gain, se) = common::param(&fit, "gain");
    assert!((gain - 0.2).abs() < 5.0 * se, "gain {gain} ± {se}");
    // A name that would be overwritten by the experiment is refused.
    refused(
        &["--set", DWELL, "--write-input", s(&d.join("x.toml"))],
        "--write-input",
    );
}

/// `--budget`: the record every design has; one that cannot be met is refused naming the key.
#[test]
fn budgets_that_cannot_be_met_exit_2_naming_the_key() {
    let cases: [(&[&str], &str); 4] = [
        (
            &["--budget", "duration=0.1"],
            "(--budget duration=0.1): [design] duration: a budget that cannot be met",
        ),
        (
            &["--budget", "samples=0"],
            "(--budget samples=0): [design] samples: a budget that cannot be met",
        ),
        (
            &[
                "--budget",
                "duration=5",
                "--set",
                "design.interval=[10.0, 20.0]",
            ],
            "[design] duration: a budget that cannot be met",
        ),
        (
            &["--budget", "time=5"],
            "--budget time=5: expected duration=",
        ),
    ];
    for (args, want) in cases {
        let mut all = vec!["--set", DWELL];
        all.extend_from_slice(args);
        refused(&all, want);
    }
}

/// `--budget` replaces the file's own budget: a file with `[design] duration` designed with
/// `--budget samples=N` keeps `N` samples.
#[test]
fn a_budget_on_the_command_line_replaces_the_file_s() {
    let d = scratch("design-budget-replaces");
    let text = std::fs::read_to_string(example("table2.toml")).unwrap()
        + "\n[design]\nmean_dwell = [1.0, 40.0]\ndraws = 2\ngrid = 3\nduration = 300.0\n";
    let exp = d.join("e.toml");
    std::fs::write(&exp, text).unwrap();
    let o = run(&["design", s(&exp), "--budget", "samples=150", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["design"]["samples"], 150, "{v}");
}

/// `--derived` chooses the derived quantities (the pole pair's natural frequency, `|G|` at a
/// frequency, the known jitter's σ as 0), in the order asked; without a terminal the progress
/// spinner draws nothing, so stderr stays empty; an unknown or undefined quantity exits 2
/// naming the flag or the key.
#[test]
fn derived_flag_chooses_the_quantities_and_bad_ones_exit_2() {
    let o = cheap_table2(&[
        "--derived",
        "pole_frequency,gain@0.05,jitter.sigma",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stderr(&o), "", "no progress without a terminal");
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let names: Vec<&str> = v["derived"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["pole1.frequency", "|G|@0.05Hz", "jitter.sigma"]);
    assert!(v["derived"][0]["std"].as_f64().unwrap() > 0.0);
    assert_eq!(v["derived"][2]["std"].as_f64(), Some(0.0));
    assert_eq!(v["baseline"]["derived"].as_array().unwrap().len(), 3);
    // The table has the rows too.
    let t = cheap_table2(&["--derived", "pole1.frequency"]);
    assert_eq!(t.status.code(), Some(0), "{}", stderr(&t));
    assert!(stdout(&t).contains("pole1.frequency"), "{}", stdout(&t));
    for (args, want) in [
        (vec!["--derived", "bogus"], "--derived bogus"),
        (vec!["--derived", "pole2.frequency"], "[design] derived"),
        (
            vec!["--set", "design.derived=[\"static_gain\", \"gain@-1\"]"],
            "derived",
        ),
    ] {
        let mut all = vec!["--set", DWELL];
        all.extend(args.iter().copied());
        refused(&all, want);
    }
}
