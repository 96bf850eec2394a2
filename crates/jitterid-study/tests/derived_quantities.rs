//! Derived quantities of a design's prediction: a pole's natural frequency by the delta method
//! against its closed-form gradient and against a Monte Carlo of parameter draws from the
//! predicted covariance, and the `[design] derived` list: reported in the order asked, the
//! default unchanged, unknown or undefined names refused naming the key.

mod common;

use common::{plan, table2};
use jitterid::estimate::ml::delta_method_std;
use jitterid::rand::rngs::StdRng;
use jitterid::rand::{Rng, SeedableRng};
use jitterid_study::design::{derived_std, derived_stds, design, predict, Derived, DerivedRequest};
use jitterid_study::experiment::{self, DesignEstimator, Experiment, Purpose};
use std::f64::consts::TAU;
use std::path::Path;

fn parse(text: &str) -> Experiment {
    experiment::parse("exp.toml", text, Path::new("."), Purpose::Simulate).unwrap()
}

/// `|p|/2π` of the pair `re ± i·im` has the gradient `(re, im)/(2π|p|)` in `(pole0.re,
/// pole0.im)` and none in the gain and the zero: the delta method with it equals the central
/// differences' to 1e-6.
#[test]
fn pole_frequency_std_is_the_delta_method_with_the_closed_form_gradient() {
    let exp = parse(&table2(""));
    let p = predict(&exp, DesignEstimator::Bcls, 4, 9).unwrap();
    assert_eq!(p.names, ["gain", "zero0", "pole0.re", "pole0.im"]);
    let (re, im) = (-0.25_f64, 0.3_f64);
    let r = re.hypot(im);
    let grad = [0.0, 0.0, re / (TAU * r), im / (TAU * r)];
    let closed = delta_method_std(&p.covariance, &grad).unwrap();
    let derived = derived_std(&p, Derived::PoleFrequency(0)).unwrap();
    assert!(
        (derived - closed).abs() <= 1e-6 * closed,
        "{derived} against {closed}"
    );
    // One pair: there is no second pole frequency.
    let e = derived_std(&p, Derived::PoleFrequency(1)).unwrap_err();
    assert!(e.to_string().contains("pole2.frequency"), "{e}");
}

/// The lower Cholesky factor of a symmetric positive definite matrix.
fn cholesky(c: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = c.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            l[i][j] = if i == j {
                (c[i][i] - s).sqrt()
            } else {
                (c[i][j] - s) / l[j][j]
            };
        }
    }
    l
}

/// An independent route: parameters drawn from `N(θ, C)` (the prediction's covariance, by its
/// Cholesky factor and Box–Muller normals) and mapped to `|p|/2π` have the delta method's
/// standard deviation, within the sampling error of 20 000 draws (a relative standard error of
/// 0.5 %; the test allows 3 %, which also covers the map's curvature over a spread this small).
#[test]
fn pole_frequency_std_agrees_with_a_monte_carlo_of_parameter_draws() {
    let exp = parse(&table2(""));
    let p = predict(&exp, DesignEstimator::Bcls, 2, 4).unwrap();
    let l = cholesky(&p.covariance);
    let mut rng = StdRng::seed_from_u64(17);
    let mut normal = || {
        let (u, v): (f64, f64) = (rng.random::<f64>(), rng.random::<f64>());
        (-2.0 * (1.0 - u).ln()).sqrt() * (TAU * v).cos()
    };
    let n = 20_000;
    let mut values = Vec::with_capacity(n);
    for _ in 0..n {
        let z: Vec<f64> = (0..4).map(|_| normal()).collect();
        let theta: Vec<f64> = (0..4)
            .map(|i| p.truth[i] + (0..=i).map(|k| l[i][k] * z[k]).sum::<f64>())
            .collect();
        values.push(theta[2].hypot(theta[3]) / TAU);
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let delta = derived_std(&p, Derived::PoleFrequency(0)).unwrap();
    assert!(
        (sd / delta - 1.0).abs() < 0.03,
        "Monte Carlo {sd} against the delta method {delta}"
    );
}

/// `[design] derived` reports the quantities asked for, in that order (`pole_frequency`
/// expanding to every pole), each the delta method's std; without the key the report is the
/// default one.
#[test]
fn the_derived_key_chooses_the_reported_quantities() {
    let cheap = "[design]\nmean_dwell = [4.0, 16.0]\ndraws = 2\ngrid = 3\n";
    let asked = plan(&table2(&format!(
        "{cheap}derived = [\"gain@0.05\", \"pole_frequency\", \"jitter.sigma\", \"static_gain\"]"
    )))
    .unwrap();
    let report = design(&asked, None).unwrap();
    let json = report.json();
    let names: Vec<&str> = json.derived.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "|G|@0.05Hz",
            "pole1.frequency",
            "jitter.sigma",
            "static_gain"
        ]
    );
    let p = &report.prediction;
    for (d, q) in json.derived.iter().zip([
        Derived::Magnitude(0.05),
        Derived::PoleFrequency(0),
        Derived::JitterStd,
        Derived::StaticGain,
    ]) {
        assert_eq!(d.std, Some(derived_std(p, q).unwrap()), "{}", d.name);
    }
    assert_eq!(json.baseline.derived.len(), 4);
    // Without the key: the default (the static gain; the known jitter's σ left out).
    let default = design(&plan(&table2(cheap)).unwrap(), None).unwrap();
    assert_eq!(default.json().derived, derived_stds(&default.prediction));
    assert_eq!(default.json().derived.len(), 1);
}

/// Unknown names are refused when the file is read, undefined ones (a second pole of a
/// second-order model) before the search, both naming `[design] derived`.
#[test]
fn unknown_and_undefined_derived_quantities_are_refused_naming_the_key() {
    let cheap = "[design]\nmean_dwell = [4.0, 16.0]\ndraws = 2\ngrid = 3\n";
    for bad in [
        "\"bogus\"",
        "\"pole0.frequency\"",
        "\"gain@-1\"",
        "\"gain@x\"",
    ] {
        let e = plan(&table2(&format!("{cheap}derived = [{bad}]"))).unwrap_err();
        assert!(e.contains("[design] derived"), "{bad}: {e}");
    }
    let p = plan(&table2(&format!("{cheap}derived = [\"pole2.frequency\"]"))).unwrap();
    let e = design(&p, None).unwrap_err().to_string();
    assert!(
        e.contains("[design] derived") && e.contains("pole2.frequency"),
        "{e}"
    );
}

/// Every name reads back as written.
#[test]
fn derived_requests_parse_and_print_alike() {
    for text in [
        "static_gain",
        "pole_frequency",
        "pole2.frequency",
        "gain@0.05",
        "jitter.sigma",
    ] {
        assert_eq!(DerivedRequest::parse(text).unwrap().to_string(), text);
    }
    assert_eq!(
        DerivedRequest::parse("|G|@0.5Hz").unwrap(),
        DerivedRequest::parse("gain@0.5").unwrap()
    );
}
