//! `jitterid design` through the real binary: the JSON's shape, the designed experiment no
//! worse than the file's own under the criterion, and bad designs refused with exit status 2
//! and the key named.

mod common;

use common::{example, run, stderr, stdout};

const DWELL: &str = "design.mean_dwell=[1.0, 40.0]";

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
    assert_eq!(keys, ["baseline", "criterion", "design", "predicted"]);
    assert_eq!(v["criterion"], "param:zero0");
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
    let o = run(&[
        "design",
        &table2,
        "--set",
        DWELL,
        "--set",
        "design.draws=2",
        "--set",
        "design.grid=3",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("designed: mean_dwell") && text.contains("baseline: mean_dwell = 8"),
        "{text}"
    );
}

#[test]
fn bad_designs_exit_2_naming_the_key() {
    let table2 = example("table2.toml");
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
        let mut all = vec!["design", table2.as_str()];
        all.extend_from_slice(args);
        let o = run(&all);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(want), "{args:?}: expected {want:?} in {err}");
    }
    let o = run(&["design", &example("ls-bias.toml")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no [design] section"), "{}", stderr(&o));
}
