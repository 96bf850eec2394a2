//! Robust experiment design (`[design] prior_spread`, `prior_jitter_spread`): the criterion
//! averaged over prior draws of the truth. Each draw's experiment is checked against the same
//! model written as an experiment file and read again, the averaged criterion against its
//! definition, the robust optimum against a scan of the averaged criterion, and a prior that
//! makes the model invalid is refused naming its key.

mod common;

use common::plan as read_plan;
use jitterid_study::design::{
    criterion_value, design, optimise, predict, prior_experiments, Design,
};
use jitterid_study::experiment::{self, DesignCriterion, DesignEstimator, Purpose};
use std::path::Path;

/// A lightly damped resonance (as `examples/experiments/design-resonant.toml`, shorter), with
/// `system` and `design` the `[system]` and `[design]` sections' bodies.
fn resonant(system: &str, design: &str) -> String {
    format!(
        r#"
[sampling]
interval = 1.0
samples = 120
[input]
kind = "random-binary"
mean_dwell = 8.0
[system]
{system}
estimate = true
[jitter]
family = "uniform-sum"
n = 1
a = 0.4
[noise]
std = 0.01
[design]
{design}
"#
    )
}

const ZPK: &str = "kind = \"zpk\"\ngain = 4.0\npoles = [[-0.05, 2.0]]";

/// Each prior draw is the file's model with moved values: written back as an experiment file
/// (its `[system]` and `[jitter]` keys from the draw) and read again, it predicts the same
/// criterion; the draws move every parameter within three spreads, and the robust value is
/// their criteria's mean.
#[test]
fn each_prior_draw_is_a_valid_experiment_and_the_value_is_their_mean() {
    let text = resonant(
        ZPK,
        "mean_dwell = [0.5, 40.0]\ndraws = 2\nprior_spread = 0.1\nprior_jitter_spread = 0.2\nprior_draws = 3",
    );
    let plan = read_plan(&text).unwrap();
    let prior = plan.spec.prior.expect("a robust design");
    let draws = prior_experiments(&plan.baseline, &prior, plan.spec.seed).unwrap();
    assert_eq!(draws.len(), 3);
    let c = DesignCriterion::D;
    let value = |e: &experiment::Experiment| {
        let p = predict(e, DesignEstimator::Bcls, 2, plan.spec.seed).unwrap();
        criterion_value(&c, &p).unwrap()
    };
    let mut sum = 0.0;
    for (i, e) in draws.iter().enumerate() {
        let gain = e.system.kind["gain"].as_f64().unwrap();
        let pole = &e.system.kind["poles"][0];
        let (re, im) = (pole[0].as_f64().unwrap(), pole[1].as_f64().unwrap());
        let a = e.jitter.truth.spec()["a"].as_f64().unwrap();
        for (moved, truth) in [(gain, 4.0), (re, -0.05), (im, 2.0)] {
            let r = moved / truth;
            assert!(
                r != 1.0 && (r - 1.0).abs() <= 0.3 + 1e-12,
                "draw {i}: {moved} from {truth}"
            );
        }
        assert!(
            a != 0.4 && (a / 0.4 - 1.0).abs() <= 0.6 + 1e-12,
            "draw {i}: a = {a}"
        );
        // The same draw written as a file.
        let written = resonant(
            &format!("kind = \"zpk\"\ngain = {gain:?}\npoles = [[{re:?}, {im:?}]]"),
            "mean_dwell = [0.5, 40.0]",
        )
        .replace("a = 0.4", &format!("a = {a:?}"));
        let read =
            experiment::parse("draw.toml", &written, Path::new("."), Purpose::Simulate).unwrap();
        let v = value(e);
        assert!((value(&read) - v).abs() < 1e-9 * v.abs(), "draw {i}");
        sum += v;
    }
    let base = plan.baseline_design();
    let nominal = value(&plan.baseline);
    let robust = plan.robust_value(&base, &c, nominal).unwrap();
    assert!(
        (robust - sum / 3.0).abs() < 1e-12 * robust.abs(),
        "{robust} vs {}",
        sum / 3.0
    );
    assert!(robust != nominal);
}

/// The robust optimum is the minimum of the averaged criterion (not of its value at the
/// prior's point): no dwell of a fine scan averages lower, and the report's JSON gives both
/// averaged values.
#[test]
fn the_robust_optimum_minimises_the_averaged_criterion() {
    let text = resonant(
        ZPK,
        "mean_dwell = [0.5, 40.0]\ndraws = 2\ngrid = 7\nprior_spread = 0.15\nprior_draws = 4",
    );
    let plan = read_plan(&text).unwrap();
    let c = DesignCriterion::D;
    let opt = optimise(&plan, &c).unwrap();
    let averaged = |dwell: f64| {
        let d = Design {
            mean_dwell: Some(dwell),
            ..plan.baseline_design()
        };
        let p = plan.predict(&d).unwrap();
        plan.robust_value(&d, &c, criterion_value(&c, &p).unwrap())
            .unwrap()
    };
    for i in 0..21 {
        let dwell = 0.5 * 80f64.powf(i as f64 / 20.0);
        let v = averaged(dwell);
        assert!(
            opt.value <= v + 1e-9,
            "optimum {} above the scan's {v} at {dwell}",
            opt.value
        );
    }
    let report = design(&plan, None).unwrap();
    let json = serde_json::to_value(report.json()).unwrap();
    let robust = &json["robust"];
    assert_eq!(robust["prior_draws"], 4);
    assert_eq!(robust["criterion_designed"].as_f64(), Some(opt.value));
    assert_eq!(robust["criterion_baseline"].as_f64(), Some(averaged(8.0)));
    // Without a spread the design is the prior's point's, and the JSON has no robust part.
    let point = read_plan(&resonant(
        ZPK,
        "mean_dwell = [0.5, 40.0]\ndraws = 2\ngrid = 7",
    ))
    .unwrap();
    assert!(point.spec.prior.is_none());
    let json = serde_json::to_value(design(&point, None).unwrap().json()).unwrap();
    assert!(json.get("robust").is_none());
}

/// A prior whose draws leave the model's domain (here a grey-box mass outside its bounds) is
/// refused when the plan is read, naming the key and the draw; spreads out of range and
/// prior draws without a spread are refused at their keys.
#[test]
fn a_prior_that_makes_the_model_invalid_is_refused_naming_the_key() {
    let grey = "kind = \"grey-box\"\nparams = { m = 1.0, damp = 0.4, k = 2.0 }\nbounds = { m = [0.97, 1.03] }\na = [[\"0\", \"1\"], [\"-k/m\", \"-damp/m\"]]\nb = [[0], [\"1/m\"]]\nc = [[1, 0]]";
    let e = read_plan(&resonant(
        grey,
        "mean_dwell = [0.5, 40.0]\nprior_spread = 0.3\nprior_draws = 16",
    ))
    .unwrap_err();
    assert!(e.contains("[design] prior_spread: prior draw"), "{e}");
    for (design, key) in [
        (
            "mean_dwell = [1.0, 9.0]\nprior_spread = 0.4",
            "[design] prior_spread",
        ),
        (
            "mean_dwell = [1.0, 9.0]\nprior_jitter_spread = -0.1",
            "[design] prior_jitter_spread",
        ),
        (
            "mean_dwell = [1.0, 9.0]\nprior_draws = 4",
            "[design] prior_draws",
        ),
        (
            "mean_dwell = [1.0, 9.0]\nprior_spread = 0.1\nprior_draws = 0",
            "[design] prior_draws",
        ),
    ] {
        let e = read_plan(&resonant(ZPK, design)).unwrap_err();
        assert!(e.contains(key), "{design}: {e}");
    }
}
