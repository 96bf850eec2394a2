//! `[estimate]`: method, frequency set and solver.

use super::checks::{describe, number};
use super::diagnostics::Source;
use super::raw::RawEstimate;
use super::spec::{EstimateSpec, LikelihoodStart, Method, SolverName};
use crate::error::StudyResult;
use jitterid::estimate::Frequencies;
use jitterid::signal::SampleGrid;
use toml::Spanned;

const S: &str = "estimate";

pub(super) fn parse_estimate(
    cx: &Source,
    r: &RawEstimate,
    grid: &SampleGrid,
) -> StudyResult<EstimateSpec> {
    let method = match &r.method {
        None => Method::BCLS,
        Some(m) => Method::parse_in(&cx.registries.criteria, m.get_ref()).ok_or_else(|| {
            cx.err(
                S,
                "method",
                &m.span(),
                format!(
                    "unknown method \"{}\"; expected {}",
                    m.get_ref(),
                    Method::names_in(&cx.registries.criteria)
                ),
            )
        })?,
    };
    let frequencies = match &r.frequencies {
        None => Frequencies::Dft,
        Some(v) => parse_frequencies(cx, v, grid)?,
    };
    let solver = match &r.solver {
        None => SolverName::LM,
        Some(s) => parse_solver(cx, s)?,
    };
    let multistart = whole_number(
        cx,
        "multistart",
        r.multistart.as_ref(),
        0,
        1000,
        "extra starts",
    )?;
    let max_iterations = whole_number(
        cx,
        "max_iterations",
        r.max_iterations.as_ref(),
        1,
        1_000_000,
        "iterations",
    )?;
    Ok(EstimateSpec {
        method,
        frequencies,
        solver,
        multistart: multistart.map_or(0, |n| n as usize),
        multistart_radius: relative_size(
            cx,
            "multistart_radius",
            r.multistart_radius.as_ref(),
            0.5,
        )?,
        perturb: relative_size(cx, "perturb", r.perturb.as_ref(), 0.2)?,
        max_iterations,
        max_seconds: None,
        likelihood_start: LikelihoodStart::default(),
    })
}

fn parse_solver(cx: &Source, s: &Spanned<String>) -> StudyResult<SolverName> {
    SolverName::parse_in(&cx.registries.solvers, s.get_ref()).ok_or_else(|| {
        cx.err(
            S,
            "solver",
            &s.span(),
            format!(
                "unknown solver \"{}\"; expected {}",
                s.get_ref(),
                SolverName::names()
            ),
        )
    })
}

/// A whole number of `what` in `[min, max]`, if given.
fn whole_number(
    cx: &Source,
    key: &str,
    v: Option<&Spanned<i64>>,
    min: i64,
    max: i64,
    what: &str,
) -> StudyResult<Option<u64>> {
    let Some(v) = v else { return Ok(None) };
    let n = *v.get_ref();
    if !(min..=max).contains(&n) {
        return Err(cx.err(
            S,
            key,
            &v.span(),
            format!("expected a whole number of {what} in [{min}, {max}], found {n}"),
        ));
    }
    Ok(Some(n as u64))
}

/// A relative size in `[0, 10]`, or `default`.
fn relative_size(
    cx: &Source,
    key: &str,
    v: Option<&Spanned<f64>>,
    default: f64,
) -> StudyResult<f64> {
    let Some(v) = v else { return Ok(default) };
    let x = cx.finite(S, key, v)?;
    if (0.0..=10.0).contains(&x) {
        Ok(x)
    } else {
        Err(cx.err(
            S,
            key,
            &v.span(),
            format!("expected a relative size in [0, 10], found {x}"),
        ))
    }
}

fn parse_frequencies(
    cx: &Source,
    v: &Spanned<toml::Value>,
    grid: &SampleGrid,
) -> StudyResult<Frequencies> {
    const K: &str = "frequencies";
    let expected = "expected \"dft\", { min = …, max = … } (Hz) or a list of frequencies in Hz";
    let nyquist_period = 1.0 / grid.interval();
    let f = match v.get_ref() {
        toml::Value::String(s) if s == "dft" => Frequencies::Dft,
        toml::Value::Table(t) => {
            if let Some(k) = t.keys().find(|k| *k != "min" && *k != "max") {
                return Err(cx.err(
                    S,
                    K,
                    &v.span(),
                    format!("unknown key `{k}` in the band; expected min and max"),
                ));
            }
            let get = |k: &str| -> StudyResult<f64> {
                let x = t.get(k).ok_or_else(|| {
                    cx.err(S, K, &v.span(), format!("the band needs `{k}`; {expected}"))
                })?;
                number(x).filter(|x| x.is_finite()).ok_or_else(|| {
                    cx.err(
                        S,
                        K,
                        &v.span(),
                        format!(
                            "band `{k}`: expected a finite number of Hz, found {}",
                            describe(x)
                        ),
                    )
                })
            };
            let (min, max) = (get("min")?, get("max")?);
            if !(min >= 0.0 && min <= max) {
                return Err(cx.err(
                    S,
                    K,
                    &v.span(),
                    format!("expected 0 <= min <= max, found min = {min}, max = {max}"),
                ));
            }
            jitterid::window::FrequencySet::band(grid, min, max)
                .map_err(|e| cx.err(S, K, &v.span(), e))?;
            Frequencies::Band { min, max }
        }
        toml::Value::Array(a) => {
            let mut out = Vec::with_capacity(a.len());
            for (i, x) in a.iter().enumerate() {
                match number(x).filter(|x| x.is_finite() && *x >= 0.0 && *x < nyquist_period) {
                    Some(f) => out.push(f),
                    None => {
                        return Err(cx.err(S, K, &v.span(), format!("element {}: expected a frequency in [0, 1/T) = [0, {nyquist_period}) Hz, found {}", i + 1, describe(x))));
                    }
                }
            }
            if out.is_empty() {
                return Err(cx.err(S, K, &v.span(), "expected at least one frequency"));
            }
            jitterid::window::FrequencySet::list(grid, out.clone())
                .map_err(|e| cx.err(S, K, &v.span(), e))?;
            Frequencies::List(out)
        }
        other => {
            return Err(cx.err(
                S,
                K,
                &v.span(),
                format!("{expected}, found {}", describe(other)),
            ))
        }
    };
    Ok(f)
}
