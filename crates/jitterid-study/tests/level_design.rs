//! The random binary input's levels as design variables (`[design] low`, `high`): the ranges
//! refused at the door naming their key, the search's optimum against a brute-force scan of
//! the criterion computed here through `predict` and `criterion_value`, levels that never
//! switch counted as infeasible, and the designed levels carried into the designed
//! experiment, its written input and the report.

mod common;

use common::{plan, table2};
use jitterid::signal::Input;
use jitterid_study::design::{
    criterion_value, design, designed_input, jitter_blind, optimise, predict, Design, Plan,
};
use jitterid_study::experiment::{self, DesignCriterion, DesignEstimator, InputSpec, Purpose};
use std::path::Path;

fn parse(text: &str) -> Result<experiment::Experiment, String> {
    experiment::parse("exp.toml", text, Path::new("."), Purpose::Simulate)
        .map_err(|e| e.to_string())
}

/// The random binary input's levels in the experiment of `design` under `plan`.
fn levels_in(plan: &Plan, design: &Design) -> (f64, f64) {
    let exp = plan.experiment(design).unwrap();
    match &exp.inputs[0].spec {
        InputSpec::RandomBinary(rb) => (rb.low(), rb.high()),
        other => panic!("not a random binary input: {other:?}"),
    }
}

/// Level ranges are read as written (negative levels too, either level alone); reversed, not
/// finite, too large, malformed ranges and ranges for an input that is not random binary are
/// refused, naming the key.
#[test]
fn level_ranges_are_read_and_refused_naming_the_key() {
    let spec = parse(&table2("[design]\nlow = [-2.0, -0.5]\nhigh = [0.0, 3.0]"))
        .unwrap()
        .design
        .unwrap();
    assert_eq!(spec.low, Some((-2.0, -0.5)));
    assert_eq!(spec.high, Some((0.0, 3.0)));
    assert_eq!(spec.mean_dwell, None);
    // One level alone is a free variable; a one-point range is allowed.
    let spec = parse(&table2("[design]\nhigh = [2.0, 2.0]"))
        .unwrap()
        .design
        .unwrap();
    assert_eq!((spec.low, spec.high), (None, Some((2.0, 2.0))));
    let cases = [
        (
            "[design]\nlow = [1.0, -1.0]",
            "[design] low: expected [min, max] of two finite levels with min <= max",
        ),
        (
            "[design]\nhigh = [nan, 1.0]",
            "[design] high: expected [min, max] of two finite levels",
        ),
        (
            "[design]\nhigh = [0.0, inf]",
            "[design] high: expected [min, max] of two finite levels",
        ),
        ("[design]\nlow = [0.5]", "[design] low: expected [min, max]"),
        (
            "[design]\nlow = [-1e60, 0.0]",
            "[design] low: min: expected a magnitude of at most 1e50",
        ),
        (
            "[design]\nhigh = [0.0, 2e50]",
            "[design] high: max: expected a magnitude of at most 1e50",
        ),
    ];
    for (section, want) in cases {
        let e = parse(&table2(section)).unwrap_err();
        assert!(e.contains(want), "{section}: {e}");
    }
    for key in ["low", "high"] {
        let sine = common::setup(
            200,
            "kind = \"sine\"\nfrequency = 0.05\namplitude = 1.0",
            &format!("[design]\n{key} = [0.0, 1.0]"),
        );
        let e = parse(&sine).unwrap_err();
        assert!(
            e.contains(&format!(
                "[design] {key}: is a design variable of a random binary input"
            )),
            "{e}"
        );
    }
}

/// The search over both levels: its optimum is no worse than every point of a 21 × 21 scan of
/// the same criterion over the ranges, computed here through `predict` and `criterion_value`
/// on the design's experiment (the levels set through the plan's edits), and lies at a scan
/// minimum's levels to the refinement's tolerance. The criterion is exactly symmetric under
/// negating both levels (each draw's first state and switch times do not depend on the
/// levels, so `(−low, −high)` gives the negated input, whose information is the same), so the
/// mirror image `(−low, −high)` is the same minimum. The scan's diagonal (`low = high`) is
/// infeasible and skipped; the search does not choose it.
#[test]
fn level_search_finds_the_scan_s_minimum() {
    let text =
        table2("[design]\nlow = [-1.0, 1.0]\nhigh = [-1.0, 1.0]\ndraws = 4\ngrid = 5\nseed = 3")
            .replace("samples = 200", "samples = 120");
    let plan = plan(&text).unwrap();
    let crit = DesignCriterion::D;
    let opt = optimise(&plan, &crit).unwrap();
    let scan_value = |low: f64, high: f64| {
        let d = Design {
            low: Some(low),
            high: Some(high),
            ..plan.baseline_design()
        };
        let exp = plan.experiment(&d).unwrap();
        let p = predict(&exp, DesignEstimator::Bcls, 4, 3).unwrap();
        criterion_value(&crit, &p).unwrap()
    };
    let n = 21;
    let level = |i: usize| -1.0 + 2.0 * i as f64 / (n - 1) as f64;
    let mut best = (f64::NAN, f64::NAN, f64::INFINITY);
    for i in 0..n {
        for j in 0..n {
            if i == j {
                continue;
            }
            let v = scan_value(level(i), level(j));
            if v < best.2 {
                best = (level(i), level(j), v);
            }
        }
    }
    let (low, high) = (opt.design.low.unwrap(), opt.design.high.unwrap());
    eprintln!(
        "optimum low {low} high {high}: {} in {} evaluations; scan best {best:?}",
        opt.value, opt.evaluations
    );
    assert!(low != high);
    assert!(
        opt.value <= best.2 + 1e-9,
        "{} against the scan's {}",
        opt.value,
        best.2
    );
    // The search's value is the criterion at its design, recomputed here.
    assert!((scan_value(low, high) - opt.value).abs() <= 1e-12 * opt.value.abs());
    // At the scan's minimum (or its mirror image) to twice the refinement's tolerance (10⁻³ of
    // the range's width).
    let tol = 2.0 * 2e-3;
    let at = |a: f64, b: f64| (a - best.0).abs() <= tol && (b - best.1).abs() <= tol;
    assert!(
        at(low, high) || at(-low, -high),
        "({low}, {high}) against {best:?}"
    );
    // The file's own levels (0, 1) are a candidate: the optimum is no worse.
    assert!(opt.value <= scan_value(0.0, 1.0));
    let again = optimise(&plan, &crit).unwrap();
    assert_eq!(again.design, opt.design);
}

/// One level free, where the optimum is inside the range: with the sensor noise at 10⁻³ the
/// jitter's noise after each switch dominates, and it grows with the step's square as the
/// signal grows with the step, so a larger step buys little while a constant level carries
/// the static gain without jitter noise. The search over `low` in [-1, 0.95] (`high = 1`
/// fixed; a linear coordinate through 0) refines between grid points to the minimum of an
/// 800-point scan of the criterion computed here: at the scan's minimum to its spacing and the
/// refinement's tolerance, and no worse than any scan point by more than that tolerance costs
/// at the scan's curvature. The minimum is interior (not
/// a grid point, not an end of the range), so the refinement is what finds it.
#[test]
fn an_interior_level_optimum_agrees_with_a_fine_scan() {
    let text = table2("[design]\nlow = [-1.0, 0.95]\ndraws = 4\ngrid = 5\nseed = 3")
        .replace("std = 0.01", "std = 0.001");
    let plan = plan(&text).unwrap();
    let crit = DesignCriterion::D;
    let opt = optimise(&plan, &crit).unwrap();
    assert_eq!(opt.design.high, Some(1.0));
    let scan_value = |low: f64| {
        let d = Design {
            low: Some(low),
            ..plan.baseline_design()
        };
        let p = predict(&plan.experiment(&d).unwrap(), DesignEstimator::Bcls, 4, 3).unwrap();
        criterion_value(&crit, &p).unwrap()
    };
    let n = 800;
    let spacing = 1.95 / (n - 1) as f64;
    let scan: Vec<(f64, f64)> = (0..n)
        .map(|i| -1.0 + spacing * i as f64)
        .map(|l| (l, scan_value(l)))
        .collect();
    let k = (0..n).fold(0, |a, i| if scan[i].1 < scan[a].1 { i } else { a });
    let best = scan[k];
    let low = opt.design.low.unwrap();
    eprintln!(
        "optimum low {low}: {} in {} evaluations; scan best {best:?}",
        opt.value, opt.evaluations
    );
    // Interior: well inside the range, and off the 5-point grid (-1, -0.5125, …, 0.95).
    assert!(best.0 > -0.9 && best.0 < 0.9, "{best:?}");
    let grid_step = 1.95 / 4.0;
    let off_grid = ((low + 1.0) / grid_step - ((low + 1.0) / grid_step).round()).abs();
    assert!(off_grid > 1e-3, "{low} is a grid point");
    // The refinement's tolerance is 10⁻³ of the range's width.
    let tol = 1e-3 * 1.95;
    assert!(
        (low - best.0).abs() <= spacing + 2.0 * tol,
        "{low} against {best:?}"
    );
    // What a point `2 tol` from the minimum costs: half the curvature times its square.
    let curvature = (scan[k + 1].1 - 2.0 * scan[k].1 + scan[k - 1].1) / spacing.powi(2);
    assert!(curvature > 0.0, "{curvature}");
    let slack = 0.5 * curvature * (2.0 * tol).powi(2);
    eprintln!("curvature {curvature}, value slack {slack}");
    assert!(
        opt.value <= best.1 + slack,
        "{} against the scan's {} + {slack}",
        opt.value,
        best.1
    );
    // The file's own `low = 0` is a candidate: no worse than it.
    assert!(opt.value <= scan_value(0.0));
}

/// Levels that never switch (`low = high`) are infeasible, not a crash: a search whose every
/// candidate has them names both keys, and the reason.
#[test]
fn equal_levels_are_infeasible() {
    let p = plan(&table2(
        "[design]\nlow = [0.5, 0.5]\nhigh = [0.5, 0.5]\ndraws = 1\ngrid = 3",
    ))
    .unwrap();
    let e = optimise(&p, &DesignCriterion::D).unwrap_err().to_string();
    assert!(
        e.contains("[design] low, high: no feasible design") && e.contains("never switches"),
        "{e}"
    );
    let d = Design {
        low: Some(0.0),
        high: Some(0.0),
        ..p.baseline_design()
    };
    assert!(p.predict(&d).is_err());
    // One free level whose range meets the other's value only at one grid point.
    let p = plan(&table2("[design]\nlow = [0.0, 1.0]\ndraws = 1\ngrid = 3")).unwrap();
    let opt = optimise(&p, &DesignCriterion::D).unwrap();
    assert_ne!(opt.design.low, Some(1.0));
}

/// The designed levels reach every product of a design: the design's experiment, the written
/// experiment and its CSV input (read back, its values are the designed levels, both of
/// them, and nothing else), the report's JSON beside the
/// baseline's levels, the jitter-blind design and a robust design; a design without free
/// levels has no `low`/`high` in its JSON.
#[test]
fn designed_levels_round_trip() {
    let text =
        table2("[design]\nlow = [-1.0, 0.0]\nhigh = [0.5, 2.0]\ndraws = 2\ngrid = 3\nseed = 3")
            .replace("samples = 200", "samples = 100");
    let p = plan(&text).unwrap();
    let base = p.baseline_design();
    assert_eq!((base.low, base.high), (Some(0.0), Some(1.0)));
    let d = Design {
        low: Some(-0.75),
        high: Some(1.5),
        ..base.clone()
    };
    assert_eq!(levels_in(&p, &d), (-0.75, 1.5));
    // Written and read back.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("level-design");
    std::fs::create_dir_all(&dir).unwrap();
    let written = designed_input(&p, &d, "designed.csv").unwrap();
    std::fs::write(dir.join("designed.csv"), &written.csv).unwrap();
    assert!(
        written
            .experiment
            .contains("between the designed levels low = -0.75 and high = 1.5"),
        "{}",
        written.experiment
    );
    let back = experiment::parse(
        "designed.toml",
        &written.experiment,
        &dir,
        Purpose::Simulate,
    )
    .unwrap();
    let Some(InputSpec::Known(Input::Piecewise(u))) = back.inputs.first().map(|c| &c.spec) else {
        panic!("not a piecewise input: {:?}", back.inputs);
    };
    let levels = u.levels();
    // Every level is a designed one, but a last 0 where the file's last row ends the input.
    let body = match levels.split_last() {
        Some((&0.0, rest)) => rest,
        _ => levels,
    };
    assert!(body.iter().all(|&l| l == -0.75 || l == 1.5), "{levels:?}");
    assert!(body.contains(&-0.75) && body.contains(&1.5), "{levels:?}");
    // The report: the design's levels and the baseline's.
    let report = design(&p, None).unwrap();
    let json = serde_json::to_value(report.json()).unwrap();
    let (low, high) = (
        json["design"]["low"].as_f64().unwrap(),
        json["design"]["high"].as_f64().unwrap(),
    );
    assert!(
        (-1.0..=0.0).contains(&low) && (0.5..=2.0).contains(&high),
        "{json}"
    );
    assert_eq!(json["baseline"]["design"]["low"], 0.0);
    assert_eq!(json["baseline"]["design"]["high"], 1.0);
    assert_eq!(levels_in(&p, &report.design), (low, high));
    // The jitter-blind design has levels of its own, in the ranges.
    let blind = jitter_blind(&p, &DesignCriterion::D).unwrap();
    let (bl, bh) = (blind.design.low.unwrap(), blind.design.high.unwrap());
    assert!((-1.0..=0.0).contains(&bl) && (0.5..=2.0).contains(&bh));
    // A robust design over the levels runs, and reports the averaged criterion.
    let robust =
        plan(&text.replace("seed = 3", "seed = 3\nprior_spread = 0.1\nprior_draws = 2")).unwrap();
    let r = design(&robust, None).unwrap();
    assert!(r.design.low.is_some() && r.json().robust.is_some());
    // Without free levels the JSON has no levels (the existing designs' JSON is unchanged).
    let dwell = plan(&table2(
        "[design]\nmean_dwell = [4.0, 16.0]\ndraws = 1\ngrid = 3",
    ))
    .unwrap();
    let json = serde_json::to_value(design(&dwell, None).unwrap().json()).unwrap();
    for d in [&json["design"], &json["baseline"]["design"]] {
        assert!(d.get("low").is_none() && d.get("high").is_none(), "{d}");
    }
}
