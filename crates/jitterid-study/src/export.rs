//! The fitted model taken out of the command line: transfer-function coefficients, zeros,
//! poles and gain, and a state-space realisation (`fit --json`'s `model`), with the input
//! delay `D` of a delayed system (the model is `G(s) e^{−sD}`), the output offset `y₀` and the
//! input's level `u₀` of a model around an operating point (`y = y₀ + G(s)(u − u₀)`), and the
//! covariance of the reported parameters.

use jitterid::estimate::validation::{BodePoint, StepPoint};
use jitterid::estimate::{validation, EstimateError};
use jitterid::signal::forms::{StateSpace, TfForm, ZpkForm};
use jitterid::signal::greybox::{ExprModel, GreyBox, GREY_BOX};
use jitterid::signal::registry::{KindReader, SignalRegistry};
use jitterid::signal::RationalModel;
use jitterid::signal::{
    AnySignal, Offset, PiecewiseConstant, SignalError, Superposition, TransferFunction, Zpk,
};
use serde::Serialize;

/// The model in the three export forms.
#[derive(Debug, Clone, Serialize)]
pub struct ModelForms {
    /// Zeros, poles and gain.
    pub zpk: ZpkForm,
    /// Coefficients, highest power first.
    pub tf: TfForm,
    /// The controllable canonical realisation.
    pub ss: StateSpace,
    /// The input delay `D` (s) of a delayed system: the model is `G(s) e^{−sD}` with `G` the
    /// three forms above (absent without a delay).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay: Option<f64>,
    /// The output offset `y₀` of a model around an operating point: the model is
    /// `y = y₀ + G(s)u` (in state space `ẋ = Ax + Bu`, `y = Cx + Du + y₀`), reported beside the
    /// three forms because none of them has a constant term (absent without an offset).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    /// The input's level `u₀` of a model around an operating point of its input: the model is
    /// driven by `u − u₀` (`y = G(s)(u − u₀)`; in state space `ẋ = Ax + B(u − u₀)`), reported
    /// beside the forms for the same reason as the offset (absent without a level).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub level: Option<f64>,
}

/// The input's level `u₀` of a signal's system, `None` when it has none.
pub fn level_of(signal: &AnySignal) -> Option<f64> {
    signal
        .spec()
        .get("level")
        .and_then(serde_json::Value::as_f64)
}

/// The output offset `y₀` of a signal around an operating point, `None` when it has none.
pub fn offset_of(signal: &AnySignal) -> Option<f64> {
    signal
        .spec()
        .get("offset")
        .and_then(serde_json::Value::as_f64)
}

/// The input delay `D` (s) of a signal's system, `None` when it has none.
pub fn delay_of(signal: &AnySignal) -> Option<f64> {
    signal
        .spec()
        .get("delay")
        .and_then(serde_json::Value::as_f64)
}

/// The signal's system rebuilt from its spec table in its own parameterisation (so that the
/// rows of its covariance match): a [`Zpk`] or a [`TransferFunction`].
///
/// A fitted model is exported whatever its poles: the rebuild accepts poles right of the axis
/// (an estimate with `unstable = true` may end there, and its export is still the model).
enum RationalSystem {
    Zpk(Zpk),
    Tf(TransferFunction),
}

impl RationalSystem {
    /// The system of `signal`, `None` for a signal kind that is not a rational system.
    ///
    /// # Errors
    ///
    /// The signal's spec table does not rebuild a rational system (the error says which key).
    fn of(signal: &AnySignal) -> Result<Option<Self>, SignalError> {
        let name = signal.kind();
        if name != "zpk" && name != "tf" {
            return Ok(None);
        }
        let spec = signal.spec();
        let Some(kind) = SignalRegistry::builtin().kind(name) else {
            return Ok(None);
        };
        let r = kind.reader(&spec)?;
        // Structural integrators are not parameters: the covariance's rows follow the model
        // with them held.
        let held = r.u32("integrators", u32::MAX)? as usize;
        Ok(Some(if name == "zpk" {
            Self::Zpk(
                Zpk::new_allowing_unstable(r.f64("gain")?, r.roots("zeros")?, r.roots("poles")?)?
                    .with_integrators(held)?,
            )
        } else {
            Self::Tf(
                TransferFunction::new_allowing_unstable(&r.f64_list("num")?, &r.f64_list("den")?)?
                    .with_integrators(held)?,
            )
        }))
    }

    fn tf(&self) -> TfForm {
        match self {
            Self::Zpk(z) => TfForm::of(z),
            Self::Tf(t) => TfForm::of(t),
        }
    }
}

/// The coefficients of a rational system (rebuilt from the signal's spec table; a grey-box
/// model's `C(sI − A)⁻¹B + D`), `None` for other signal kinds.
///
/// # Errors
///
/// The spec table of a `zpk` or `tf` signal does not rebuild its system.
pub fn tf_of(signal: &AnySignal) -> Result<Option<TfForm>, SignalError> {
    if let Some(g) = grey_box_of(signal)? {
        let g = g.downcast::<GreyBox<ExprModel>>();
        return g.map(GreyBox::transfer_function).transpose();
    }
    Ok(RationalSystem::of(signal)?.map(|g| g.tf()))
}

/// A grey-box system's model alone, as a [`GreyBox`] signal on a unit step: the signal
/// itself, or, for a model with an input delay, a free response or an output offset (which
/// put it on its transfer function's route), the model rebuilt from its spec table without
/// them. `None` for other kinds.
///
/// # Errors
///
/// The spec table does not rebuild the model.
pub fn grey_box_of(signal: &AnySignal) -> Result<Option<AnySignal>, SignalError> {
    if signal.kind() != GREY_BOX {
        return Ok(None);
    }
    if signal.downcast::<GreyBox<ExprModel>>().is_some() {
        return Ok(Some(signal.clone()));
    }
    let mut spec = signal.spec();
    for key in [
        "delay",
        "initial",
        "origin",
        "level",
        "estimate_level",
        "offset",
        "estimate_offset",
    ] {
        spec.remove(key);
    }
    let step = PiecewiseConstant::new(vec![0.0, 1.0], vec![1.0])?;
    SignalRegistry::builtin()
        .build(&spec, Some(&step.into()))
        .map(Some)
}

/// The fitted model in every export form, `None` for signals that are not rational systems
/// (transfer functions, zeros and poles, grey-box state space).
///
/// # Errors
///
/// The system does not rebuild, or its zeros and poles cannot be found (non-finite
/// coefficients): an export that cannot be made says why rather than going missing.
pub fn model_forms(signal: &AnySignal) -> Result<Option<ModelForms>, SignalError> {
    let Some(tf) = tf_of(signal)? else {
        return Ok(None);
    };
    // A grey-box model exports its own realisation (the fitted A, B, C, D).
    let grey = grey_box_of(signal)?;
    let ss = match grey
        .as_ref()
        .and_then(|g| g.downcast::<GreyBox<ExprModel>>())
    {
        Some(g) => g.state_space(),
        None => tf.to_state_space(),
    };
    Ok(Some(ModelForms {
        zpk: tf.to_zpk()?,
        ss,
        tf,
        delay: delay_of(signal),
        offset: offset_of(signal),
        level: level_of(signal),
    }))
}

/// The fitted model of `fit --json`: one input's [`ModelForms`], or a multi-input system's
/// forms per input with one state-space realisation of them all.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum ExportedModel {
    /// A system with one input.
    One(ModelForms),
    /// A system with several inputs.
    Several(SeveralInputs),
}

/// A multi-input system's export: `y = y₀ + Σᵢ Gᵢ(s) e^{−sDᵢ} uᵢ`.
#[derive(Debug, Clone, Serialize)]
pub struct SeveralInputs {
    /// Each input's transfer function in the three forms (with its delay), in input order.
    pub inputs: Vec<InputForms>,
    /// One realisation of them all: the channels' realisations side by side
    /// (block-diagonal `A`, `B` with one column per input, `C` and `D` one row), or for a
    /// grey-box model with a column of `B` per input its own `A, B, C, D`; without the delays.
    pub ss: MultiInputStateSpace,
    /// The output offset `y₀` (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
}

/// One input's part of a multi-input export.
#[derive(Debug, Clone, Serialize)]
pub struct InputForms {
    /// The input's name.
    pub name: String,
    /// `Gᵢ` in the three forms, with its delay.
    #[serde(flatten)]
    pub forms: ModelForms,
}

/// `ẋ = A x + B u`, `y = C x + D u` with `m` inputs: `{"a": n×n, "b": n×m, "c": 1×n, "d": 1×m}`.
#[derive(Debug, Clone, Serialize)]
pub struct MultiInputStateSpace {
    /// `A`, rows.
    pub a: Vec<Vec<f64>>,
    /// `B`, rows (one column per input).
    pub b: Vec<Vec<f64>>,
    /// `C`, one row.
    pub c: Vec<Vec<f64>>,
    /// `D`, one row (one column per input).
    pub d: Vec<Vec<f64>>,
}

impl MultiInputStateSpace {
    /// One model's realisation from its single-input parts (the same `A` and `C`, a column of
    /// `B` and `D` each): a grey-box model whose `B` has a column per input.
    fn columns(parts: &[&StateSpace]) -> Self {
        let Some(first) = parts.first() else {
            return Self::of(parts);
        };
        let b = (0..first.order())
            .map(|i| parts.iter().map(|p| p.b()[i]).collect())
            .collect();
        Self {
            a: first.a().to_vec(),
            b,
            c: vec![first.c().to_vec()],
            d: vec![parts.iter().map(|p| p.d()).collect()],
        }
    }

    /// The realisations `parts` (one per input) side by side.
    fn of(parts: &[&StateSpace]) -> Self {
        let n: usize = parts.iter().map(|p| p.order()).sum();
        let m = parts.len();
        let mut a = vec![vec![0.0; n]; n];
        let mut b = vec![vec![0.0; m]; n];
        let mut c = Vec::with_capacity(n);
        let mut d = Vec::with_capacity(m);
        let mut at = 0;
        for (j, p) in parts.iter().enumerate() {
            for (i, row) in p.a().iter().enumerate() {
                a[at + i][at..at + row.len()].copy_from_slice(row);
                b[at + i][j] = p.b()[i];
            }
            c.extend_from_slice(p.c());
            d.push(p.d());
            at += p.order();
        }
        Self {
            a,
            b,
            c: vec![c],
            d: vec![d],
        }
    }
}

/// The fitted model of `fit --json` ([`model_forms`] for one input; each channel's forms and
/// their joint realisation for several), `None` for signals that are not rational systems.
///
/// # Errors
///
/// Those of [`model_forms`], for any channel.
pub fn exported_model(signal: &AnySignal) -> Result<Option<ExportedModel>, SignalError> {
    let Some(sum) = signal.downcast::<Offset<Superposition>>() else {
        return Ok(model_forms(signal)?.map(ExportedModel::One));
    };
    let mut inputs = Vec::with_capacity(sum.signal().channels().len());
    for c in sum.signal().channels() {
        let Some(forms) = model_forms(&c.signal)? else {
            return Ok(None);
        };
        inputs.push(InputForms {
            name: c.name.clone(),
            forms,
        });
    }
    let parts: Vec<&StateSpace> = inputs.iter().map(|i| &i.forms.ss).collect();
    let ss = if sum.signal().is_shared() {
        MultiInputStateSpace::columns(&parts)
    } else {
        MultiInputStateSpace::of(&parts)
    };
    let offset = (sum.offset() != 0.0 || sum.estimated()).then_some(sum.offset());
    Ok(Some(ExportedModel::Several(SeveralInputs {
        inputs,
        ss,
        offset,
    })))
}

/// Where a reported parameter sits in the estimator's covariance: its index there and the
/// factor it is scaled by (`None` for a reported value without a covariance row, such as a
/// profiled integer or a noise level estimated after the fit).
pub type CovarianceSource = Option<(usize, f64)>;

/// The covariance of the reported parameters: `scale_i scale_j C[src_i][src_j]`, `None` where
/// a parameter has no source or the entry is not finite.
pub fn reported_covariance(
    covariance: &[Vec<f64>],
    sources: &[CovarianceSource],
) -> Vec<Vec<Option<f64>>> {
    let entry = |a: CovarianceSource, b: CovarianceSource| {
        let ((i, si), (j, sj)) = (a?, b?);
        let c = covariance.get(i)?.get(j)? * si * sj;
        c.is_finite().then_some(c)
    };
    sources
        .iter()
        .map(|&a| sources.iter().map(|&b| entry(a, b)).collect())
        .collect()
}

/// The Bode diagram of a rational signal's system at `freqs` with delta-method bands from the
/// covariance of its parameters; `None` for other signal kinds. For a delayed system the
/// response is `G(i2πf) e^{−i2πfD}` and `covariance` covers the system's parameters then the
/// delay (the order of the signal's parameters).
pub fn bode_of(
    signal: &AnySignal,
    freqs: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Option<Result<Vec<BodePoint>, EstimateError>> {
    let delay = delay_of(signal);
    Some(match RationalSystem::of(signal) {
        Err(e) => Err(e.into()),
        Ok(None) => return None,
        Ok(Some(RationalSystem::Zpk(z))) => delayed_bode(&z, delay, freqs, covariance),
        Ok(Some(RationalSystem::Tf(t))) => delayed_bode(&t, delay, freqs, covariance),
    })
}

/// `G`'s Bode diagram, with the delay's phase and band for a delayed system.
fn delayed_bode<M: RationalModel>(
    model: &M,
    delay: Option<f64>,
    freqs: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Result<Vec<BodePoint>, EstimateError> {
    match delay {
        Some(d) => validation::delayed_bode(model, d, freqs, covariance),
        None => validation::bode(model, freqs, covariance),
    }
}

/// The unit-step response of a rational signal's system with delta-method bands; `None` for
/// other signal kinds. A delayed system's response is `G`'s shifted by `D` (zero before), and
/// `covariance` covers the system's parameters then the delay.
pub fn step_of(
    signal: &AnySignal,
    times: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Option<Result<Vec<StepPoint>, EstimateError>> {
    let delay = delay_of(signal);
    Some(match RationalSystem::of(signal) {
        Err(e) => Err(e.into()),
        Ok(None) => return None,
        Ok(Some(RationalSystem::Zpk(z))) => delayed_step(&z, delay, times, covariance),
        Ok(Some(RationalSystem::Tf(t))) => delayed_step(&t, delay, times, covariance),
    })
}

/// `G`'s step response, shifted by the delay (with its band) for a delayed system.
fn delayed_step<M: RationalModel>(
    model: &M,
    delay: Option<f64>,
    times: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Result<Vec<StepPoint>, EstimateError> {
    match delay {
        Some(d) => validation::delayed_step_response(model, d, times, covariance),
        None => validation::step_response(model, times, covariance),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid::estimate::validation::BAND_SIGMAS;
    use jitterid::num_complex::Complex64;
    use jitterid::signal::{Input, PiecewiseConstant};
    use serde_json::json;

    /// `2 (s − z) / ((s − a)² + b²)` with input delay `d` (none when `d` is `None`), for
    /// `θ = [gain, z, a, b]`.
    fn signal(theta: &[f64], delay: Option<f64>) -> AnySignal {
        let mut spec: jitterid::signal::registry::SpecTable = json!({
            "kind": "zpk",
            "gain": theta[0],
            "zeros": [theta[1]],
            "poles": [[theta[2], theta[3]]],
        })
        .as_object()
        .unwrap()
        .clone();
        if let Some(d) = delay {
            spec.insert("delay".into(), json!(d));
        }
        let input = Input::Piecewise(PiecewiseConstant::new(vec![0.0, 100.0], vec![1.0]).unwrap());
        SignalRegistry::builtin()
            .build(&spec, Some(&input))
            .unwrap()
    }

    const THETA: [f64; 4] = [2.0, -1.0, -0.5, 1.5];
    const DELAY: f64 = 1.3;

    /// `G(i2πf) e^{−i2πfD}` written out: `k (s − z) / ((s − a − ib)(s − a + ib)) e^{−sD}`.
    fn by_hand(theta: &[f64], d: f64, f: f64) -> Complex64 {
        let s = Complex64::new(0.0, std::f64::consts::TAU * f);
        let (p, q) = (
            Complex64::new(theta[2], theta[3]),
            Complex64::new(theta[2], -theta[3]),
        );
        theta[0] * (s - theta[1]) / ((s - p) * (s - q)) * (-s * d).exp()
    }

    /// A covariance with correlations between every pair (`A Aᵀ`, `A` fixed), delay last.
    fn covariance() -> Vec<Vec<f64>> {
        let a = [
            [0.19, 0.01, -0.02, 0.03, 0.01],
            [0.05, 0.12, 0.01, -0.01, 0.02],
            [-0.01, 0.02, 0.04, 0.01, -0.01],
            [0.02, -0.01, 0.01, 0.04, 0.005],
            [0.01, 0.02, -0.005, 0.01, 0.02],
        ];
        (0..5)
            .map(|i| {
                (0..5)
                    .map(|j| (0..5).map(|k| a[i][k] * a[j][k]).sum())
                    .collect()
            })
            .collect()
    }

    const FREQS: [f64; 4] = [0.01, 0.1, 0.25, 0.45];

    /// A system with `unstable = true` whose fit ended right of the axis: `1/(s² + s − 0.01)`
    /// as `tf`, and its pole `0.0099…` as `zpk`.
    fn unstable(kind: &str) -> AnySignal {
        let spec = if kind == "tf" {
            json!({"kind": "tf", "num": [1.0], "den": [1.0, 1.0, -0.01], "unstable": true})
        } else {
            json!({"kind": "zpk", "gain": 1.0, "poles": [0.01, -1.01], "unstable": true})
        };
        let input = Input::Piecewise(PiecewiseConstant::new(vec![0.0, 100.0], vec![1.0]).unwrap());
        SignalRegistry::builtin()
            .build(spec.as_object().unwrap(), Some(&input))
            .unwrap()
    }

    #[test]
    fn a_model_with_a_pole_right_of_the_axis_is_exported() {
        for kind in ["tf", "zpk"] {
            let s = unstable(kind);
            let forms = model_forms(&s).unwrap().expect("a rational system");
            let right = forms.zpk.poles().iter().filter(|p| p.re > 0.0).count();
            assert_eq!(right, 1, "{kind}: {:?}", forms.zpk.poles());
            // The static gain of 1/(s² + a1 s + a0) is 1/a0, whatever the sign of a0.
            let a0 = *forms.tf.den().last().unwrap();
            let bode = bode_of(&s, &[1e-9], None).unwrap().unwrap();
            let db = 20.0 * (1.0 / a0.abs()).log10();
            assert!((bode[0].magnitude_db - db).abs() < 1e-6, "{kind}: {bode:?}");
            let step = step_of(&s, &[0.0, 1.0], None).unwrap().unwrap();
            assert_eq!(step.len(), 2, "{kind}");
        }
    }

    /// `1/(s(s + 1))` with its integrator held: exported with the pole at the origin, and its
    /// Bode band built from the covariance of the two free parameters (`b0`, `a1`).
    #[test]
    fn a_model_with_integrators_is_exported_with_them() {
        for spec in [
            json!({"kind": "tf", "num": [1.0], "den": [1.0, 1.0, 0.0], "integrators": 1}),
            json!({"kind": "zpk", "gain": 1.0, "poles": [0.0, -1.0], "integrators": 1}),
        ] {
            let input =
                Input::Piecewise(PiecewiseConstant::new(vec![0.0, 100.0], vec![1.0]).unwrap());
            let s = SignalRegistry::builtin()
                .build(spec.as_object().unwrap(), Some(&input))
                .unwrap();
            let forms = model_forms(&s).unwrap().unwrap();
            assert_eq!(forms.tf.den(), &[1.0, 1.0, 0.0], "{spec}");
            let cov = vec![vec![0.01, 0.0], vec![0.0, 0.01]];
            let bode = bode_of(&s, &[0.1], Some(&cov)).unwrap().unwrap();
            assert!(bode[0].magnitude_db_lo.is_some(), "{spec}");
        }
    }

    #[test]
    fn other_signals_have_no_model() {
        let spec = json!({"kind": "sinusoid", "amplitude": 1.0, "frequency": 0.1, "phase": 0.0});
        let s = SignalRegistry::builtin()
            .build(spec.as_object().unwrap(), None)
            .unwrap();
        assert!(model_forms(&s).unwrap().is_none());
        assert!(bode_of(&s, &[0.1], None).is_none());
    }

    #[test]
    fn exported_model_and_phase_carry_the_delay() {
        let s = signal(&THETA, Some(DELAY));
        assert_eq!(model_forms(&s).unwrap().unwrap().delay, Some(DELAY));
        assert_eq!(
            model_forms(&signal(&THETA, None)).unwrap().unwrap().delay,
            None
        );
        let points = bode_of(&s, &FREQS, None).unwrap().unwrap();
        for p in &points {
            let h = by_hand(&THETA, DELAY, p.f_hz);
            assert!((p.magnitude_db - 20.0 * h.norm().log10()).abs() < 1e-10);
            // The CSV's phase is unwrapped; equal to arg H up to whole turns.
            let turns = (p.phase_deg - h.arg().to_degrees()) / 360.0;
            assert!((turns - turns.round()).abs() < 1e-10, "{p:?}");
        }
        // Unwrapped along the grid: the delay alone turns the phase by −360 f D.
        let plain = bode_of(&signal(&THETA, None), &FREQS, None)
            .unwrap()
            .unwrap();
        for (a, b) in points.iter().zip(&plain) {
            assert!((a.phase_deg - b.phase_deg + 360.0 * a.f_hz * DELAY).abs() < 1e-9);
        }
    }

    /// Central differences of `value(θ)` in each of the five parameters (delay last).
    fn gradient(value: impl Fn(&[f64]) -> f64) -> Vec<f64> {
        let base = [THETA[0], THETA[1], THETA[2], THETA[3], DELAY];
        (0..5)
            .map(|j| {
                let h = 1e-6;
                let (mut up, mut down) = (base, base);
                up[j] += h;
                down[j] -= h;
                (value(&up) - value(&down)) / (2.0 * h)
            })
            .collect()
    }

    #[test]
    fn the_delayed_phase_band_matches_finite_differences() {
        let c = covariance();
        let s = signal(&THETA, Some(DELAY));
        let points = bode_of(&s, &FREQS, Some(&c)).unwrap().unwrap();
        for p in &points {
            let f = p.f_hz;
            let reference = by_hand(&THETA, DELAY, f);
            // The phase relative to the base point's, so that no wrap enters the difference.
            let phase = |t: &[f64]| (by_hand(t, t[4], f) / reference).arg().to_degrees();
            let magnitude = |t: &[f64]| 20.0 * by_hand(t, t[4], f).norm().log10();
            let sd = |g: Vec<f64>| BAND_SIGMAS * validation::delta_method_variance(&c, &g).sqrt();
            let (dp, dm) = (sd(gradient(phase)), sd(gradient(magnitude)));
            let half = p.phase_deg_hi.unwrap() - p.phase_deg;
            assert!((half - dp).abs() < 1e-6 * dp, "f {f}: {half} vs {dp}");
            let half = p.magnitude_db_hi.unwrap() - p.magnitude_db;
            assert!((half - dm).abs() < 1e-6 * dm, "f {f}: {half} vs {dm}");
        }
        // A covariance without the delay's row is refused, not read as G's alone.
        let short: Vec<Vec<f64>> = c[..4].iter().map(|r| r[..4].to_vec()).collect();
        assert!(bode_of(&s, &FREQS, Some(&short)).unwrap().is_err());
    }

    #[test]
    fn the_delayed_step_is_shifted_and_its_band_matches_finite_differences() {
        let c = covariance();
        let times = [0.0, 0.5, 1.29, 1.31, 2.0, 4.5, 9.0];
        let delayed = step_of(&signal(&THETA, Some(DELAY)), &times, Some(&c))
            .unwrap()
            .unwrap();
        let step_at = |t: &[f64], time: f64| {
            if time < t[4] {
                return 0.0;
            }
            step_of(&signal(&t[..4], None), &[time - t[4]], None)
                .unwrap()
                .unwrap()[0]
                .value
        };
        for p in &delayed {
            assert!(
                (p.value - step_at(&[THETA[0], THETA[1], THETA[2], THETA[3], DELAY], p.t)).abs()
                    < 1e-12
            );
            if p.t < DELAY {
                assert_eq!(p.value, 0.0);
                continue;
            }
            let g = gradient(|t| step_at(t, p.t));
            let sd = BAND_SIGMAS * validation::delta_method_variance(&c, &g).sqrt();
            let half = p.hi.unwrap() - p.value;
            assert!(
                (half - sd).abs() < 1e-6 * sd.max(1e-9),
                "t {}: {half} vs {sd}",
                p.t
            );
        }
    }
}
