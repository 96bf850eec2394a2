//! `[system]`: zeros, poles and gain, a transfer function, or a sinusoid.

use super::checks::{describe, number};
use super::diagnostics::Source;
use super::range;
use super::raw::{RawOutput, RawSystem};
use super::spec::{quoted_list, SystemSpec};
use crate::error::StudyResult;
use jitterid::signal::greybox::{ExprModel, GreyBox};
use jitterid::signal::registry::{roots_json, SignalKind, SignalRegistry, SpecTable, KIND_KEY};
use jitterid::signal::{PiecewiseConstant, Root, SampleGrid, Sinusoid, TransferFunction, Zpk};
use serde_json::{json, Value};
use toml::Spanned;

const S: &str = "system";

/// Keys of `[system]` the command line reads itself rather than passing to the kind.
const OWN_KEYS: &[&str] = &["estimate"];

/// Keys of a kind's spec table that the command line sets itself: a free response starts at
/// the record's first instant; the output offset comes from `[output]`, the input's level from
/// `[input]`.
const SET_HERE: &[&str] = &[
    "origin",
    "offset",
    "estimate_offset",
    "level",
    "estimate_level",
];

/// The keys `[system]` takes for `kind`: `kind`, the kind's registry keys (but those set here)
/// and the command line's own.
fn keys_of(kind: &SignalKind) -> Vec<&str> {
    let mut keys = vec![KIND_KEY];
    keys.extend(
        kind.params()
            .iter()
            .map(|p| p.key.as_str())
            .filter(|k| !SET_HERE.contains(k)),
    );
    keys.extend(OWN_KEYS);
    keys
}

/// The registry keys of `kind` that `[system]` has no place for (a kind added to the signal
/// registry whose keys the experiment file cannot hold yet).
fn unwritable(kind: &SignalKind) -> Vec<&str> {
    keys_of(kind)
        .into_iter()
        .filter(|k| !RawSystem::KEYS.contains(k))
        .collect()
}

/// The signal registry's kinds that an experiment file can describe, quoted, for messages.
pub(super) fn kinds(registry: &SignalRegistry) -> String {
    let names: Vec<&str> = registry
        .kinds()
        .filter(|k| unwritable(k).is_empty())
        .map(SignalKind::name)
        .collect();
    quoted_list(&names)
}

pub(super) fn parse_system(
    cx: &Source,
    r: &RawSystem,
    grid: &SampleGrid,
) -> StudyResult<SystemSpec> {
    let kinds = kinds(&cx.registries.signal);
    let kind = cx.required(S, "kind", &r.kind, &format!("expected kind = {kinds}"))?;
    let name = kind.get_ref().as_str();
    let Some(entry) = cx.registries.signal.kind(name) else {
        return Err(cx.err(
            S,
            "kind",
            &kind.span(),
            format!("unknown system kind \"{name}\"; expected {kinds}"),
        ));
    };
    let missing = unwritable(entry);
    if !missing.is_empty() {
        return Err(cx.err(
            S,
            "kind",
            &kind.span(),
            format!(
                "the signal kind \"{name}\" ({}) takes {}, which an experiment file cannot give; expected {kinds}",
                entry.summary(),
                missing.join(", ")
            ),
        ));
    }
    cx.only(S, &r.present(), "kind", &keys_of(entry), name)?;
    // The range checks of the kinds the command line knows well; the registry builds every
    // other kind from its keys.
    let kind = match name {
        "zpk" => zpk(cx, r, grid)?,
        "tf" => tf(cx, r, grid)?,
        "sinusoid" => sinusoid(cx, r, grid)?,
        "grey-box" => grey_box(cx, r, grid)?,
        other => {
            return Err(cx.err(
                S,
                "kind",
                &kind.span(),
                format!(
                "the command line has no reader for the signal kind \"{other}\"; expected {kinds}"
            ),
            ))
        }
    };
    let kind = response_keys(cx, r, grid, kind)?;
    let estimate = r.estimate.as_ref().is_some_and(|e| *e.get_ref());
    Ok(SystemSpec { kind, estimate })
}

fn zpk(cx: &Source, r: &RawSystem, grid: &SampleGrid) -> StudyResult<SpecTable> {
    let why = "kind = \"zpk\" needs gain, poles and optionally zeros";
    let g = cx.required(S, "gain", &r.gain, why)?;
    let gain = cx.checked(S, "gain", g, range::gain)?;
    let p = cx.required(S, "poles", &r.poles, why)?;
    let poles = parse_roots(cx, "poles", p)?;
    range::poles(range::root_moduli(&poles), grid).map_err(|m| cx.err(S, "poles", &p.span(), m))?;
    let zeros = match &r.zeros {
        Some(z) => {
            let zeros = parse_roots(cx, "zeros", z)?;
            range::zeros(&zeros, grid).map_err(|m| cx.err(S, "zeros", &z.span(), m))?;
            zeros
        }
        None => Vec::new(),
    };
    let unstable = r.unstable.as_ref().is_some_and(|u| *u.get_ref());
    let zpk = if unstable {
        Zpk::new_allowing_unstable(gain, zeros, poles)
    } else {
        Zpk::new(gain, zeros, poles)
    };
    let zpk = zpk.map_err(|e| cx.err(S, "poles", &p.span(), e))?;
    range::response(&zpk, grid).map_err(|m| cx.err(S, "gain", &g.span(), m))?;
    let order = zpk.poles().iter().map(Root::count).sum();
    let n = integrators(cx, r, order, |n| zpk.with_integrators(n).map(|_| ()))?;
    Ok(with_integrators(
        with_unstable(
            spec(
                "zpk",
                [
                    ("gain", json!(zpk.gain())),
                    ("zeros", roots_json(zpk.zeros())),
                    ("poles", roots_json(zpk.poles())),
                ],
            ),
            unstable,
        ),
        n,
    ))
}

fn tf(cx: &Source, r: &RawSystem, grid: &SampleGrid) -> StudyResult<SpecTable> {
    let why = "kind = \"tf\" needs num and den (highest power first)";
    let n = cx.required(S, "num", &r.num, why)?;
    let d = cx.required(S, "den", &r.den, why)?;
    let num = cx.finite_list(S, "num", n)?;
    let den = cx.finite_list(S, "den", d)?;
    let unstable = r.unstable.as_ref().is_some_and(|u| *u.get_ref());
    let tf = if unstable {
        TransferFunction::new_allowing_unstable(&num, &den)
    } else {
        TransferFunction::new(&num, &den)
    };
    let tf = tf.map_err(|e| cx.err(S, "den", &d.span(), e))?;
    range::response(&tf, grid).map_err(|m| cx.err(S, "den", &d.span(), m))?;
    if tf.num().iter().all(|b| *b == 0.0) {
        return Err(cx.err(
            S,
            "num",
            &n.span(),
            "expected a nonzero numerator (a zero gain gives no signal to identify)",
        ));
    }
    let order = tf.den().len() - 1;
    let n = integrators(cx, r, order, |n| tf.with_integrators(n).map(|_| ()))?;
    Ok(with_integrators(
        with_unstable(
            spec("tf", [("num", json!(tf.num())), ("den", json!(tf.den()))]),
            unstable,
        ),
        n,
    ))
}

/// A grey-box model, checked by building it on a unit step: the expressions, the shapes, the
/// bounds, the stability and the poles' range, each error at its key.
fn grey_box(cx: &Source, r: &RawSystem, grid: &SampleGrid) -> StudyResult<SpecTable> {
    let why = "kind = \"grey-box\" needs params, a, b and c (and optionally fixed, bounds, d)";
    let mut table = SpecTable::new();
    table.insert(KIND_KEY.into(), json!("grey-box"));
    let keys = [
        ("params", &r.params),
        ("fixed", &r.fixed),
        ("bounds", &r.bounds),
        ("a", &r.a),
        ("b", &r.b),
        ("c", &r.c),
        ("d", &r.d),
    ];
    let mut spans = Vec::new();
    for (key, v) in keys {
        let Some(v) = v else {
            if matches!(key, "params" | "a" | "b" | "c") {
                cx.required(S, key, v, why)?;
            }
            continue;
        };
        // TOML's infinities have no JSON form: an infinite bound is written as an open side.
        let value = serde_json::to_value(v.get_ref()).map_err(|e| cx.err(S, key, &v.span(), e))?;
        table.insert(key.into(), value);
        spans.push((key, v.span()));
    }
    let span_of = |key: Option<&str>| {
        spans
            .iter()
            .find(|(k, _)| Some(*k) == key)
            .or(spans.first())
            .map(|(k, s)| (*k, s.clone()))
            .unwrap_or(("kind", 0..0))
    };
    let end = grid.start() + grid.duration().max(grid.interval());
    let step = PiecewiseConstant::new(vec![grid.start(), end], vec![1.0])
        .map_err(|e| cx.err(S, "kind", &(0..0), e))?;
    let built = SignalRegistry::builtin()
        .build(&table, Some(&step.into()))
        .map_err(|e| {
            let (key, span) = span_of(e.key());
            cx.err(S, key, &span, e)
        })?;
    if let Some(g) = built.downcast::<GreyBox<ExprModel>>() {
        let (key, span) = span_of(Some("a"));
        range::poles(g.poles().iter().map(|p| p.norm()), grid)
            .map_err(|m| cx.err(S, key, &span, m))?;
    }
    Ok(built.spec())
}

fn sinusoid(cx: &Source, r: &RawSystem, grid: &SampleGrid) -> StudyResult<SpecTable> {
    let why = "kind = \"sinusoid\" needs amplitude, frequency and optionally phase";
    let a = cx.required(S, "amplitude", &r.amplitude, why)?;
    let f = cx.required(S, "frequency", &r.frequency, why)?;
    let amplitude = cx.checked(S, "amplitude", a, range::gain)?;
    let frequency = cx.checked(S, "frequency", f, |f| range::frequency(f, grid))?;
    let phase = cx.opt_finite(S, "phase", &r.phase, 0.0)?;
    let s = Sinusoid::new(amplitude, frequency, phase)
        .map_err(|e| cx.err(S, "frequency", &f.span(), e))?;
    Ok(spec(
        "sinusoid",
        [
            ("amplitude", json!(s.amplitude())),
            ("frequency", json!(s.frequency())),
            ("phase", json!(s.phase())),
        ],
    ))
}

/// `initial` and `delay` written into a rational system's spec table as the signal registry
/// reads them: a free response from the record's first instant `t0` (started at rest, one
/// coefficient per pole) and an input delay. A kind without them refused the keys already.
fn response_keys(
    cx: &Source,
    r: &RawSystem,
    grid: &SampleGrid,
    mut kind: SpecTable,
) -> StudyResult<SpecTable> {
    if let Some(d) = &r.delay {
        let d = cx.checked(S, "delay", d, |d| range::delay(d, grid))?;
        kind.insert("delay".into(), json!(d));
    }
    let Some(mode) = &r.initial else {
        return Ok(kind);
    };
    match mode.get_ref().as_str() {
        "zero" => Ok(kind),
        "estimate" => {
            let order = match kind.get("poles").zip(kind.get("zeros")) {
                Some(_) => zpk_order(&kind),
                None => match kind.get("den").and_then(Value::as_array) {
                    Some(den) => den.len().saturating_sub(1),
                    // A grey-box model: one state per row of A.
                    None => kind.get("a").and_then(Value::as_array).map_or(0, Vec::len),
                },
            };
            kind.insert("initial".into(), json!(vec![0.0; order]));
            kind.insert("origin".into(), json!(grid.start()));
            Ok(kind)
        }
        other => Err(cx.err(
            S,
            "initial",
            &mode.span(),
            format!("unknown initial state \"{other}\"; expected \"zero\" or \"estimate\""),
        )),
    }
}

/// `[output]`: the output offset `y₀` (operating point) and whether it is estimated, written
/// into the system's spec table as the signal registry reads them (`offset`,
/// `estimate_offset`). An absent section, or one that leaves both keys out, writes nothing:
/// the model and every number it gives stay those of the system alone.
///
/// The offset is estimated with the system (a parameter of the same signal), so
/// `estimate_offset = true` needs `[system] estimate = true`.
pub(super) fn output_keys(
    cx: &Source,
    r: Option<&RawOutput>,
    system: &mut SystemSpec,
) -> StudyResult<()> {
    const O: &str = "output";
    let Some(r) = r else {
        return Ok(());
    };
    let (offset, estimate) = (r.offset.as_ref(), r.estimate_offset.as_ref());
    let Some((key, span)) = offset
        .map(|o| ("offset", o.span()))
        .or_else(|| estimate.map(|e| ("estimate_offset", e.span())))
    else {
        return Ok(());
    };
    let name = system
        .kind
        .get(KIND_KEY)
        .and_then(Value::as_str)
        .unwrap_or_default()
        .to_string();
    // A multi-input system has one offset, added to the sum of its inputs' responses.
    let takes = name == jitterid::signal::superposition::SUPERPOSITION_KIND
        || cx
            .registries
            .signal
            .kind(&name)
            .is_some_and(|k| k.params().iter().any(|p| p.key == "offset"));
    if !takes {
        return Err(cx.err(
            O,
            key,
            &span,
            format!("the system kind \"{name}\" takes no output offset; expected kind = \"zpk\", \"tf\" or \"grey-box\""),
        ));
    }
    let y0 = match offset {
        Some(v) => cx.checked(O, "offset", v, range::level)?,
        None => 0.0,
    };
    let estimated = estimate.is_some_and(|e| *e.get_ref());
    if estimated && !system.estimate {
        let span = estimate.map(Spanned::span).unwrap_or_default();
        return Err(cx.err(
            O,
            "estimate_offset",
            &span,
            "the offset is estimated with the system; expected [system] estimate = true (or estimate_offset = false)",
        ));
    }
    system.kind.insert("offset".into(), json!(y0));
    if estimated {
        system.kind.insert("estimate_offset".into(), json!(true));
    }
    Ok(())
}

/// The number of poles of a zpk spec table (a pair `[re, im]` counts two).
fn zpk_order(kind: &SpecTable) -> usize {
    kind.get("poles").and_then(Value::as_array).map_or(0, |ps| {
        ps.iter().map(|p| if p.is_array() { 2 } else { 1 }).sum()
    })
}

/// The signal registry's spec table of `kind` with `keys`, as the door checks built them.
/// `spec` with `unstable = true` when asked for (`[system] unstable`).
fn with_unstable(mut spec: SpecTable, unstable: bool) -> SpecTable {
    if unstable {
        spec.insert("unstable".into(), json!(true));
    }
    spec
}

/// `[system] integrators`: a whole number in `[0, order]` (0 when absent) that `check` (the
/// model's `with_integrators`) accepts; every refusal names the key and the value.
fn integrators(
    cx: &Source,
    r: &RawSystem,
    order: usize,
    check: impl FnOnce(usize) -> Result<(), jitterid::signal::SignalError>,
) -> StudyResult<usize> {
    let Some(v) = &r.integrators else {
        return Ok(0);
    };
    let n = *v.get_ref();
    let Some(n) = usize::try_from(n).ok().filter(|&n| n <= order) else {
        return Err(cx.err(
            S,
            "integrators",
            &v.span(),
            format!("expected a whole number of poles in [0, {order}] (the system's), found {n}"),
        ));
    };
    check(n).map_err(|e| cx.err(S, "integrators", &v.span(), e))?;
    Ok(n)
}

/// `spec` with `integrators = n` when there are any.
fn with_integrators(mut spec: SpecTable, n: usize) -> SpecTable {
    if n > 0 {
        spec.insert("integrators".into(), json!(n));
    }
    spec
}

fn spec<const N: usize>(kind: &str, keys: [(&str, Value); N]) -> SpecTable {
    let mut spec = SpecTable::new();
    spec.insert(KIND_KEY.into(), kind.into());
    spec.extend(keys.into_iter().map(|(k, v)| (k.to_string(), v)));
    spec
}

fn parse_roots(cx: &Source, key: &str, v: &Spanned<Vec<toml::Value>>) -> StudyResult<Vec<Root>> {
    let mut out = Vec::new();
    for (i, e) in v.get_ref().iter().enumerate() {
        let bad = |what: String| {
            cx.err("system", key, &v.span(), format!(
                "element {}: expected a number (a real root), [re, im] with im > 0 (a complex pair) or {{a1 = …, a0 = …}} (the two roots of s² + a1·s + a0), found {what}",
                i + 1
            ))
        };
        let root = match e {
            toml::Value::Array(a) if a.len() == 2 => match (number(&a[0]), number(&a[1])) {
                (Some(re), Some(im)) if re.is_finite() && im.is_finite() && im > 0.0 => {
                    Root::Pair { re, im }
                }
                (Some(re), Some(im)) => return Err(bad(format!("[{re}, {im}]"))),
                _ => return Err(bad(describe(e))),
            },
            toml::Value::Table(t) => {
                let coefficient = |k: &str| t.get(k).and_then(number).filter(|x| x.is_finite());
                match (coefficient("a1"), coefficient("a0"), t.len()) {
                    (Some(a1), Some(a0), 2) => Root::Quadratic { a1, a0 },
                    _ => return Err(bad(describe(e))),
                }
            }
            other => match number(other) {
                Some(x) if x.is_finite() => Root::Real(x),
                Some(x) => return Err(bad(format!("{x}"))),
                None => return Err(bad(describe(other))),
            },
        };
        out.push(root);
    }
    Ok(out)
}
