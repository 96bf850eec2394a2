//! Experiment design: the predicted precision of a planned experiment against a Monte Carlo of
//! it, against an independent closed form, against the Cramér–Rao ordering, and the design
//! search's optimum against a fine scan of its criterion.

mod common;

use common::{plan, table2};
use faer::linalg::solvers::DenseSolveCore;
use jitterid::estimate::ml::delta_method_std;
use jitterid::signal::Signal;
use jitterid_study::design::{
    criterion_value, derived_std, design, evaluate, jitter_blind, monte_carlo, optimise, predict,
    Derived, Design, Plan,
};
use jitterid_study::experiment::{
    self, DesignCriterion, DesignEstimator, Experiment, Purpose, ReadOptions,
};
use jitterid_study::montecarlo::{montecarlo_realizations, DEFAULT_SEED};
use std::path::Path;

fn example(file: &str) -> Experiment {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/experiments")
        .join(file);
    experiment::read(&path, Purpose::Estimate(None)).unwrap()
}

fn parse(text: &str) -> Result<Experiment, String> {
    experiment::parse("exp.toml", text, Path::new("."), Purpose::Simulate)
        .map_err(|e| e.to_string())
}

/// The predicted BCLS standard deviations of the Table 2 setup agree with a Monte Carlo of 64
/// realisations. The prediction averages the sandwich over the same 64 input draws the Monte
/// Carlo runs see (same seed), so what is left is the Monte Carlo's own error, whose standard
/// error for a standard deviation is about `std/√(2R)`: the test allows 3 of those.
#[test]
fn predicted_bcls_std_agrees_with_monte_carlo() {
    let exp = example("table2.toml");
    let runs = 64;
    let p = predict(&exp, DesignEstimator::Bcls, runs, DEFAULT_SEED).unwrap();
    assert_eq!(p.draws, runs);
    let mc = montecarlo_realizations(&exp, runs as u64, DEFAULT_SEED, None).unwrap();
    assert_eq!(mc.names, p.names);
    for (i, name) in p.names.iter().enumerate() {
        let v: Vec<f64> = mc
            .runs
            .iter()
            .filter(|r| r.converged)
            .filter_map(|r| r.values[i])
            .collect();
        let r = v.len() as f64;
        assert!(r >= 60.0, "{name}: only {r} converged runs");
        let mean = v.iter().sum::<f64>() / r;
        let std = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (r - 1.0)).sqrt();
        let se = p.std[i] / (2.0 * r).sqrt();
        eprintln!(
            "{name}: predicted {:.5}, Monte Carlo {std:.5} (se {se:.5})",
            p.std[i]
        );
        assert!(
            (std - p.std[i]).abs() <= 3.0 * se,
            "{name}: predicted {} against Monte Carlo {std} ± {se}",
            p.std[i]
        );
    }
}

/// An independent route to the same number: on the half DFT grid `0 ≤ j ≤ N/2` with the
/// rectangular window, `Σ_j |D_j|² = ½ dᵀ(N I + 11ᵀ + [N even] aaᵀ) d` with `a_k = (−1)^k`, so
/// BCLS is generalised least squares in time with that weight `Q`, and its covariance is
/// `(GᵀQG)⁻¹ GᵀQΛQG (GᵀQG)⁻¹` with `G = ∂m/∂θ` (here by central differences of `m_k`, not
/// the analytic sensitivities) and `Λ = diag(σ_v² + E s² − m²)`. Checked for an odd and an
/// even `N` on a fixed piecewise input.
#[test]
fn bcls_prediction_is_the_time_domain_gls_sandwich() {
    for n in [61usize, 64] {
        let text = format!(
            r#"
[sampling]
interval = 0.5
samples = {n}
[input]
kind = "piecewise"
times = [0.0, 3.1, 7.4, 9.0, 15.2, 21.7, 25.0]
values = [0.0, 1.0, -1.0, 0.5, 1.0, 0.0, -0.5]
[system]
kind = "zpk"
gain = 0.2
zeros = [-0.5]
poles = [[-0.25, 0.3]]
estimate = true
[jitter]
family = "uniform-sum"
n = 1
a = 0.4
estimate = true
[noise]
std = 0.02
"#
        );
        let exp = parse(&text).unwrap();
        let p = predict(&exp, DesignEstimator::Bcls, 8, 1).unwrap();
        assert_eq!(p.draws, 1, "a fixed input is one draw");
        let s = p.model();
        let grid = &exp.grid;
        let theta = s.params();
        let np = theta.len();
        let m_at = |t: &[f64]| {
            let m = s.with_params(t).unwrap();
            m.signal.expected_values(grid, &m.jitter)
        };
        let g: Vec<Vec<f64>> = (0..np)
            .map(|j| {
                let h = 1e-6 * theta[j].abs().max(1e-3);
                let (mut up, mut dn) = (theta.clone(), theta.clone());
                up[j] += h;
                dn[j] -= h;
                let (a, b) = (m_at(&up), m_at(&dn));
                a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect()
            })
            .collect();
        let m = s.signal.expected_values(grid, &s.jitter);
        let sq = s.signal.expected_squares(grid, &s.jitter);
        let lambda: Vec<f64> = m
            .iter()
            .zip(&sq)
            .map(|(m, q)| 0.02f64.powi(2) + (q - m * m).max(0.0))
            .collect();
        // Q g for a column g: N g + 1(1ᵀg) + [N even] a(aᵀg).
        let q = |v: &[f64]| -> Vec<f64> {
            let sum: f64 = v.iter().sum();
            let alt: f64 = v
                .iter()
                .enumerate()
                .map(|(k, x)| if k % 2 == 0 { *x } else { -x })
                .sum();
            v.iter()
                .enumerate()
                .map(|(k, x)| {
                    let a = if k % 2 == 0 { 1.0 } else { -1.0 };
                    n as f64 * x + sum + if n % 2 == 0 { a * alt } else { 0.0 }
                })
                .collect()
        };
        let qg: Vec<Vec<f64>> = g.iter().map(|c| q(c)).collect();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let h = faer::Mat::from_fn(np, np, |i, j| dot(&g[i], &qg[j]));
        let meat = faer::Mat::from_fn(np, np, |i, j| {
            qg[i]
                .iter()
                .zip(&qg[j])
                .zip(&lambda)
                .map(|((a, b), l)| a * b * l)
                .sum::<f64>()
        });
        let hinv = h.partial_piv_lu().inverse();
        let cov = &hinv * &meat * &hinv;
        for i in 0..np {
            let closed = cov[(i, i)].sqrt();
            let rel = (closed - p.std[i]).abs() / closed;
            eprintln!(
                "N = {n}, {}: {} against {closed} ({rel:e})",
                p.names[i], p.std[i]
            );
            assert!(
                rel < 1e-5,
                "N = {n}, {}: {} against {closed}",
                p.names[i],
                p.std[i]
            );
        }
    }
}

/// Exact ML's predicted covariance is the Cramér–Rao bound, which no consistent estimator's
/// asymptotic covariance goes below: every parameter's ML std is at most BCLS's, on the same
/// draws.
#[test]
fn ml_prediction_is_below_bcls() {
    let exp = parse(&table2("").replace("samples = 200", "samples = 100")).unwrap();
    let b = predict(&exp, DesignEstimator::Bcls, 2, 5).unwrap();
    let m = predict(&exp, DesignEstimator::Ml, 2, 5).unwrap();
    assert_eq!(b.names, m.names);
    for i in 0..b.names.len() {
        eprintln!("{}: ML {} BCLS {}", b.names[i], m.std[i], b.std[i]);
        assert!(
            m.std[i] > 0.0 && m.std[i] <= b.std[i] * (1.0 + 1e-6),
            "{}",
            b.names[i]
        );
    }
}

/// The static gain's delta-method std with the gradient in closed form:
/// `G(0) = k(−z)/(re² + im²)` for `G = k (s − z)/((s − re)² + im²)`.
#[test]
fn static_gain_std_is_the_delta_method_with_the_closed_form_gradient() {
    let exp = parse(&table2("")).unwrap();
    let p = predict(&exp, DesignEstimator::Bcls, 4, 9).unwrap();
    let (k, z, re, im) = (0.2, -0.5, -0.25, 0.3);
    let d = re * re + im * im;
    let g0 = -k * z / d;
    let grad = [g0 / k, -k / d, -g0 * 2.0 * re / d, -g0 * 2.0 * im / d];
    let closed = delta_method_std(&p.covariance, &grad).unwrap();
    let derived = derived_std(&p, Derived::StaticGain).unwrap();
    assert!(
        (derived - closed).abs() <= 1e-6 * closed,
        "{derived} against {closed}"
    );
    // The jitter is known here: its σ has no spread.
    assert_eq!(derived_std(&p, Derived::JitterStd).unwrap(), 0.0);
    let at = derived_std(&p, Derived::Magnitude(0.05)).unwrap();
    assert!(at > 0.0 && at.is_finite());
    assert!(derived_std(&p, Derived::Magnitude(f64::NAN)).is_err());
}

/// The design search on the mean dwell: its optimum is no worse than any point of a fine scan
/// of the same criterion over the range (the grid and refinement found the basin), no worse
/// than the file's own dwell, deterministic, and reported in the command's JSON shape.
#[test]
fn dwell_search_finds_the_scan_s_minimum() {
    let text = table2(
        "[design]\nmean_dwell = [0.5, 40.0]\ncriterion = \"d\"\ndraws = 4\ngrid = 7\nseed = 3",
    )
    .replace("samples = 200", "samples = 120");
    let plan = plan(&text).unwrap();
    let opt = optimise(&plan, &DesignCriterion::D).unwrap();
    let scan_value = |dwell: f64| {
        let d = Design {
            mean_dwell: Some(dwell),
            ..plan.baseline_design()
        };
        let exp = plan.experiment(&d).unwrap();
        let p = predict(&exp, DesignEstimator::Bcls, 4, 3).unwrap();
        criterion_value(&DesignCriterion::D, &p).unwrap()
    };
    let mut scan = Vec::new();
    for i in 0..25 {
        let dwell = 0.5 * (80.0f64).powf(i as f64 / 24.0);
        scan.push((dwell, scan_value(dwell)));
    }
    let best = scan
        .iter()
        .cloned()
        .fold((0.0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
    eprintln!(
        "optimum {:?} = {}, scan best {best:?}",
        opt.design, opt.value
    );
    assert!(
        opt.value <= best.1 + 1e-9,
        "{} against the scan's {}",
        opt.value,
        best.1
    );
    assert!(opt.value <= scan_value(8.0));
    let again = optimise(&plan, &DesignCriterion::D).unwrap();
    assert_eq!(again.design, opt.design);
    let report = design(&plan, None).unwrap();
    let json = serde_json::to_value(report.json()).unwrap();
    let keys: Vec<&String> = json.as_object().unwrap().keys().collect();
    assert_eq!(
        keys,
        ["baseline", "criterion", "derived", "design", "predicted"]
    );
    assert_eq!(json["criterion"], "d");
    assert_eq!(json["baseline"]["design"]["mean_dwell"], 8.0);
    assert_eq!(json["predicted"].as_array().unwrap().len(), 4);
    assert_eq!(json["predicted"][0]["name"], "gain");
}

/// A held duration: the interval's search keeps `N T` and its optimum's `N` is
/// `round(duration / T)`.
#[test]
fn interval_search_with_a_held_duration_keeps_the_duration() {
    let text = table2(
        "[design]\ninterval = [0.25, 2.0]\nhold = \"duration\"\ndraws = 2\ngrid = 4\ncriterion = \"a\"",
    )
    .replace("samples = 200", "samples = 80");
    let plan = plan(&text).unwrap();
    let opt = optimise(&plan, &DesignCriterion::A).unwrap();
    let d = opt.design;
    assert!((0.25..=2.0).contains(&d.interval), "{d:?}");
    assert_eq!(d.samples, (80.0 / d.interval).round() as usize, "{d:?}");
}

/// Bad `[design]` sections are refused at the door, naming the key; a criterion that names no
/// parameter is refused by the search.
#[test]
fn infeasible_designs_are_refused_naming_the_key() {
    let cases = [
        (
            "[design]\nmean_dwell = [2.0, 1.0]",
            "[design] mean_dwell: expected [min, max]",
        ),
        (
            "[design]\nmean_dwell = [1e-9, 1e-8]",
            "[design] mean_dwell: no feasible mean dwell",
        ),
        (
            "[design]\ninterval = [300.0, 400.0]\nhold = \"duration\"",
            "[design] interval: no feasible interval",
        ),
        (
            "[design]\ndraws = 4",
            "[design] mean_dwell: the section names no free variable",
        ),
        (
            "[design]\ninterval = [0.5, 1.0]\ncriterion = \"e\"",
            "[design] criterion: expected",
        ),
        (
            "[design]\ninterval = [0.5, 1.0]\nhold = \"time\"",
            "[design] hold: expected",
        ),
        (
            "[design]\ninterval = [0.5, 1.0]\ndraws = 0",
            "[design] draws: expected a whole number",
        ),
        ("[design]\ninterval = [0.5, 1.0]\nfoo = 1", "foo"),
    ];
    for (section, want) in cases {
        let e = parse(&table2(section)).unwrap_err();
        assert!(e.contains(want), "{section}: {e}");
    }
    // A dwell range needs a random binary input.
    let sine = common::setup(
        200,
        "kind = \"sine\"\nfrequency = 0.05\namplitude = 1.0",
        "[design]\nmean_dwell = [1.0, 2.0]",
    );
    let e = parse(&sine).unwrap_err();
    assert!(
        e.contains("[design] mean_dwell: is a design variable of a random binary input"),
        "{e}"
    );
    let p = plan(&table2(
        "[design]\ninterval = [0.5, 1.0]\ngrid = 3\ndraws = 1",
    ))
    .unwrap();
    let e = optimise(&p, &DesignCriterion::Param("nope".into()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("param:nope") && e.contains("gain"), "{e}");
    assert!(plan(&table2(""))
        .unwrap_err()
        .contains("no [design] section"));
}

/// The jitter-blind plan is the prior with its jitter replaced by none: for BCLS and ML its
/// prediction at a design equals that of the same file written with `family = "none"`, and
/// the true plan's is larger (the jitter adds noise after every switch).
#[test]
fn jitter_blind_plan_is_the_file_without_jitter() {
    for estimator in ["bcls", "ml"] {
        let text = table2(&format!(
            "[design]\nmean_dwell = [1.0, 40.0]\ndraws = 2\nestimator = \"{estimator}\""
        ))
        .replace("samples = 200", "samples = 100");
        let none = text.replace(
            "family = \"uniform-sum\"\nn = 2\na = 0.28867513459481287",
            "family = \"none\"",
        );
        assert_ne!(none, text);
        let jittered = plan(&text).unwrap();
        let blind = jittered.jitter_blind().unwrap();
        assert!(blind.is_jitter_blind() && !jittered.is_jitter_blind());
        let d = Design {
            mean_dwell: Some(3.0),
            ..jittered.baseline_design()
        };
        let b = blind.predict(&d).unwrap();
        let w = plan(&none).unwrap().predict(&d).unwrap();
        let t = jittered.predict(&d).unwrap();
        assert_eq!(b.names, w.names);
        for i in 0..b.names.len() {
            eprintln!(
                "{estimator} {}: blind {} written {} jittered {}",
                b.names[i], b.std[i], w.std[i], t.std[i]
            );
            assert!(
                (b.std[i] - w.std[i]).abs() <= 1e-9 * w.std[i],
                "{estimator} {}",
                b.names[i]
            );
            assert!(t.std[i] > b.std[i], "{estimator} {}", b.names[i]);
        }
    }
}

/// The resonant example: the jitter-blind design switches more often than the jitter-aware
/// one, and on jittered data it is worse. Predicted (under the true prior) and by a small
/// seeded Monte Carlo of both designs: the Monte Carlo's difference of `log det C` agrees with
/// the predicted one within three of its standard errors (jackknife), and the predicted
/// margin is beyond them.
#[test]
fn jitter_blind_design_is_worse_on_jittered_data() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/experiments/design-resonant.toml");
    let read = ReadOptions {
        overrides: vec![
            experiment::Override::parse("design.draws=4").unwrap(),
            experiment::Override::parse("design.grid=5").unwrap(),
        ],
        ..ReadOptions::default()
    };
    let plan = Plan::read(&path, &read).unwrap();
    let crit = DesignCriterion::D;
    let aware = optimise(&plan, &crit).unwrap();
    let blind = jitter_blind(&plan, &crit).unwrap();
    let (a, b) = (
        aware.design.mean_dwell.unwrap(),
        blind.design.mean_dwell.unwrap(),
    );
    eprintln!(
        "aware dwell {a}: {}; blind dwell {b}: {} (promised {})",
        aware.value, blind.value, blind.blind_value
    );
    assert!(b < a, "blind {b} against aware {a}");
    assert!(blind.value > aware.value && blind.blind_value < blind.value);
    // The Monte Carlo, with the predictions on its own draws.
    let runs = 256;
    let seed = 11;
    let matched = plan.with_draws(runs, seed).unwrap();
    let mc_a = monte_carlo(&plan, &aware.design, &crit, runs as u64, seed).unwrap();
    let mc_b = monte_carlo(&plan, &blind.design, &crit, runs as u64, seed).unwrap();
    let (_, pa) = evaluate(&matched, &aware.design, &crit).unwrap();
    let (_, pb) = evaluate(&matched, &blind.design, &crit).unwrap();
    let mc_diff = mc_b.criterion - mc_a.criterion;
    let se = (mc_a.criterion_se.powi(2) + mc_b.criterion_se.powi(2)).sqrt();
    eprintln!(
        "log det: aware {pa} (MC {} ± {}), blind {pb} (MC {} ± {}); difference {} against MC {mc_diff} ± {se}",
        mc_a.criterion, mc_a.criterion_se, mc_b.criterion, mc_b.criterion_se, pb - pa
    );
    assert!(mc_a.used >= runs - 2 && mc_b.used >= runs - 2);
    assert!(
        (mc_diff - (pb - pa)).abs() <= 3.0 * se,
        "{mc_diff} ± {se} against {}",
        pb - pa
    );
    assert!(
        pb - pa > 3.0 * se,
        "predicted margin {} within the error {se}",
        pb - pa
    );
}

/// The predicted standard deviations at a design agree with a Monte Carlo there, for BCLS and
/// exact ML, within three of the Monte Carlo's standard errors (the prediction averaged over
/// the runs' own input draws).
#[test]
fn predicted_std_agrees_with_monte_carlo_for_both_estimators() {
    for estimator in ["bcls", "ml"] {
        let text = table2(&format!(
            "[design]\nmean_dwell = [1.0, 40.0]\nestimator = \"{estimator}\""
        ));
        let plan = plan(&text).unwrap();
        let d = Design {
            mean_dwell: Some(4.0),
            ..plan.baseline_design()
        };
        let runs = 40;
        let seed = 5;
        let p = plan.with_draws(runs, seed).unwrap().predict(&d).unwrap();
        let mc = monte_carlo(&plan, &d, &DesignCriterion::D, runs as u64, seed).unwrap();
        assert_eq!(p.names, mc.names);
        for i in 0..p.names.len() {
            eprintln!(
                "{estimator} {}: predicted {} MC {} ± {}",
                p.names[i], p.std[i], mc.std[i], mc.std_se[i]
            );
            assert!(
                (mc.std[i] - p.std[i]).abs() <= 3.0 * mc.std_se[i],
                "{estimator} {}",
                p.names[i]
            );
        }
    }
}

/// A budget: `[design] samples` gives every design that many samples; `[design] duration`
/// with the interval free keeps `N T` at the duration; budgets that cannot be met, and a
/// budget against `hold`, are refused naming the key.
#[test]
fn budgets_set_every_design_s_record() {
    let p = plan(&table2(
        "[design]\nmean_dwell = [2.0, 20.0]\nsamples = 120\ndraws = 1\ngrid = 3",
    ))
    .unwrap();
    assert_eq!(p.budget_design().samples, 120);
    assert_eq!(p.baseline_design().samples, 200);
    assert_eq!(
        optimise(&p, &DesignCriterion::D).unwrap().design.samples,
        120
    );
    let p = plan(&table2(
        "[design]\ninterval = [0.5, 2.0]\nduration = 150.0\ndraws = 1\ngrid = 3",
    ))
    .unwrap();
    let d = optimise(&p, &DesignCriterion::D).unwrap().design;
    assert_eq!(d.samples, (150.0 / d.interval).round() as usize, "{d:?}");
    for (section, want) in [
        (
            "[design]\nmean_dwell = [2.0, 20.0]\nsamples = 0",
            "[design] samples: a budget that cannot be met",
        ),
        (
            "[design]\nmean_dwell = [2.0, 20.0]\nduration = 0.2",
            "[design] duration: a budget that cannot be met",
        ),
        (
            "[design]\nmean_dwell = [2.0, 20.0]\nduration = 100.0\nsamples = 10",
            "[design] samples: a budget that cannot be met: give either",
        ),
        (
            "[design]\ninterval = [0.5, 2.0]\nduration = 100.0\nhold = \"samples\"",
            "[design] hold: \"samples\" contradicts the budget",
        ),
    ] {
        let e = parse(&table2(section)).unwrap_err();
        assert!(e.contains(want), "{section}: {e}");
    }
}
