//! `[jitter]`: the family of the truth and of the model.
//!
//! The section is read without a fixed set of keys: besides the command line's own keys
//! (`family`, `estimate`, `offset`, `fit_family`, `n_range`) its keys are the chosen family's
//! parameters, described by [`FamilyParam`]s, so that a family brings its keys with it.

use super::checks::describe;
use super::diagnostics::{unknown_key, Source};
use super::range;
use super::raw::RawTable;
use super::spec::JitterSpec;
use crate::error::{CliError, CliResult};
use crate::models::AnyJitter;
use jitterid::jitter::{
    ExponentialDelay, Gaussian, JitterError, JitterModel, Laplace, NoJitter, Shifted, TwoPoint,
    UniformSum,
};
use jitterid::signal::SampleGrid;
use std::collections::BTreeMap;
use toml::Spanned;

const S: &str = "jitter";
/// The keys of `[jitter]` that belong to the command line, not to a family.
const OWN_KEYS: &[&str] = &["family", "estimate", "offset", "fit_family", "n_range"];

/// One parameter key of a family, as the experiment file gives it.
#[derive(Debug, Clone, Copy)]
struct FamilyParam {
    key: &'static str,
    /// A whole number (the uniform sum's `n`); otherwise a time scale in seconds.
    integer: bool,
    default: Option<f64>,
}

const fn time(key: &'static str) -> FamilyParam {
    FamilyParam {
        key,
        integer: false,
        default: None,
    }
}

/// The families, each with its parameter keys.
const FAMILIES: &[(&str, &[FamilyParam])] = &[
    ("none", &[]),
    (
        "uniform-sum",
        &[
            FamilyParam {
                key: "n",
                integer: true,
                default: Some(0.0),
            },
            time("a"),
        ],
    ),
    ("gaussian", &[time("sigma")]),
    ("laplace", &[time("scale")]),
    ("two-point", &[time("d")]),
    ("exponential", &[time("mean")]),
];

fn family_params(name: &str) -> Option<&'static [FamilyParam]> {
    FAMILIES.iter().find(|(n, _)| *n == name).map(|f| f.1)
}

fn family_names() -> String {
    let names: Vec<String> = FAMILIES.iter().map(|(n, _)| format!("\"{n}\"")).collect();
    names.join(", ")
}

pub(super) fn parse_jitter(cx: &Source, r: &RawTable, grid: &SampleGrid) -> CliResult<JitterSpec> {
    let why = format!("expected family = {}", family_names());
    let fam = r
        .get("family")
        .ok_or_else(|| cx.err_section(S, "family", format!("missing; {why}")))?;
    let family = cx.string_value(S, "family", fam)?;
    let params = family_params(family).ok_or_else(|| {
        cx.err(
            S,
            "family",
            &fam.span(),
            format!("unknown jitter family \"{family}\"; {why}"),
        )
    })?;
    check_keys(cx, r, family, params)?;
    let base = build(cx, r, family, params, grid)?;
    let offset = match r.get("offset") {
        Some(o) => {
            let x = cx.number_value(S, "offset", o)?;
            Some(range::offset(x, grid).map_err(|m| cx.err(S, "offset", &o.span(), m))?)
        }
        None => None,
    };
    let truth = shifted(cx, base.clone(), offset)?;
    let estimate = match r.get("estimate") {
        Some(e) => cx.bool_value(S, "estimate", e)?,
        None => false,
    };
    let (model, family_differs, model_family) = match r.get("fit_family") {
        Some(ff) if cx.string_value(S, "fit_family", ff)? != family => {
            let (j, name) = fitted_family(cx, ff, &base)?;
            (shifted(cx, j, offset)?, true, name)
        }
        _ => (truth.clone(), false, family),
    };
    if estimate && model.num_params() == 0 {
        return Err(cx.err_at(
            S,
            "estimate",
            r.get("estimate"),
            format!("family \"{model_family}\" has no parameter to estimate; set estimate = false"),
        ));
    }
    let profiled = estimate && model_family == "uniform-sum" && offset.is_none();
    let n_range = n_range(cx, r.get("n_range"), profiled)?;
    Ok(JitterSpec {
        truth,
        model,
        estimate,
        n_range,
        family_differs,
    })
}

/// Every key is the command line's or the family's.
fn check_keys(cx: &Source, r: &RawTable, family: &str, params: &[FamilyParam]) -> CliResult<()> {
    let mut allowed: Vec<&str> = OWN_KEYS.to_vec();
    allowed.extend(params.iter().map(|p| p.key));
    for (key, v) in r {
        if allowed.contains(&key.as_str()) {
            continue;
        }
        let of_another = FAMILIES
            .iter()
            .any(|(_, ps)| ps.iter().any(|p| p.key == key));
        let msg = if of_another {
            format!(
                "not a key of family = \"{family}\"; expected {}",
                allowed.join(", ")
            )
        } else {
            let mut known: Vec<&str> = OWN_KEYS.to_vec();
            known.extend(FAMILIES.iter().flat_map(|(_, ps)| ps.iter().map(|p| p.key)));
            unknown_key(key, &known, &allowed.join(", "))
        };
        return Err(cx.err(S, key, &v.span(), msg));
    }
    Ok(())
}

/// The family's parameters from the file: whole numbers where the family says so, time
/// scales within the representable range otherwise.
fn param_values<'p>(
    cx: &Source,
    r: &RawTable,
    family: &str,
    params: &'p [FamilyParam],
    grid: &SampleGrid,
) -> CliResult<BTreeMap<&'p str, f64>> {
    let needs: Vec<&str> = params.iter().map(|p| p.key).collect();
    let why = format!("missing; family = \"{family}\" needs {}", needs.join(", "));
    let mut out = BTreeMap::new();
    for p in params {
        let x = match (r.get(p.key), p.default) {
            (None, Some(d)) => d,
            (None, None) => return Err(cx.err_section(S, p.key, &why)),
            (Some(v), _) if p.integer => cx.integer_value(S, p.key, v)? as f64,
            (Some(v), _) => {
                let x = cx.number_value(S, p.key, v)?;
                if !(x > 0.0) {
                    return Err(cx.err(
                        S,
                        p.key,
                        &v.span(),
                        format!("expected a number > 0, found {x}"),
                    ));
                }
                range::width(x, grid).map_err(|m| cx.err(S, p.key, &v.span(), m))?
            }
        };
        out.insert(p.key, x);
    }
    Ok(out)
}

/// The family `family` with the file's parameters; a constructor's refusal names its key.
fn build(
    cx: &Source,
    r: &RawTable,
    family: &str,
    params: &[FamilyParam],
    grid: &SampleGrid,
) -> CliResult<AnyJitter> {
    let v = param_values(cx, r, family, params, grid)?;
    let at = |key: &'static str| move |e: JitterError| cx.err_at(S, key, r.get(key), e);
    let x = |key: &str| v.get(key).copied().unwrap_or(f64::NAN);
    Ok(match family {
        "uniform-sum" => {
            let n = x("n");
            let n = u32::try_from(n as i64)
                .ok()
                .filter(|n| *n <= UniformSum::MAX_N)
                .ok_or_else(|| {
                    cx.err_at(
                        S,
                        "n",
                        r.get("n"),
                        format!(
                            "expected a whole number in [0, {}], found {n}",
                            UniformSum::MAX_N
                        ),
                    )
                })?;
            AnyJitter::UniformSum(UniformSum::new(n, x("a")).map_err(at("a"))?)
        }
        "gaussian" => AnyJitter::Gaussian(Gaussian::new(x("sigma")).map_err(at("sigma"))?),
        "laplace" => AnyJitter::Laplace(Laplace::new(x("scale")).map_err(at("scale"))?),
        "two-point" => AnyJitter::TwoPoint(TwoPoint::new(x("d")).map_err(at("d"))?),
        "exponential" => {
            AnyJitter::Exponential(ExponentialDelay::new(x("mean")).map_err(at("mean"))?)
        }
        // `family_params` accepted the name, and the only other name is "none".
        _ => AnyJitter::None(NoJitter),
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
fn fitted_family<'v>(
    cx: &Source,
    ff: &'v Spanned<toml::Value>,
    base: &AnyJitter,
) -> CliResult<(AnyJitter, &'v str)> {
    let name = cx.string_value(S, "fit_family", ff)?;
    let fail = |m: String| -> CliError { cx.err(S, "fit_family", &ff.span(), m) };
    if family_params(name).is_none() {
        return Err(fail(format!(
            "unknown jitter family \"{name}\"; expected {}",
            family_names()
        )));
    }
    let n = match base {
        AnyJitter::UniformSum(u) => u.n(),
        _ => 0,
    };
    Ok((
        family_with_std(name, base.std_dev(), n).map_err(fail)?,
        name,
    ))
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
        other => {
            return Err(format!(
                "unknown family \"{other}\"; expected {}",
                family_names()
            ))
        }
    })
}

/// The range of `n` profiled over: given, or `[0, 9]`, and only for a profiled uniform sum.
fn n_range(
    cx: &Source,
    v: Option<&Spanned<toml::Value>>,
    profiled: bool,
) -> CliResult<Option<(u32, u32)>> {
    let max = i64::from(UniformSum::MAX_N);
    let expected = format!("expected [min, max] with 0 <= min <= max <= {max}");
    match (v, profiled) {
        (Some(v), true) => {
            let l: Vec<i64> = match v.get_ref() {
                toml::Value::Array(a) => a.iter().filter_map(|x| x.as_integer()).collect(),
                _ => Vec::new(),
            };
            let whole = matches!(v.get_ref(), toml::Value::Array(a) if a.len() == l.len());
            let ok = whole && l.len() == 2 && l[0] >= 0 && l[0] <= l[1] && l[1] <= max;
            if !ok {
                return Err(cx.err(
                    S,
                    "n_range",
                    &v.span(),
                    if whole {
                        format!("{expected}, found {l:?}")
                    } else {
                        format!("{expected}, found {}", describe(v.get_ref()))
                    },
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
