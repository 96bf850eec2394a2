//! The built-in signal kinds.

use super::{KindReader, ParamSpec, SignalKind, SignalRegistry, SpecReader, SpecTable};
use crate::spectrum::Spectrum;
use crate::{
    AnySignal, Delayed, DrivenSignal, Input, InputLevel, LtiResponse, ModalSignal, Offset,
    PulseResponse, RationalModel, Root, SignalError, Sinusoid, TransferFunction, WithInitialState,
    Zpk,
};
use serde_json::{json, Value};

pub(super) fn registry() -> SignalRegistry {
    let mut r = SignalRegistry::new();
    for kind in [
        zpk(),
        tf(),
        sinusoid(),
        pulse_response(),
        super::greybox::kind(),
    ] {
        // Names are distinct by construction.
        let _ = r.register(kind);
    }
    r
}

/// The key a constructor's error is about, from the name it carries.
fn key_of(error: &SignalError, keys: &[(&str, &str)], fallback: &str) -> String {
    let name = match error {
        SignalError::NotFinite { name, .. }
        | SignalError::NotPositive { name, .. }
        | SignalError::TooFew { name, .. }
        | SignalError::BadPair { name, .. }
        | SignalError::ZeroLeading { name }
        | SignalError::Roots { name }
        | SignalError::WrongLength { name, .. } => Some(*name),
        _ => None,
    };
    name.and_then(|n| keys.iter().find(|(from, _)| *from == n))
        .map_or(fallback, |(_, key)| key)
        .to_string()
}

fn input_of(input: Option<&Input>) -> Result<Input, SignalError> {
    // The registry hands an input to every kind that needs one.
    input.cloned().ok_or(SignalError::MissingInput {
        kind: String::new(),
    })
}

/// Roots as a spec table writes them ([`Root::to_json`]: a number for a real root, `[re, im]`
/// for a pair, `{a1, a0}` for a quadratic factor; what [`KindReader::roots`] reads back).
pub fn roots_json(roots: &[Root]) -> Value {
    roots.iter().map(Root::to_json).collect()
}

fn zpk() -> SignalKind {
    SignalKind::new(
        "zpk",
        "k·Π(s − z)/Π(s − p) driven by the input, exact (modal form, or a realisation for repeated poles and integrators)",
        vec![
            ParamSpec::new("gain", "gain k", "", "finite"),
            ParamSpec::new(
                "zeros",
                "zeros: a number (real), [re, im] (the pair re ± i·im) or {a1, a0} (the two roots of s² + a1·s + a0)",
                "rad/s",
                "optional; finite, im > 0, no more zeros than poles",
            ),
            ParamSpec::new(
                "poles",
                "poles: a number (real), [re, im] (the pair re ± i·im) or {a1, a0} (the two roots of s² + a1·s + a0); a real pole given twice is estimated as its quadratic factor",
                "rad/s",
                "at least one; real part ≤ 0 (unless `unstable`), im > 0",
            ),
            unstable_key(),
            integrators_key(),
        ]
        .into_iter()
        .chain(response_keys())
        .collect(),
        true,
        |r: &SpecReader<'_>, input| {
            let (gain, zeros, poles) = (r.f64("gain")?, r.roots("zeros")?, r.roots("poles")?);
            let keys = [
                ("gain", "gain"),
                ("zero", "zeros"),
                ("pole", "poles"),
                ("poles", "poles"),
            ];
            let g = if r.flag("unstable")? {
                Zpk::new_allowing_unstable(gain, zeros, poles)
            } else {
                Zpk::new(gain, zeros, poles)
            };
            let g = g.map_err(|e| {
                let fallback = if matches!(e, SignalError::Improper { .. }) {
                    "zeros"
                } else {
                    "poles"
                };
                r.invalid(&key_of(&e, &keys, fallback), e)
            })?;
            let g = match integrators(r)? {
                0 => g,
                n => g
                    .with_integrators(n)
                    .map_err(|e| r.invalid("integrators", e))?,
            };
            lti_signal(
                "zpk",
                r,
                LtiResponse::new(g, input_of(input)?),
                |g: &Zpk| {
                    with_integrators(
                        with_unstable(
                            spec([
                                ("gain", json!(g.gain())),
                                ("zeros", roots_json(g.zeros())),
                                ("poles", roots_json(g.poles())),
                            ]),
                            g,
                        ),
                        g.integrators(),
                    )
                },
            )
        },
    )
}

fn tf() -> SignalKind {
    SignalKind::new(
        "tf",
        "(b_m s^m + … + b_0)/(s^n + … + a_0) driven by the input, exact (modal form, or a realisation for repeated poles and integrators)",
        vec![
            ParamSpec::new(
                "num",
                "numerator coefficients, highest power first",
                "",
                "finite, degree ≤ that of den",
            ),
            ParamSpec::new(
                "den",
                "denominator coefficients, highest power first (normalised to monic)",
                "",
                "finite, leading ≠ 0, poles with real part ≤ 0 (unless `unstable`)",
            ),
            unstable_key(),
            integrators_key(),
        ]
        .into_iter()
        .chain(response_keys())
        .collect(),
        true,
        |r: &SpecReader<'_>, input| {
            let (num, den) = (r.f64_list("num")?, r.f64_list("den")?);
            let keys = [("num", "num"), ("den", "den")];
            let g = if r.flag("unstable")? {
                TransferFunction::new_allowing_unstable(&num, &den)
            } else {
                TransferFunction::new(&num, &den)
            };
            let g = g.map_err(|e| {
                let fallback = if matches!(e, SignalError::Improper { .. }) {
                    "num"
                } else {
                    "den"
                };
                r.invalid(&key_of(&e, &keys, fallback), e)
            })?;
            let g = match integrators(r)? {
                0 => g,
                n => g
                    .with_integrators(n)
                    .map_err(|e| r.invalid("integrators", e))?,
            };
            lti_signal(
                "tf",
                r,
                LtiResponse::new(g, input_of(input)?),
                |g: &TransferFunction| {
                    with_integrators(
                        with_unstable(spec([("num", json!(g.num())), ("den", json!(g.den()))]), g),
                        g.integrators(),
                    )
                },
            )
        },
    )
}

/// The permission for poles right of the imaginary axis.
fn unstable_key() -> ParamSpec {
    ParamSpec::new(
        "unstable",
        "accept poles with a positive real part (true) or refuse them (false, the default); \
         kept while the model is estimated, so that a search may cross the axis",
        "",
        "optional; true or false",
    )
}

/// The structural integrators: poles at the origin held there, not estimated.
fn integrators_key() -> ParamSpec {
    ParamSpec::new(
        "integrators",
        "how many of the poles at exactly 0 (tf: trailing zeros of `den`; zpk: poles 0.0) are \
         structural integrators, held at the origin and not parameters",
        "",
        "optional; a whole number, at most the number of poles at 0",
    )
    .with_default(0.0)
    .integer()
}

/// The `integrators` key (0 when absent), bounded by the pole-count limit.
fn integrators(r: &SpecReader<'_>) -> Result<usize, SignalError> {
    // MAX_POLES (30) fits a u32; a larger count is refused by the poles themselves.
    let max = u32::try_from(jitterid_numeric::limits::MAX_POLES).unwrap_or(u32::MAX);
    Ok(r.u32("integrators", max)? as usize)
}

/// `spec` with the `integrators` key when there are any.
fn with_integrators(mut spec: SpecTable, n: usize) -> SpecTable {
    if n > 0 {
        spec.insert("integrators".into(), json!(n));
    }
    spec
}

/// `spec` with `unstable = true` when the model accepts unstable poles.
fn with_unstable<M: RationalModel>(mut spec: SpecTable, g: &M) -> SpecTable {
    if g.rational().allows_unstable() {
        spec.insert("unstable".into(), json!(true));
    }
    spec
}

/// The keys every LTI kind adds to its model's: an input delay and the free response from an
/// initial state (each a parameter only when given).
pub(super) fn response_keys() -> Vec<ParamSpec> {
    vec![
        ParamSpec::new(
            "delay",
            "input delay (dead time) D, a parameter `delay` when given",
            "s",
            "optional; finite, ≥ 0, piecewise-constant input",
        ),
        ParamSpec::new(
            "initial",
            "free response q_0 … q_{n−1} (Laplace transform q(s)/A(s) from `origin`), \
             parameters `initial.j` when given",
            "",
            "optional; one finite value per pole",
        ),
        ParamSpec::new(
            "origin",
            "time t0 of the initial state (the record's first instant)",
            "s",
            "finite",
        )
        .with_default(0.0),
        ParamSpec::new(
            "level",
            "input level u₀ (operating point of the input): the model is driven by u − u₀ over the input's span",
            "",
            "optional; finite (absent: no level)",
        ),
        ParamSpec::new(
            "estimate_level",
            "whether u₀ is estimated, the parameter `level` (true), or known (false, the default)",
            "",
            "optional; true or false",
        ),
        ParamSpec::new(
            "offset",
            "output offset y₀ (operating point): the model is y₀ + the response",
            "",
            "optional; finite (absent: no offset)",
        ),
        ParamSpec::new(
            "estimate_offset",
            "whether y₀ is estimated, the parameter `offset` (true), or known (false, the default)",
            "",
            "optional; true or false",
        ),
    ]
}

/// `signal` plus the spec table's output offset, when it has `offset` or `estimate_offset`
/// (else `signal` unchanged: no wrapper, no parameter, every number as before). The wrapped
/// signal writes back the inner signal's keys and the two offset keys.
fn with_offset(
    kind: &'static str,
    r: &SpecReader<'_>,
    signal: AnySignal,
) -> Result<AnySignal, SignalError> {
    if !r.has("offset") && !r.has("estimate_offset") {
        return Ok(signal);
    }
    let offset = if r.has("offset") {
        r.f64("offset")?
    } else {
        0.0
    };
    let estimated = r.flag("estimate_offset")?;
    let spectrum = signal.has_spectrum();
    let wrapped = Offset::new(signal, offset, estimated).map_err(|e| r.invalid("offset", e))?;
    let to_spec = |s: &Offset<AnySignal>| {
        let mut out = s.signal().spec();
        out.remove(super::KIND_KEY);
        out.insert("offset".into(), json!(s.offset()));
        if s.estimated() {
            out.insert("estimate_offset".into(), json!(true));
        }
        out
    };
    Ok(if spectrum {
        AnySignal::with_spectrum(kind, wrapped, to_spec)
    } else {
        AnySignal::new(kind, wrapped, to_spec)
    })
}

/// `response`, delayed and given a free response as the spec table asks, with `keys` writing
/// the model's keys back.
pub(super) fn lti_signal<M: RationalModel + Clone + 'static>(
    kind: &'static str,
    r: &SpecReader<'_>,
    response: LtiResponse<M>,
    keys: fn(&M) -> SpecTable,
) -> Result<AnySignal, SignalError> {
    with_offset(kind, r, lti_response(kind, r, response, keys)?)
}

/// `response`, delayed, around its input's level and given a free response as the spec table
/// asks (without the output offset, which [`with_offset`] adds around it).
fn lti_response<M: RationalModel + Clone + 'static>(
    kind: &'static str,
    r: &SpecReader<'_>,
    response: LtiResponse<M>,
    keys: fn(&M) -> SpecTable,
) -> Result<AnySignal, SignalError> {
    let delay = if r.has("delay") {
        let d = r.f64("delay")?;
        if !(d >= 0.0) {
            return Err(r.invalid("delay", format!("must be ≥ 0, got {d}")));
        }
        Some(d)
    } else {
        None
    };
    match delay {
        None => around_level(kind, r, response, move |s: &LtiResponse<M>| keys(s.model())),
        Some(d) => {
            let delayed = Delayed::new(response, d).map_err(|e| r.invalid("delay", e))?;
            around_level(kind, r, delayed, move |s: &Delayed<M>| {
                let mut out = keys(s.response().model());
                out.insert("delay".into(), json!(s.delay()));
                out
            })
        }
    }
}

/// `response` around the input's level `level` (the parameter `level` when
/// `estimate_level`), when the spec table has either key; else `response` unchanged (no
/// wrapper, no parameter, every number as before). Then the free response.
fn around_level<S>(
    kind: &'static str,
    r: &SpecReader<'_>,
    response: S,
    keys: impl Fn(&S) -> SpecTable + Clone + Send + Sync + 'static,
) -> Result<AnySignal, SignalError>
where
    S: DrivenSignal + ModalSignal + Spectrum + Clone + 'static,
{
    if !r.has("level") && !r.has("estimate_level") {
        return with_free_response(kind, r, response, keys);
    }
    let level = if r.has("level") { r.f64("level")? } else { 0.0 };
    let estimated = r.flag("estimate_level")?;
    let wrapped = InputLevel::new(response, level, estimated).map_err(|e| r.invalid("level", e))?;
    with_free_response(kind, r, wrapped, move |s: &InputLevel<S>| {
        let mut out = keys(s.response());
        out.insert("level".into(), json!(s.level()));
        if s.estimated() {
            out.insert("estimate_level".into(), json!(true));
        }
        out
    })
}

/// `response` with the free response from `initial` at `origin` when the spec table has
/// `initial`.
fn with_free_response<S>(
    kind: &'static str,
    r: &SpecReader<'_>,
    response: S,
    keys: impl Fn(&S) -> SpecTable + Send + Sync + 'static,
) -> Result<AnySignal, SignalError>
where
    S: ModalSignal + Spectrum + Clone + 'static,
{
    if !r.has("initial") {
        return Ok(AnySignal::with_spectrum(kind, response, keys));
    }
    let initial = r.f64_list("initial")?;
    let origin = r.f64("origin")?;
    let free = WithInitialState::new(response, origin, initial).map_err(|e| {
        let key = if matches!(e, SignalError::NotFinite { name: "origin", .. }) {
            "origin"
        } else {
            "initial"
        };
        r.invalid(key, e)
    })?;
    Ok(AnySignal::new(
        kind,
        free,
        move |s: &WithInitialState<S>| {
            let mut out = keys(s.response());
            out.insert("initial".into(), json!(s.initial()));
            out.insert("origin".into(), json!(s.origin()));
            out
        },
    ))
}

fn sinusoid() -> SignalKind {
    SignalKind::new(
        "sinusoid",
        "A sin(2πf0 t + φ), no input",
        vec![
            ParamSpec::new("amplitude", "amplitude A", "", "finite"),
            ParamSpec::new("frequency", "frequency f0", "Hz", "finite, ≥ 0"),
            ParamSpec::new("phase", "phase φ", "rad", "finite").with_default(0.0),
        ],
        false,
        |r: &SpecReader<'_>, _| {
            let (a, f, p) = (r.f64("amplitude")?, r.f64("frequency")?, r.f64("phase")?);
            let keys = [
                ("amplitude", "amplitude"),
                ("frequency", "frequency"),
                ("phase", "phase"),
            ];
            let s = Sinusoid::new(a, f, p)
                .map_err(|e| r.invalid(&key_of(&e, &keys, "frequency"), e))?;
            Ok(AnySignal::with_spectrum("sinusoid", s, |s: &Sinusoid| {
                spec([
                    ("amplitude", json!(s.amplitude())),
                    ("frequency", json!(s.frequency())),
                    ("phase", json!(s.phase())),
                ])
            }))
        },
    )
}

fn pulse_response() -> SignalKind {
    SignalKind::new(
        "pulse-response",
        "Σ h_l u(t − l·T_s): a discrete pulse response driven by a piecewise-constant input",
        vec![
            ParamSpec::new(
                "coefficients",
                "pulse response h_0, h_1, …",
                "",
                "at least one, finite",
            ),
            ParamSpec::new("interval", "spacing T_s of the pulses", "s", "> 0"),
        ],
        true,
        |r: &SpecReader<'_>, input| {
            let (h, ts) = (r.f64_list("coefficients")?, r.f64("interval")?);
            let Some(Input::Piecewise(u)) = input else {
                return Err(r.invalid("kind", "pulse-response needs a piecewise-constant input"));
            };
            let keys = [("coefficients", "coefficients"), ("interval", "interval")];
            let p = PulseResponse::new(h, ts, u.clone())
                .map_err(|e| r.invalid(&key_of(&e, &keys, "coefficients"), e))?;
            Ok(AnySignal::with_spectrum(
                "pulse-response",
                p,
                |p: &PulseResponse| {
                    spec([
                        ("coefficients", json!(p.coefficients())),
                        ("interval", json!(p.interval())),
                    ])
                },
            ))
        },
    )
}

fn spec<const N: usize>(pairs: [(&str, Value); N]) -> SpecTable {
    pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}
