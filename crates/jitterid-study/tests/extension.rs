//! Extensions written outside the workspace reach the study layer with one type and one
//! registry entry: an out-of-tree jitter family and an out-of-tree likelihood are read from an
//! experiment file, simulated, fitted and studied by Monte Carlo exactly as built-in ones.

use jitterid::estimate::ml::{Evaluation, GradientRequest, LikelihoodCriterion, LikelihoodData};
use jitterid::estimate::{AnyCriterion, CriterionEntry, MlError, ModelStructure, NoiseModel};
use jitterid::jitter::kernels::validate::{param_count, positive};
use jitterid::jitter::registry::{Family, ParamSpec};
use jitterid::jitter::{AnyJitter, JitterError, JitterModel, UniformSum};
use jitterid::num_complex::Complex64;
use jitterid::rand::{Rng, RngCore};
use jitterid::signal::Signal;
use jitterid_study::experiment::{self, Purpose};
use jitterid_study::montecarlo::montecarlo_values;
use jitterid_study::{fit, simulate, Registries, Watch};
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

/// The symmetric triangular density on `[-a, a]`: the sum of two independent uniforms on
/// `[-a/2, a/2]`, so that it is also the built-in uniform sum with `n = 1` (the cross-check
/// below), written here as a user would write a family of their own.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Triangle {
    a: f64,
}

impl Triangle {
    fn new(a: f64) -> Result<Self, JitterError> {
        Ok(Triangle {
            a: positive("a", a)?,
        })
    }
}

/// `sin(x)/x`: 1 at 0, and its limit 0 beyond the largest finite argument.
fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else if !x.is_finite() {
        0.0
    } else {
        x.sin() / x
    }
}

impl JitterModel for Triangle {
    fn name(&self) -> &'static str {
        "triangle"
    }
    fn param_names(&self) -> Vec<String> {
        vec!["a".into()]
    }
    fn params(&self) -> Vec<f64> {
        vec![self.a]
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 1, params)?;
        Triangle::new(params[0])
    }
    fn cf(&self, f: f64) -> Complex64 {
        // The characteristic function of one uniform on [-a/2, a/2], squared.
        Complex64::new(sinc(PI * f * self.a).powi(2), 0.0)
    }
    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        let x = PI * f * self.a;
        let d = if x == 0.0 || !x.is_finite() {
            0.0
        } else {
            // d/da sinc(x)² = 2 sinc(x) (cos x − sinc x)/a.
            2.0 * sinc(x) * (x.cos() - sinc(x)) / self.a
        };
        vec![Complex64::new(d, 0.0)]
    }
    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        let w = z * (0.5 * self.a);
        let one = if w.norm() < 1e-8 {
            Complex64::new(1.0, 0.0) + w * w / 6.0
        } else {
            w.sinh() / w
        };
        Some(one * one)
    }
    fn pdf(&self, tau: f64) -> f64 {
        let t = tau.abs();
        if t < self.a {
            (self.a - t) / (self.a * self.a)
        } else {
            0.0
        }
    }
    fn pieces(&self) -> Vec<(f64, f64)> {
        vec![(-self.a, 0.0), (0.0, self.a)]
    }
    fn mean(&self) -> f64 {
        0.0
    }
    fn variance(&self) -> f64 {
        self.a * self.a / 6.0
    }
    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        let h = 0.5 * self.a;
        rng.random_range(-h..h) + rng.random_range(-h..h)
    }
}

fn spec_of(t: &Triangle) -> jitterid::jitter::registry::SpecTable {
    let mut s = jitterid::jitter::registry::SpecTable::new();
    s.insert("a".into(), t.a.into());
    s
}

/// The built-in registries with the triangle family added: one entry.
fn registries() -> Arc<Registries> {
    let family = Family::new(
        "triangle",
        "symmetric triangular jitter on [-a, a]",
        vec![ParamSpec::new("a", "half-width of the support", "s", "> 0")],
        |r, _| {
            let t = Triangle::new(r.f64("a")?).map_err(|e| r.invalid("a", e))?;
            Ok(AnyJitter::new("triangle", t, spec_of))
        },
    )
    .with_std_dev(|sigma, _, _| {
        Ok(AnyJitter::new(
            "triangle",
            Triangle::new(sigma * 6f64.sqrt())?,
            spec_of,
        ))
    });
    let mut r = (*Registries::builtin()).clone();
    r.jitter.register(family).expect("a new family name");
    Arc::new(r)
}

/// The paper's Table 1 set-up (`G(s) = 1/(s + 2)` known, the jitter estimated) with the
/// triangle family.
const EXPERIMENT: &str = r#"
[sampling]
interval = 1.0
samples = 200

[input]
kind = "random-binary"
mean_dwell = 8.0

[system]
kind = "zpk"
gain = 1.0
poles = [-2.0]
estimate = false

[jitter]
family = "triangle"
a = 0.5
estimate = true

[noise]
std = 0.01

[estimate]
method = "bcls"
perturb = 0.2
"#;

#[test]
fn the_family_is_the_uniform_sum_of_two_terms() {
    let (t, u) = (
        Triangle::new(0.5).unwrap(),
        UniformSum::new(1, 0.5).unwrap(),
    );
    for f in [0.0, 0.1, 0.7, 1.3, 4.0] {
        assert!((t.cf(f) - u.cf(f)).norm() < 1e-15, "cf at {f}");
    }
    assert!((t.variance() - u.variance()).abs() < 1e-15);
    if let Err(report) = jitterid::jitter::testing::check_contract(&t, 7) {
        panic!("{report}");
    }
}

#[test]
fn the_built_in_registries_do_not_know_the_family() {
    let err = experiment::parse("e.toml", EXPERIMENT, Path::new("."), Purpose::Simulate)
        .unwrap_err()
        .to_string();
    assert!(err.contains("triangle"), "{err}");
}

#[test]
fn an_out_of_tree_family_is_fitted_and_studied_through_the_study_layer() {
    let registries = registries();
    let exp = experiment::parse_with(
        &registries,
        "e.toml",
        EXPERIMENT,
        Path::new("."),
        Purpose::Estimate(None),
        experiment::Paths::Inside,
    )
    .unwrap();
    assert_eq!(exp.jitter.model.name(), "triangle");

    // One record, simulated and fitted as `jitterid simulate` and `fit` do.
    let data = simulate::simulate_data(&exp, 11, 0).unwrap();
    let signal = fit::signal_of(&exp, &data.inputs).unwrap();
    let f = fit::fit_values(&exp, signal, data.y, "record", &Watch::none()).unwrap();
    assert!(f.converged, "{}", f.termination);
    assert_eq!(f.params[0].name, "jitter.a");
    let (a, se) = (f.params[0].estimate, f.params[0].stderr.unwrap());
    assert!((a - 0.5).abs() < 5.0 * se, "a = {a} ± {se}");

    // A Monte Carlo study: unbiased within its own standard error, and the same numbers on
    // one thread and on two.
    let one = montecarlo_values(&exp, 24, 3, None, Some(1)).unwrap();
    let two = montecarlo_values(&exp, 24, 3, None, Some(2)).unwrap();
    assert_eq!(one.parameters, two.parameters);
    assert_eq!(one.converged, 24);
    let p = &one.parameters[0];
    let (mean, mc_se) = (p.mean.unwrap(), p.se.unwrap());
    assert!((mean - 0.5).abs() < 4.0 * mc_se, "mean {mean} ± {mc_se}");
}

/// The Gaussian likelihood of the first moment alone, `y_k ~ N(m_k, σ_v²)` independent: the
/// jitter enters the mean `m_k = E[s(t_k + τ)]` but not the variance, so `σ_v` absorbs the
/// jitter's spread. A time-domain least squares with a likelihood's scale, written here as a
/// user would write a likelihood of their own: one type, then one registry entry.
#[derive(Debug, Clone, Copy)]
struct MeanGaussian;

impl LikelihoodCriterion for MeanGaussian {
    fn name(&self) -> &'static str {
        "mean-gaussian"
    }

    fn supports_coloured_noise(&self) -> bool {
        false
    }

    fn evaluate<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        data: &LikelihoodData,
        model: &ModelStructure<S, J, N>,
        noise_std: f64,
        gradient: GradientRequest,
    ) -> Result<Evaluation, MlError> {
        if !(noise_std > 0.0) {
            return Err(MlError::NoNoise { value: noise_std });
        }
        let record = data.record();
        let m = model.signal.expected_values(record.grid(), &model.jitter);
        let r: Vec<f64> = record.y().iter().zip(&m).map(|(y, m)| y - m).collect();
        let n = r.len() as f64;
        let s2 = noise_std * noise_std;
        let ss: f64 = r.iter().map(|r| r * r).sum();
        let nll = 0.5 * ss / s2 + n * noise_std.ln() + 0.5 * n * (2.0 * PI).ln();
        let signal_gradient = gradient.signal.then(|| {
            model
                .signal
                .expected_values_gradient(record.grid(), &model.jitter)
                .iter()
                .map(|dm| -r.iter().zip(dm).map(|(r, d)| r * d).sum::<f64>() / s2)
                .collect()
        });
        Ok(Evaluation {
            nll,
            signal_gradient,
            noise_std_gradient: gradient
                .noise_std
                .then(|| n / noise_std - ss / (s2 * noise_std)),
        })
    }
}

/// The built-in registries with the triangle family and the mean-Gaussian likelihood added:
/// one entry each.
fn registries_with_likelihood() -> Arc<Registries> {
    let mut r = (*registries()).clone();
    r.criteria
        .register(CriterionEntry::new(
            "mean-gaussian",
            "Gaussian likelihood of the first moment, the jitter's variance ignored",
            Vec::new(),
            |_| Ok(AnyCriterion::likelihood(MeanGaussian)),
        ))
        .expect("a new criterion name");
    Arc::new(r)
}

/// The system of Table 1 (`G(s) = 1/(s + 2)`) estimated with the triangle jitter known and the
/// noise level estimated, by the mean-Gaussian likelihood. The measurement noise dominates the
/// jitter's spread, so the likelihoods' default start of `σ_v` (the residuals' spread less the
/// jitter's) is near this criterion's optimum, which includes the jitter's spread.
const LIKELIHOOD_EXPERIMENT: &str = r#"
[sampling]
interval = 1.0
samples = 200

[input]
kind = "random-binary"
mean_dwell = 8.0

[system]
kind = "zpk"
gain = 1.0
poles = [-2.0]
estimate = true

[jitter]
family = "triangle"
a = 0.5

[noise]
std = 0.05
estimate = true

[estimate]
method = "mean-gaussian"
perturb = 0.2
"#;

#[test]
fn an_out_of_tree_likelihood_is_fitted_and_studied_through_the_study_layer() {
    let registries = registries_with_likelihood();
    let exp = experiment::parse_with(
        &registries,
        "e.toml",
        LIKELIHOOD_EXPERIMENT,
        Path::new("."),
        Purpose::Estimate(None),
        experiment::Paths::Inside,
    )
    .unwrap();
    assert!(exp.estimate.method.is_likelihood_in(&registries.criteria));

    // Its gradient in the signal's parameters against central differences of its value.
    let data = simulate::simulate_data(&exp, 5, 0).unwrap();
    let signal = fit::signal_of(&exp, &data.inputs).unwrap();
    let structure = fit::structure(&exp, signal.clone(), exp.estimate.method).unwrap();
    let record = jitterid::estimate::Record::new(exp.grid, data.y.clone()).unwrap();
    let prepared = MeanGaussian.prepare(&structure, &record);
    let all = GradientRequest {
        signal: true,
        noise_std: true,
    };
    let at = MeanGaussian
        .evaluate(&prepared, &structure, 0.02, all)
        .unwrap();
    let theta = structure.signal.params();
    for (j, g) in at.signal_gradient.unwrap().iter().enumerate() {
        let h = 1e-6 * theta[j].abs().max(1e-3);
        let nll = |d: f64| {
            let mut t = theta.clone();
            t[j] += d;
            let mut s = structure.clone();
            s.signal = s.signal.with_params(&t).unwrap();
            let plain = GradientRequest::default();
            MeanGaussian
                .evaluate(&prepared, &s, 0.02, plain)
                .unwrap()
                .nll
        };
        let fd = (nll(h) - nll(-h)) / (2.0 * h);
        assert!(
            (g - fd).abs() <= 1e-5 * fd.abs().max(1.0),
            "θ{j}: {g} vs {fd}"
        );
    }

    // One record fitted as `jitterid fit` does: the system and σ_v, a likelihood's report.
    let f = fit::fit_values(&exp, signal, data.y, "record", &Watch::none()).unwrap();
    assert!(f.converged, "{}", f.termination);
    let names: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["gain", "pole0", "noise.std"]);
    // σ_v absorbs the jitter's spread: above the measurement noise alone.
    assert!(
        f.params[2].estimate > 0.05,
        "σ_v = {}",
        f.params[2].estimate
    );
    assert!(
        f.params[2].stderr.is_some(),
        "a likelihood's σ_v has a standard error: {f:?}"
    );

    // A Monte Carlo study: the system unbiased within its standard error, and the same numbers
    // on one thread and on two.
    let one = montecarlo_values(&exp, 24, 3, None, Some(1)).unwrap();
    let two = montecarlo_values(&exp, 24, 3, None, Some(2)).unwrap();
    assert_eq!(one.parameters, two.parameters);
    assert_eq!(one.converged, 24);
    for (p, truth) in one.parameters.iter().zip([1.0, -2.0]) {
        let (mean, mc_se) = (p.mean.unwrap(), p.se.unwrap());
        assert!(
            (mean - truth).abs() < 4.0 * mc_se,
            "{}: mean {mean} ± {mc_se}",
            p.name
        );
    }
}
