//! The data-driven start of a rational system's spec table (`fit --init auto`): the
//! initializer's fit written back into the model's own keys, for one input
//! ([`crate::select::auto_start`]) and for one transfer function per input ([`channels_start`],
//! the multi-input initializer [`fit_channels`]).

use crate::error::StudyResult;
use crate::experiment::Experiment;
use crate::fit;
use crate::study_err;
use jitterid::estimate::{fit_channels, ChannelOrder, InitOptions, InitialModel, RationalFit};
use jitterid::jitter::JitterModel;
use jitterid::signal::registry::{roots_json, SpecTable};
use jitterid::signal::{AnySignal, Input, Root, Signal, TransferFunction, Zpk};
use serde_json::{json, Value};

/// The parameterisation of a rational model read from its spec table: the template whose
/// orders the initializer fits and whose keys its fit is written into.
pub(crate) enum Template {
    /// `kind = "tf"`: `num`, `den`.
    Tf(TransferFunction),
    /// `kind = "zpk"`: `gain`, `zeros`, `poles` (real roots and pairs kept as they are).
    Zpk(Zpk),
}

fn roots_of(spec: &SpecTable, key: &str) -> Option<Vec<Root>> {
    let Some(v) = spec.get(key) else {
        return Some(Vec::new());
    };
    v.as_array()?
        .iter()
        .map(|r| Root::from_json(r).ok())
        .collect()
}

fn f64s(spec: &SpecTable, key: &str) -> Option<Vec<f64>> {
    spec.get(key)?
        .as_array()?
        .iter()
        .map(Value::as_f64)
        .collect()
}

impl Template {
    /// The template of `spec` (a model of kind `kind`); `at` names the section in messages.
    pub(crate) fn of(kind: &str, spec: &SpecTable, at: &str) -> StudyResult<Self> {
        match kind {
            "tf" => {
                let (num, den) = f64s(spec, "num")
                    .zip(f64s(spec, "den"))
                    .ok_or_else(|| study_err!("{at} num, den: not numbers"))?;
                let tf = TransferFunction::new(&num, &den).map_err(|e| study_err!("{at}: {e}"))?;
                Ok(Self::Tf(tf))
            }
            "zpk" => {
                let (zeros, poles) = roots_of(spec, "zeros")
                    .zip(roots_of(spec, "poles"))
                    .ok_or_else(|| study_err!("{at} zeros, poles: not roots"))?;
                let zpk = Zpk::new(1.0, zeros, poles).map_err(|e| study_err!("{at}: {e}"))?;
                Ok(Self::Zpk(zpk))
            }
            other => Err(study_err!(
                "{at}: --init auto: the initializer fits rational systems (kind tf or zpk), not `{other}`"
            )),
        }
    }

    /// Numbers of zeros and of poles.
    pub(crate) fn orders(&self) -> (usize, usize) {
        match self {
            Self::Tf(t) => t.orders(),
            Self::Zpk(z) => z.orders(),
        }
    }

    /// `spec` with the model's keys replaced by `fit` in this parameterisation.
    ///
    /// A model with structural integrators (`integrators = n`) holds `n` poles at exactly 0,
    /// which the initializer's free fit puts only near it: the start moves them there (the
    /// last `n` coefficients of `den` set to 0, or the `n` real poles nearest the origin), a
    /// small change of a start that the fit then refines.
    pub(crate) fn write(&self, fit: &RationalFit, spec: &mut SpecTable) -> StudyResult<()> {
        let err = |e| study_err!("--init auto: the initializer's model: {e}");
        let held = spec.get("integrators").and_then(Value::as_u64).unwrap_or(0) as usize;
        match self {
            Self::Tf(t) => {
                let g = t.with_fit(fit).map_err(err)?;
                let mut den = g.den().to_vec();
                let n = den.len();
                den[n - held.min(n - 1)..].iter_mut().for_each(|a| *a = 0.0);
                spec.insert("num".into(), json!(g.num()));
                spec.insert("den".into(), json!(den));
            }
            Self::Zpk(z) => {
                let g = z.with_fit(fit).map_err(err)?;
                let mut poles = g.poles().to_vec();
                let mut real: Vec<usize> = (0..poles.len())
                    .filter(|&i| matches!(poles[i], Root::Real(_)))
                    .collect();
                real.sort_by(|&a, &b| {
                    let m = |i: usize| match poles[i] {
                        Root::Real(p) => p.abs(),
                        _ => f64::INFINITY,
                    };
                    m(a).total_cmp(&m(b))
                });
                if real.len() < held {
                    return Err(study_err!(
                        "--init auto: the initializer's model has {} real pole(s) to hold at the origin for integrators = {held}; start from the experiment's values (--init experiment)",
                        real.len()
                    ));
                }
                for &i in &real[..held] {
                    poles[i] = Root::Real(0.0);
                }
                spec.insert("gain".into(), json!(g.gain()));
                spec.insert("zeros".into(), roots_json(g.zeros()));
                spec.insert("poles".into(), roots_json(&poles));
            }
        }
        Ok(())
    }
}

/// `input` as the rational part of the system in `spec` sees it, what the initializer fits a
/// response to: around the input's level (`u − u₀` over its span, the file's `u₀`, the start of
/// an estimated one), then delayed by the system's delay, so that the rational model does not
/// carry the delay's phase a second time. `file` and `at` (the system's section) name the keys
/// in messages.
///
/// # Errors
///
/// A level or delay the input cannot take (a tone input's delay).
pub(crate) fn driven_input(
    input: &Input,
    spec: &SpecTable,
    file: &str,
    at: &str,
) -> StudyResult<Input> {
    let around = match spec.get("level").and_then(Value::as_f64) {
        Some(u0) => input
            .deviation(u0)
            .map_err(|e| study_err!("{file}: [input] level: {e}"))?,
        None => input.clone(),
    };
    match spec.get("delay").and_then(Value::as_f64) {
        Some(d) if d > 0.0 => around.delayed(d).map_err(|e| study_err!("{at} delay: {e}")),
        _ => Ok(around),
    }
}

/// The multi-input system `signal` (a `superposition`) with each estimated channel's model
/// replaced by the multi-input initializer's ([`fit_channels`], the jitter's damping
/// compensated with the experiment's jitter) on the record `y` less the fixed channels'
/// expected samples. Each channel keeps its other keys (a delay, whose delayed input the
/// initializer sees, an initial state); the output offset is started by the caller.
///
/// # Errors
///
/// A grey-box channel or one shared model (no rational template), and the initializer's
/// failures, naming the record `data`.
pub(crate) fn channels_start(
    exp: &Experiment,
    signal: &AnySignal,
    inputs: &[Input],
    y: &[f64],
    data: &str,
) -> StudyResult<AnySignal> {
    let mut spec = signal.spec();
    if spec.get("shared") == Some(&Value::Bool(true)) {
        return Err(study_err!(
            "{}: [system] kind: --init auto fits one transfer function per input, not a grey-box model with a column per input; start from the experiment's values (--init experiment)",
            exp.file
        ));
    }
    let list = |key: &str| spec.get(key).and_then(Value::as_array).cloned();
    let (Some(channels), Some(estimated)) = (list("channels"), list("estimate")) else {
        return Err(study_err!(
            "{}: [[system]]: not a multi-input system",
            exp.file
        ));
    };
    let jitter: &dyn JitterModel = &exp.jitter.model;
    // The fixed channels are known: their expected samples leave the record first.
    let mut rest = y.to_vec();
    let mut free = Vec::new();
    for (i, ((c, e), input)) in channels.iter().zip(&estimated).zip(inputs).enumerate() {
        let c = c.as_object().cloned().unwrap_or_default();
        let at = format!("{}: [[system]] {}", exp.file, i + 1);
        if e.as_bool() != Some(true) {
            let own = exp
                .registries
                .signal
                .build(&c, Some(input))
                .map_err(|e| study_err!("{at}: {e}"))?;
            let m = own.expected_values(&exp.grid, jitter);
            rest.iter_mut().zip(&m).for_each(|(r, m)| *r -= m);
            continue;
        }
        let kind = c.get("kind").and_then(Value::as_str).unwrap_or("");
        let template = Template::of(kind, &c, &at)?;
        let driven = driven_input(input, &c, &exp.file, &at)?;
        free.push((i, template, driven));
    }
    let record = fit::record(&exp.grid, rest).map_err(|e| study_err!("{data}: {e}"))?;
    let orders: Vec<ChannelOrder<'_>> = free
        .iter()
        .map(|(_, t, driven)| {
            let (zeros, poles) = t.orders();
            ChannelOrder {
                input: driven,
                zeros,
                poles,
            }
        })
        .collect();
    // An estimated output offset moves only the bin f = 0, which the initializer leaves out.
    let opts = InitOptions {
        offset: spec.get("estimate_offset") == Some(&Value::Bool(true)),
        ..InitOptions::default()
    };
    let fits = fit_channels(&record, &orders, Some(jitter), &opts)
        .map_err(|e| study_err!("{data}: --init auto: the initializer failed: {e}"))?;
    let mut channels = channels;
    for ((i, template, _), f) in free.iter().zip(&fits) {
        if let Some(Value::Object(c)) = channels.get_mut(*i) {
            template.write(f, c)?;
        }
    }
    spec.insert("channels".into(), Value::Array(channels));
    fit::build_signal(exp, &spec, inputs)
        .map_err(|e| study_err!("{data}: --init auto: the initializer's model: {e}"))
}
