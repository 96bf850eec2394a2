//! The built-in signal kinds.

use super::{ParamSpec, SignalKind, SignalRegistry, Spec, SpecReader};
use crate::{
    AnySignal, Input, LtiResponse, PulseResponse, Root, SignalError, Sinusoid, TransferFunction,
    Zpk,
};
use serde_json::{json, Value};

pub(super) fn registry() -> SignalRegistry {
    let mut r = SignalRegistry::new();
    for kind in [zpk(), tf(), sinusoid(), pulse_response()] {
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

/// Roots as a spec table writes them: a number for a real root, `[re, im]` for a pair
/// (what [`SpecReader::roots`](super::SpecReader::roots) reads back).
pub fn roots_json(roots: &[Root]) -> Value {
    roots
        .iter()
        .map(|r| match *r {
            Root::Real(x) => json!(x),
            Root::Pair { re, im } => json!([re, im]),
        })
        .collect()
}

fn zpk() -> SignalKind {
    SignalKind::new(
        "zpk",
        "k·Π(s − z)/Π(s − p) driven by the input, exact (modal form)",
        vec![
            ParamSpec::new("gain", "gain k", "", "finite"),
            ParamSpec::new(
                "zeros",
                "zeros: a number (real) or [re, im] (the pair re ± i·im)",
                "rad/s",
                "optional; finite, im > 0, no more zeros than poles",
            ),
            ParamSpec::new(
                "poles",
                "poles: a number (real) or [re, im] (the pair re ± i·im)",
                "rad/s",
                "at least one; real part < 0, distinct, im > 0",
            ),
        ],
        true,
        |r: &SpecReader<'_>, input| {
            let (gain, zeros, poles) = (r.f64("gain")?, r.roots("zeros")?, r.roots("poles")?);
            let keys = [
                ("gain", "gain"),
                ("zero", "zeros"),
                ("pole", "poles"),
                ("poles", "poles"),
            ];
            let g = Zpk::new(gain, zeros, poles).map_err(|e| {
                let fallback = if matches!(e, SignalError::Improper { .. }) {
                    "zeros"
                } else {
                    "poles"
                };
                r.invalid(&key_of(&e, &keys, fallback), e)
            })?;
            Ok(AnySignal::with_spectrum(
                "zpk",
                LtiResponse::new(g, input_of(input)?),
                |s: &LtiResponse<Zpk>| {
                    let g = s.model();
                    spec([
                        ("gain", json!(g.gain())),
                        ("zeros", roots_json(g.zeros())),
                        ("poles", roots_json(g.poles())),
                    ])
                },
            ))
        },
    )
}

fn tf() -> SignalKind {
    SignalKind::new(
        "tf",
        "(b_m s^m + … + b_0)/(s^n + … + a_0) driven by the input, exact (modal form)",
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
                "finite, leading ≠ 0, stable distinct poles",
            ),
        ],
        true,
        |r: &SpecReader<'_>, input| {
            let (num, den) = (r.f64_list("num")?, r.f64_list("den")?);
            let keys = [("num", "num"), ("den", "den")];
            let g = TransferFunction::new(&num, &den).map_err(|e| {
                let fallback = if matches!(e, SignalError::Improper { .. }) {
                    "num"
                } else {
                    "den"
                };
                r.invalid(&key_of(&e, &keys, fallback), e)
            })?;
            Ok(AnySignal::with_spectrum(
                "tf",
                LtiResponse::new(g, input_of(input)?),
                |s: &LtiResponse<TransferFunction>| {
                    spec([
                        ("num", json!(s.model().num())),
                        ("den", json!(s.model().den())),
                    ])
                },
            ))
        },
    )
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

fn spec<const N: usize>(pairs: [(&str, Value); N]) -> Spec {
    pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}
