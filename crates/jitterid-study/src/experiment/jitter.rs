//! `[jitter]`: the family of the truth and of the model, from the library's registry.
//!
//! Besides the command line's own keys (`estimate`, `fit_family`, `n_range`) the section is a
//! spec table of [`JitterRegistry`]: `family`, that family's keys (described by its
//! [`ParamSpec`](jitterid::jitter::registry::ParamSpec)s), `offset`, and for a composite family
//! `[[jitter.terms]]`, each term a spec table of its own. A family registered in the library
//! reaches the file with no change here.

use super::diagnostics::{unknown_key, Source};
use super::range;
use super::raw::RawTable;
use super::spec::JitterSpec;
use crate::error::{StudyError, StudyResult};
use jitterid::jitter::registry::{Family, SpecTable, FAMILY_KEY, OFFSET_KEY, TERMS_KEY};
use jitterid::jitter::{AnyJitter, JitterError, JitterModel, NoJitter, UniformSum};
use jitterid::signal::SampleGrid;
use serde_json::Value;
use toml::Spanned;

const S: &str = "jitter";
/// The keys of `[jitter]` that belong to the command line, not to the spec table.
const OWN_KEYS: &[&str] = &["estimate", "fit_family", "n_range"];

pub(super) fn parse_jitter(
    cx: &Source,
    r: &RawTable,
    grid: &SampleGrid,
) -> StudyResult<JitterSpec> {
    let registry = &cx.registries.jitter;
    let fam = r.get(FAMILY_KEY).ok_or_else(|| {
        cx.err_section(
            S,
            FAMILY_KEY,
            format!("missing; expected family = {}", registry.names()),
        )
    })?;
    let family = cx.string_value(S, FAMILY_KEY, fam)?;
    let entry = registry.family(family).ok_or_else(|| {
        cx.err(
            S,
            FAMILY_KEY,
            &fam.span(),
            format!(
                "unknown jitter family \"{family}\"; expected {}",
                registry.names()
            ),
        )
    })?;
    check_keys(cx, r, entry)?;
    let spec = spec_table(r)?;
    check_ranges(cx, r, &spec, "", grid)?;
    let truth = registry.build(&spec).map_err(|e| jitter_error(cx, r, e))?;
    let estimate = match r.get("estimate") {
        Some(e) => cx.bool_value(S, "estimate", e)?,
        None => false,
    };
    let (model, family_differs) = match r.get("fit_family") {
        Some(ff) if cx.string_value(S, "fit_family", ff)? != family => {
            (fitted_family(cx, ff, &truth, &spec)?, true)
        }
        _ => (truth.clone(), false),
    };
    if estimate && model.num_params() == 0 {
        return Err(cx.err_at(
            S,
            "estimate",
            r.get("estimate"),
            format!(
                "family \"{}\" has no parameter to estimate; set estimate = false",
                model.family()
            ),
        ));
    }
    let n_range = n_range(cx, r.get("n_range"), estimate && profiled(&model))?;
    Ok(JitterSpec {
        truth,
        model,
        estimate,
        n_range,
        family_differs,
    })
}

/// No jitter, and nothing of it estimated (the default without a `[jitter]` section).
pub(super) fn no_jitter() -> JitterSpec {
    let none = AnyJitter::new("none", NoJitter, |_| SpecTable::new());
    JitterSpec {
        truth: none.clone(),
        model: none,
        estimate: false,
        n_range: None,
        family_differs: false,
    }
}

/// Whether an estimated `model` has its whole-number parameter profiled: the uniform sum
/// without an offset (the library's profile is over its `n`).
pub(super) fn profiled(model: &AnyJitter) -> bool {
    model.downcast_ref::<UniformSum>().is_some()
}

/// Every key is the command line's or the family's; a typo gets a suggestion.
fn check_keys(cx: &Source, r: &RawTable, entry: &Family) -> StudyResult<()> {
    let mut allowed: Vec<&str> = entry.keys();
    allowed.extend_from_slice(OWN_KEYS);
    let Some((key, v)) = r.iter().find(|(k, _)| !allowed.contains(&k.as_str())) else {
        return Ok(());
    };
    let registry = &cx.registries.jitter;
    let of_another = registry
        .families()
        .any(|f| f.keys().contains(&key.as_str()));
    let msg = if of_another {
        format!(
            "not a key of family = \"{}\"; expected {}",
            entry.name(),
            allowed.join(", ")
        )
    } else {
        let mut known: Vec<&str> = registry.families().flat_map(|f| f.keys()).collect();
        known.extend_from_slice(OWN_KEYS);
        unknown_key(key, &known, &allowed.join(", "))
    };
    Err(cx.err(S, key, &v.span(), msg))
}

/// The section as the registry's spec table (the command line's own keys left out).
fn spec_table(r: &RawTable) -> StudyResult<SpecTable> {
    r.iter()
        .filter(|(k, _)| !OWN_KEYS.contains(&k.as_str()))
        .map(|(k, v)| {
            serde_json::to_value(v.get_ref())
                .map(|v| (k.clone(), v))
                .map_err(|e| crate::study_err!("[jitter] {k}: {e}"))
        })
        .collect()
}

/// Time scales (keys in seconds) and offsets within the representable range, in the spec
/// and in each of its terms (`path` is the prefix of a term's keys, `terms.<i>.`).
fn check_ranges(
    cx: &Source,
    r: &RawTable,
    spec: &SpecTable,
    path: &str,
    grid: &SampleGrid,
) -> StudyResult<()> {
    let registry = &cx.registries.jitter;
    let entry = spec
        .get(FAMILY_KEY)
        .and_then(Value::as_str)
        .and_then(|name| registry.family(name));
    let seconds = entry
        .into_iter()
        .flat_map(|f| f.params())
        .filter(|p| p.unit == "s" && !p.integer)
        .map(|p| p.key.as_str());
    for key in seconds {
        if let Some(x) = spec.get(key).and_then(Value::as_f64).filter(|x| *x > 0.0) {
            range::width(x, grid).map_err(|m| located(cx, r, &format!("{path}{key}"), m))?;
        }
    }
    if let Some(x) = spec.get(OFFSET_KEY).and_then(Value::as_f64) {
        range::offset(x, grid).map_err(|m| located(cx, r, &format!("{path}{OFFSET_KEY}"), m))?;
    }
    if let Some(Value::Array(terms)) = spec.get(TERMS_KEY) {
        for (i, term) in terms.iter().enumerate() {
            if let Some(t) = term.as_object() {
                check_ranges(cx, r, t, &format!("{path}{TERMS_KEY}.{i}."), grid)?;
            }
        }
    }
    Ok(())
}

/// An error about the key `path` of the section: `key`, or `terms.<i>.key` for a term's key
/// (located in the `i`-th `[[jitter.terms]]` table).
fn located(cx: &Source, r: &RawTable, path: &str, msg: impl std::fmt::Display) -> StudyError {
    let term = path
        .strip_prefix("terms.")
        .and_then(|rest| rest.split_once('.'))
        .and_then(|(i, key)| Some((i.parse::<usize>().ok()?, key)));
    match term {
        Some((i, key)) => {
            let line = cx
                .array_table_key_line("jitter.terms", i, key)
                .or_else(|| r.get(TERMS_KEY).map(|t| cx.line_of_span(&t.span())));
            cx.err_on_line(S, path, line, msg)
        }
        None => cx.err_at(S, path, r.get(path), msg),
    }
}

/// A registry error, located at the key it names.
fn jitter_error(cx: &Source, r: &RawTable, e: JitterError) -> StudyError {
    match e.key() {
        Some(key) => {
            let key = key.to_string();
            located(cx, r, &key, e)
        }
        None => cx.err_section(S, FAMILY_KEY, e),
    }
}

/// The model's family `fit_family`, started at the standard deviation of the given `truth`;
/// the given whole-number keys (the uniform sum's `n`) and `offset` carry over.
fn fitted_family(
    cx: &Source,
    ff: &Spanned<toml::Value>,
    truth: &AnyJitter,
    spec: &SpecTable,
) -> StudyResult<AnyJitter> {
    let registry = &cx.registries.jitter;
    let name = cx.string_value(S, "fit_family", ff)?;
    let fail = |m: String| -> StudyError { cx.err(S, "fit_family", &ff.span(), m) };
    let entry = registry.family(name).ok_or_else(|| {
        fail(format!(
            "unknown jitter family \"{name}\"; expected {}",
            registry.names()
        ))
    })?;
    let sigma = truth.std_dev();
    if name != "none" && !(sigma.is_finite() && sigma > 0.0) {
        return Err(fail(format!("a fitted family \"{name}\" needs a given jitter with a spread (standard deviation > 0) to start from")));
    }
    let mut structural = SpecTable::new();
    for p in entry.params().iter().filter(|p| p.integer) {
        if let Some(v) = spec.get(&p.key) {
            structural.insert(p.key.clone(), v.clone());
        }
    }
    if let Some(v) = spec.get(OFFSET_KEY) {
        structural.insert(OFFSET_KEY.into(), v.clone());
    }
    if name == "none" {
        structural.insert(FAMILY_KEY.into(), name.into());
        return registry.build(&structural).map_err(|e| fail(e.to_string()));
    }
    registry
        .from_std_dev(name, sigma, &structural)
        .map_err(|e| fail(e.to_string()))
}

/// The range of `n` profiled over: given, or `[0, 9]`, and only for a profiled model.
fn n_range(
    cx: &Source,
    v: Option<&Spanned<toml::Value>>,
    profiled: bool,
) -> StudyResult<Option<(u32, u32)>> {
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
                let found = if whole {
                    format!("{l:?}")
                } else {
                    super::checks::describe(v.get_ref())
                };
                return Err(cx.err(S, "n_range", &v.span(), format!("{expected}, found {found}")));
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
