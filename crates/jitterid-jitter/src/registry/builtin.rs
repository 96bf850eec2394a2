//! The registry entries of this crate's families.

use super::{Family, JitterRegistry, ParamSpec, Spec, SpecReader};
use crate::{
    AnyJitter, ExponentialDelay, Gaussian, JitterError, JitterModel, Laplace, NoJitter, TwoPoint,
    UniformSum,
};
use serde_json::Value;

/// A spec table of the given keys and values.
pub(crate) fn spec_of<const N: usize>(pairs: [(&str, Value); N]) -> Spec {
    pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

/// An entry for a family with one positive parameter in seconds, written as key `key`, whose
/// standard deviation is `std_per_scale` times that parameter.
fn one_scale<T: JitterModel + Clone + PartialEq + 'static>(
    name: &'static str,
    summary: &str,
    key: &'static str,
    meaning: &str,
    new: fn(f64) -> Result<T, JitterError>,
    get: fn(&T) -> f64,
    std_per_scale: f64,
) -> Family {
    let wrap =
        move |model: T| AnyJitter::new(name, model, move |m: &T| spec_of([(key, get(m).into())]));
    Family::new(
        name,
        summary,
        vec![ParamSpec::new(key, meaning, "s", "> 0")],
        move |r: &SpecReader<'_>, _: &JitterRegistry| {
            Ok(wrap(new(r.f64(key)?).map_err(|e| r.invalid(key, e))?))
        },
    )
    .with_std_dev(move |sigma, _, _| Ok(wrap(new(sigma / std_per_scale)?)))
}

fn uniform_sum_spec(u: &UniformSum) -> Spec {
    spec_of([("n", u.n().into()), ("a", u.a().into())])
}

fn uniform_sum() -> Family {
    let range = format!("whole number in [0, {}]", UniformSum::MAX_N);
    Family::new(
        "uniform-sum",
        "sum of n + 1 independent uniforms, support [-a, a] (the paper's eq. 15, corrected)",
        vec![
            ParamSpec::new("n", "number of uniform terms minus one", "", range)
                .integer()
                .with_default(0.0),
            ParamSpec::new("a", "half-width of the support", "s", "> 0"),
        ],
        |r, _| {
            let n = r.u32("n", UniformSum::MAX_N)?;
            let u = UniformSum::new(n, r.f64("a")?).map_err(|e| r.invalid("a", e))?;
            Ok(AnyJitter::new("uniform-sum", u, uniform_sum_spec))
        },
    )
    .with_std_dev(|sigma, r, _| {
        let n = r.u32("n", UniformSum::MAX_N)?;
        // Variance a²/(3(n+1)).
        let a = sigma * (3.0 * (f64::from(n) + 1.0)).sqrt();
        Ok(AnyJitter::new(
            "uniform-sum",
            UniformSum::new(n, a)?,
            uniform_sum_spec,
        ))
    })
}

fn none() -> Family {
    let wrap = || AnyJitter::new("none", NoJitter, |_: &NoJitter| Spec::new());
    Family::new("none", "no jitter: τ = 0", Vec::new(), move |_, _| {
        Ok(wrap())
    })
    .with_std_dev(move |_, _, _| Ok(wrap()))
}

/// The families of this crate.
pub(super) fn registry() -> JitterRegistry {
    let families = [
        none(),
        uniform_sum(),
        one_scale(
            "gaussian",
            "zero-mean Gaussian",
            "sigma",
            "standard deviation",
            Gaussian::new,
            Gaussian::sigma,
            1.0,
        ),
        one_scale(
            "laplace",
            "zero-mean Laplace (double exponential), density e^{-|τ|/b}/(2b)",
            "scale",
            "scale b (standard deviation b√2)",
            Laplace::new,
            Laplace::b,
            std::f64::consts::SQRT_2,
        ),
        one_scale(
            "two-point",
            "±d with probability 1/2 each",
            "d",
            "half-distance between the two points",
            TwoPoint::new,
            TwoPoint::d,
            1.0,
        ),
        one_scale(
            "exponential",
            "one-sided exponential delay τ ≥ 0",
            "mean",
            "mean delay (equal to the standard deviation)",
            ExponentialDelay::new,
            <ExponentialDelay as JitterModel>::mean,
            1.0,
        ),
    ];
    let mut registry = JitterRegistry::new();
    for family in families {
        // The built-in names are distinct.
        let _ = registry.register(family);
    }
    registry
}
