//! The jitter's dependence on the sampling interval (`[design] jitter_exponent`): a design at
//! interval `T` is predicted with the file's jitter family at `σ₀ (T/T₀)^α`, which is checked
//! against the same experiment written by hand at that interval with the jitter's key scaled
//! (the uniform sum's `a` is proportional to its σ); `α = 0` leaves the jitter alone; the
//! interval search sees the scaled jitter; bad values are refused naming the key.

mod common;

use common::{plan, setup, table2, RANDOM_BINARY};
use jitterid_study::design::{optimise, Design};
use jitterid_study::experiment::DesignCriterion;

const A: f64 = 0.28867513459481287;

/// The file at interval `t` with the uniform sum's `a` written as `a`.
fn by_hand(t: f64, a: f64) -> String {
    table2("[design]\nmean_dwell = [1.0, 40.0]\ndraws = 4")
        .replace("interval = 1.0", &format!("interval = {t}"))
        .replace(&format!("a = {A}"), &format!("a = {a}"))
}

/// The design at interval `t` (the file's N held) under `[design]` keys `keys`.
fn predicted(keys: &str, t: f64) -> Vec<f64> {
    let p = plan(&table2(&format!("[design]\n{keys}\ndraws = 4"))).unwrap();
    let d = Design {
        interval: t,
        ..p.baseline_design()
    };
    p.predict(&d).unwrap().std
}

fn baseline_std(text: &str) -> Vec<f64> {
    let p = plan(text).unwrap();
    p.predict(&p.baseline_design()).unwrap().std
}

#[test]
fn the_jitter_follows_the_interval_as_written_by_hand() {
    for (alpha, t) in [(1.0, 0.5), (0.5, 2.0), (2.0, 0.8)] {
        let keys = format!("interval = [0.25, 2.0]\njitter_exponent = {alpha}");
        let designed = predicted(&keys, t);
        let hand = baseline_std(&by_hand(t, A * t.powf(alpha)));
        for (d, h) in designed.iter().zip(&hand) {
            assert!(
                (d - h).abs() <= 1e-9 * h,
                "α {alpha}, T {t}: {designed:?} against {hand:?}"
            );
        }
        // Not the jitter left at the file's spread.
        let fixed = baseline_std(&by_hand(t, A));
        assert!(
            designed
                .iter()
                .zip(&fixed)
                .any(|(d, f)| (d - f).abs() > 1e-6 * f),
            "α {alpha}, T {t}: {designed:?}"
        );
    }
    // Exponent 0 (the default): the file's jitter at every interval.
    let designed = predicted("interval = [0.25, 2.0]", 0.5);
    let hand = baseline_std(&by_hand(0.5, A));
    for (d, h) in designed.iter().zip(&hand) {
        assert!((d - h).abs() <= 1e-9 * h);
    }
}

/// With `N` held a longer interval is a longer record, which the search takes while the jitter
/// stays put; a jitter that grows with `T` makes a long interval costly: the D-optimal interval
/// with `α = 1` is less than half the one with `α = 0`, and its predicted standard deviations
/// are the hand-written experiment's at that interval.
#[test]
fn the_interval_search_sees_the_scaled_jitter() {
    let section = |alpha: f64| {
        setup(
            100,
            RANDOM_BINARY,
            &format!(
                "[design]\ninterval = [0.25, 4.0]\nhold = \"samples\"\njitter_exponent = {alpha}\ndraws = 4\ngrid = 5"
            ),
        )
    };
    let fixed = optimise(&plan(&section(0.0)).unwrap(), &DesignCriterion::D).unwrap();
    let grows = optimise(&plan(&section(1.0)).unwrap(), &DesignCriterion::D).unwrap();
    eprintln!(
        "α = 0: T = {} ({}); α = 1: T = {} ({})",
        fixed.design.interval, fixed.value, grows.design.interval, grows.value
    );
    assert!(grows.design.interval < 0.5 * fixed.design.interval);
    let t = grows.design.interval;
    let hand = setup(
        100,
        RANDOM_BINARY,
        "[design]\nmean_dwell = [1.0, 40.0]\ndraws = 4",
    )
    .replace("interval = 1.0", &format!("interval = {t}"))
    .replace(&format!("a = {A}"), &format!("a = {}", A * t));
    let hand = baseline_std(&hand);
    for (d, h) in grows.prediction.std.iter().zip(&hand) {
        assert!(
            (d - h).abs() <= 1e-9 * h,
            "{:?} against {hand:?}",
            grows.prediction.std
        );
    }
}

#[test]
fn bad_exponents_are_refused_naming_the_key() {
    for (keys, words) in [
        ("interval = [0.5, 2.0]\njitter_exponent = -1.0", "[0, 2]"),
        ("interval = [0.5, 2.0]\njitter_exponent = 2.5", "[0, 2]"),
        ("interval = [0.5, 2.0]\njitter_exponent = nan", "[0, 2]"),
        (
            "mean_dwell = [1.0, 40.0]\njitter_exponent = 1.0",
            "interval",
        ),
        (
            "interval = [0.5, 2.0]\njitter_exponent = 1.0\nprior_jitter_spread = 0.1",
            "prior_jitter_spread",
        ),
    ] {
        let e = plan(&table2(&format!("[design]\n{keys}"))).unwrap_err();
        assert!(
            e.contains("[design] jitter_exponent") && e.contains(words),
            "{keys}: {e}"
        );
    }
}

/// `--write-input` writes the jitter at the designed interval: the written `[jitter] a` is the
/// file's scaled by `(T/T₀)^α`, the family and `n` kept; at the file's interval nothing of the
/// jitter is rewritten.
#[test]
fn the_written_experiment_carries_the_scaled_jitter() {
    let p = plan(&table2(
        "[design]\ninterval = [0.25, 2.0]\njitter_exponent = 0.5\ndraws = 4",
    ))
    .unwrap();
    let jitter_of = |t: f64| {
        let d = Design {
            interval: t,
            ..p.baseline_design()
        };
        let written = jitterid_study::design::designed_input(&p, &d, "designed.csv").unwrap();
        let doc: toml::Table = written.experiment.parse().unwrap();
        doc["jitter"].as_table().unwrap().clone()
    };
    let j = jitter_of(0.64);
    let a = j["a"].as_float().unwrap();
    assert!((a - A * 0.8).abs() <= 1e-12 * A, "{j:?}");
    assert_eq!(j["family"].as_str(), Some("uniform-sum"));
    assert_eq!(j["n"].as_integer(), Some(2));
    assert_eq!(jitter_of(1.0)["a"].as_float(), Some(A));
}

/// The report gives the jitter's σ at each design's interval under `jitter_exponent` (the
/// designed one's is the baseline's times `(T/T₀)^α`), and leaves the key out otherwise.
#[test]
fn the_report_gives_the_jitter_at_each_design() {
    let text = |alpha: f64| {
        setup(
            100,
            RANDOM_BINARY,
            &format!(
                "[design]\ninterval = [0.25, 4.0]\nhold = \"samples\"\njitter_exponent = {alpha}\ndraws = 4\ngrid = 5"
            ),
        )
    };
    let p = plan(&text(0.5)).unwrap();
    let mut report = jitterid_study::design::design(&p, None).unwrap();
    report.jitter_blind =
        Some(jitterid_study::design::jitter_blind(&p, &DesignCriterion::D).unwrap());
    let json = report.json();
    let designed = json.jitter_std.unwrap();
    let baseline = json.baseline.jitter_std.unwrap();
    let t = json.design.interval;
    assert!(
        (designed / baseline - t.sqrt()).abs() < 1e-12,
        "{designed} {baseline} at {t}"
    );
    let blind = json.jitter_blind.as_ref().unwrap();
    let tb = blind.design.interval;
    assert!((blind.jitter_std.unwrap() / baseline - tb.sqrt()).abs() < 1e-12);
    // Without the exponent the key is absent from every design.
    let v = serde_json::to_value(
        jitterid_study::design::design(&plan(&text(0.0)).unwrap(), None)
            .unwrap()
            .json(),
    )
    .unwrap();
    assert!(
        v.get("jitter_std").is_none() && v["baseline"].get("jitter_std").is_none(),
        "{v}"
    );
}
