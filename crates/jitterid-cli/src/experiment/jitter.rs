//! `[jitter]`: the family of the truth and of the model.

use super::diagnostics::Source;
use super::range;
use super::raw::RawJitter;
use super::spec::JitterSpec;
use crate::error::{CliError, CliResult};
use crate::models::AnyJitter;
use jitterid::jitter::{
    ExponentialDelay, Gaussian, JitterError, JitterModel, Laplace, NoJitter, Shifted, TwoPoint,
    UniformSum,
};
use jitterid::signal::SampleGrid;
use toml::Spanned;

const S: &str = "jitter";
const FAMILIES: &str =
    "\"none\", \"uniform-sum\", \"gaussian\", \"laplace\", \"two-point\" or \"exponential\"";

/// The keys that carry a family's parameters.
fn family_keys(family: &str) -> Option<&'static [&'static str]> {
    Some(match family {
        "none" => &[],
        "uniform-sum" => &["n", "a"],
        "gaussian" => &["sigma"],
        "laplace" => &["scale"],
        "two-point" => &["d"],
        "exponential" => &["mean"],
        _ => return None,
    })
}

pub(super) fn parse_jitter(cx: &Source, r: &RawJitter, grid: &SampleGrid) -> CliResult<JitterSpec> {
    let fam = cx.required(
        S,
        "family",
        &r.family,
        &format!("expected family = {FAMILIES}"),
    )?;
    let family = fam.get_ref().as_str();
    let Some(own) = family_keys(family) else {
        return Err(cx.err(
            S,
            "family",
            &fam.span(),
            format!("unknown jitter family \"{family}\"; expected {FAMILIES}"),
        ));
    };
    let mut allowed = vec!["family", "estimate", "offset", "fit_family", "n_range"];
    allowed.extend_from_slice(own);
    cx.only(S, &r.present(), "family", &allowed, family)?;
    let base = given_family(cx, r, family, own, grid)?;
    let offset = match &r.offset {
        Some(o) => Some(cx.checked(S, "offset", o, |x| range::offset(x, grid))?),
        None => None,
    };
    let truth = shifted(cx, base.clone(), offset)?;
    let estimate = r.estimate.as_ref().is_some_and(|e| *e.get_ref());
    let (model, family_differs, model_family) = match &r.fit_family {
        Some(ff) if ff.get_ref() != family => {
            let j = fitted_family(cx, ff, &base)?;
            (shifted(cx, j, offset)?, true, ff.get_ref().as_str())
        }
        _ => (truth.clone(), false, family),
    };
    if estimate && model.num_params() == 0 {
        return Err(cx.err_at(
            S,
            "estimate",
            r.estimate.as_ref(),
            format!("family \"{model_family}\" has no parameter to estimate; set estimate = false"),
        ));
    }
    let profiled = estimate && model_family == "uniform-sum" && offset.is_none();
    let n_range = n_range(cx, r.n_range.as_ref(), profiled)?;
    Ok(JitterSpec {
        truth,
        model,
        estimate,
        n_range,
        family_differs,
    })
}

/// The family given by `family` and its keys `own`.
fn given_family(
    cx: &Source,
    r: &RawJitter,
    family: &str,
    own: &[&str],
    grid: &SampleGrid,
) -> CliResult<AnyJitter> {
    let why = format!("family = \"{family}\" needs {}", own.join(", "));
    let positive = |key: &str, v: &Option<Spanned<f64>>| -> CliResult<f64> {
        let v = cx.required(S, key, v, &why)?;
        cx.positive(S, key, v)?;
        cx.checked(S, key, v, |x| range::width(x, grid))
    };
    let jerr = |key: &'static str| move |e: JitterError| cx.err_section(S, key, e);
    Ok(match family {
        "uniform-sum" => {
            let n = uniform_sum_n(cx, r.n.as_ref())?;
            let a = positive("a", &r.a)?;
            AnyJitter::UniformSum(UniformSum::new(n, a).map_err(jerr("a"))?)
        }
        "gaussian" => {
            AnyJitter::Gaussian(Gaussian::new(positive("sigma", &r.sigma)?).map_err(jerr("sigma"))?)
        }
        "laplace" => {
            AnyJitter::Laplace(Laplace::new(positive("scale", &r.scale)?).map_err(jerr("scale"))?)
        }
        "two-point" => AnyJitter::TwoPoint(TwoPoint::new(positive("d", &r.d)?).map_err(jerr("d"))?),
        "exponential" => AnyJitter::Exponential(
            ExponentialDelay::new(positive("mean", &r.mean)?).map_err(jerr("mean"))?,
        ),
        // `family_keys` accepted the name, and the only other accepted name is "none".
        _ => AnyJitter::None(NoJitter),
    })
}

fn uniform_sum_n(cx: &Source, v: Option<&Spanned<i64>>) -> CliResult<u32> {
    let Some(v) = v else { return Ok(0) };
    let n = *v.get_ref();
    u32::try_from(n)
        .ok()
        .filter(|n| *n <= UniformSum::MAX_N)
        .ok_or_else(|| {
            cx.err(
                S,
                "n",
                &v.span(),
                format!(
                    "expected a whole number in [0, {}], found {n}",
                    UniformSum::MAX_N
                ),
            )
        })
}

/// `j` moved by the constant `offset`, if one is given.
fn shifted(cx: &Source, j: AnyJitter, offset: Option<f64>) -> CliResult<AnyJitter> {
    match offset {
        Some(c) => Ok(AnyJitter::Shifted(Box::new(
            Shifted::new(j, c).map_err(|e| cx.err_section(S, "offset", e))?,
        ))),
        None => Ok(j),
    }
}

/// The model's family `fit_family`, started at the standard deviation of the given `base`.
fn fitted_family(cx: &Source, ff: &Spanned<String>, base: &AnyJitter) -> CliResult<AnyJitter> {
    let name = ff.get_ref().as_str();
    let fail = |m: String| -> CliError { cx.err(S, "fit_family", &ff.span(), m) };
    if family_keys(name).is_none() {
        return Err(fail(format!(
            "unknown jitter family \"{name}\"; expected {FAMILIES}"
        )));
    }
    let n = match base {
        AnyJitter::UniformSum(u) => u.n(),
        _ => 0,
    };
    family_with_std(name, base.std_dev(), n).map_err(fail)
}

/// A family with the standard deviation `sigma` (for `fit_family`); `n` for the uniform sum.
fn family_with_std(family: &str, sigma: f64, n: u32) -> Result<AnyJitter, String> {
    if family == "none" {
        return Ok(AnyJitter::None(NoJitter));
    }
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(format!("a fitted family \"{family}\" needs a given jitter with a spread (standard deviation > 0) to start from"));
    }
    let e = |e: JitterError| e.to_string();
    Ok(match family {
        "uniform-sum" => AnyJitter::UniformSum(
            UniformSum::new(n, sigma * (3.0 * (f64::from(n) + 1.0)).sqrt()).map_err(e)?,
        ),
        "gaussian" => AnyJitter::Gaussian(Gaussian::new(sigma).map_err(e)?),
        "laplace" => AnyJitter::Laplace(Laplace::new(sigma / 2f64.sqrt()).map_err(e)?),
        "two-point" => AnyJitter::TwoPoint(TwoPoint::new(sigma).map_err(e)?),
        "exponential" => AnyJitter::Exponential(ExponentialDelay::new(sigma).map_err(e)?),
        other => return Err(format!("unknown family \"{other}\"; expected {FAMILIES}")),
    })
}

/// The range of `n` profiled over: given, or `[0, 9]`, and only for a profiled uniform sum.
fn n_range(
    cx: &Source,
    v: Option<&Spanned<Vec<i64>>>,
    profiled: bool,
) -> CliResult<Option<(u32, u32)>> {
    match (v, profiled) {
        (Some(v), true) => {
            let l = v.get_ref();
            let max = i64::from(UniformSum::MAX_N);
            let ok = l.len() == 2 && l[0] >= 0 && l[0] <= l[1] && l[1] <= max;
            if !ok {
                return Err(cx.err(
                    S,
                    "n_range",
                    &v.span(),
                    format!("expected [min, max] with 0 <= min <= max <= {max}, found {l:?}"),
                ));
            }
            Ok(Some((l[0] as u32, l[1] as u32)))
        }
        (Some(v), false) => Err(cx.err(
            S,
            "n_range",
            &v.span(),
            "applies only when estimate = true and the fitted family is \"uniform-sum\" without an offset",
        )),
        (None, true) => Ok(Some((0, 9))),
        (None, false) => Ok(None),
    }
}
