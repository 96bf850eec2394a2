//! The registry entries of this crate's families.

use super::{Family, FamilyReader, JitterRegistry, ParamSpec, SpecReader, SpecTable};
use crate::{
    AnyJitter, ExponentialDelay, Gaussian, JitterError, JitterModel, Laplace, Mixture, NoJitter,
    Periodic, Shifted, Sum, TwoPoint, UniformSum,
};
use jitterid_numeric::limits::{self, Limit};
use serde_json::Value;

/// A spec table of the given keys and values.
pub(crate) fn spec_of<const N: usize>(pairs: [(&str, Value); N]) -> SpecTable {
    pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

/// An entry for a family with one positive parameter in seconds, written as key `key`, whose
/// standard deviation is `std_per_scale` times that parameter.
fn one_scale<T: JitterModel + Clone + PartialEq + 'static>(
    name: &'static str,
    summary: &'static str,
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

fn uniform_sum_spec(u: &UniformSum) -> SpecTable {
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
    let wrap = || AnyJitter::new("none", NoJitter, |_: &NoJitter| SpecTable::new());
    Family::new("none", "no jitter: τ = 0", Vec::new(), move |_, _| {
        Ok(wrap())
    })
    .with_std_dev(move |_, _, _| Ok(wrap()))
}

/// The spec tables of the terms of a (right-nested) sum, as one flat list.
fn sum_terms(s: &Sum<AnyJitter, AnyJitter>) -> Vec<Value> {
    let mut terms = vec![Value::Object(s.first().spec())];
    match s.second().downcast_ref::<Sum<AnyJitter, AnyJitter>>() {
        // A nested sum without an offset of its own continues the list.
        Some(inner) if s.second().spec().get(super::OFFSET_KEY).is_none() => {
            terms.extend(sum_terms(inner))
        }
        _ => terms.push(Value::Object(s.second().spec())),
    }
    terms
}

/// The leaf terms of `j` and how many of them have a density, counted through sums (whose
/// terms add), mixtures (the largest component counts: a component's density is evaluated
/// on its own) and offsets: what the limits on a sum bound, since each further term with a
/// density nests one more quadrature inside every density value.
fn term_counts(j: &AnyJitter) -> (usize, usize) {
    if let Some(s) = j.downcast_ref::<Sum<AnyJitter, AnyJitter>>() {
        let ((ta, da), (tb, db)) = (term_counts(s.first()), term_counts(s.second()));
        (ta + tb, da + db)
    } else if let Some(m) = j.downcast_ref::<Mixture<AnyJitter>>() {
        m.components()
            .iter()
            .map(term_counts)
            .fold((1, 0), |(t, d), (tc, dc)| (t.max(tc), d.max(dc)))
    } else if let Some(s) = j.downcast_ref::<Shifted<AnyJitter>>() {
        term_counts(s.inner())
    } else {
        (1, usize::from(!j.pieces().is_empty()))
    }
}

fn wrap_sum(s: Sum<AnyJitter, AnyJitter>) -> AnyJitter {
    AnyJitter::new("sum", s, |s: &Sum<AnyJitter, AnyJitter>| {
        spec_of([(super::TERMS_KEY, Value::Array(sum_terms(s)))])
    })
}

fn sum() -> Family {
    Family::new(
        "sum",
        "independent sum of two or more terms, each a spec table of its own (γ = Π γ_k)",
        Vec::new(),
        |r, registry| {
            let mut terms = r.terms(registry, 2, Limit::SumTerms)?;
            let (count, densities) = terms
                .iter()
                .map(term_counts)
                .fold((0, 0), |(t, d), (tc, dc)| (t + tc, d + dc));
            limits::check(Limit::SumTerms, count)?;
            limits::check(Limit::DensityTerms, densities)?;
            // Nest to the right: t0 + (t1 + (… + tn)).
            let mut acc = terms
                .pop()
                .ok_or_else(|| r.invalid(super::TERMS_KEY, "no terms"))?;
            while let Some(t) = terms.pop() {
                acc = wrap_sum(Sum::new(t, acc));
            }
            Ok(acc)
        },
    )
    .with_terms()
}

fn mixture_spec(m: &Mixture<AnyJitter>) -> SpecTable {
    let terms = m
        .components()
        .iter()
        .map(|c| Value::Object(c.spec()))
        .collect();
    let mut spec = spec_of([
        (super::TERMS_KEY, Value::Array(terms)),
        (
            "weights",
            m.weights().iter().copied().map(Value::from).collect(),
        ),
    ]);
    if m.fixed_weights() {
        spec.insert("fixed_weights".into(), true.into());
    }
    spec
}

fn mixture() -> Family {
    Family::new(
        "mixture",
        "with probability w_k, a draw of term k (two or more terms, each a spec table)",
        vec![
            ParamSpec::new(
                "weights",
                "probability of each term, in the order of `terms` (an array)",
                "",
                "each in (0, 1), summing to 1",
            ),
            ParamSpec::new(
                "fixed_weights",
                "true: the weights are known, not estimated",
                "",
                "true or false",
            )
            .boolean(false),
        ],
        |r, registry| {
            let terms = r.terms(registry, 2, Limit::MixtureComponents)?;
            let weights = r.f64_list("weights")?;
            let m = Mixture::new(terms, weights).map_err(|e| r.invalid("weights", e))?;
            let m = if r.bool_or("fixed_weights", false)? {
                m.with_fixed_weights()
            } else {
                m
            };
            Ok(AnyJitter::new("mixture", m, mixture_spec))
        },
    )
    .with_terms()
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
            "zero-mean Laplace (double exponential) of scale b",
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
        one_scale(
            "periodic",
            "τ = A sin φ, φ uniform: the arcsine law of a clock disturbed by a tone",
            "amplitude",
            "amplitude A of the sinusoidal disturbance (standard deviation A/√2)",
            Periodic::new,
            Periodic::amplitude,
            std::f64::consts::FRAC_1_SQRT_2,
        ),
        sum(),
        mixture(),
    ];
    let mut registry = JitterRegistry::new();
    for family in families {
        // The built-in names are distinct.
        let _ = registry.register(family);
    }
    registry
}
