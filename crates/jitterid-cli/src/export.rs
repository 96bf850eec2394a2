//! The fitted model taken out of the command line: transfer-function coefficients, zeros,
//! poles and gain, and a state-space realisation (`fit --json`'s `model`), and the covariance
//! of the reported parameters.

use jitterid::estimate::{validation, EstimateError};
use jitterid::signal::forms::{StateSpace, TfForm, ZpkForm};
use jitterid::signal::registry::{SignalRegistry, SpecReader};
use jitterid::signal::{AnySignal, SignalError, TransferFunction, Zpk};
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
}

/// The coefficients of a rational system (rebuilt from the signal's spec table), `None` for
/// other signal kinds.
pub fn tf_of(signal: &AnySignal) -> Option<TfForm> {
    let spec = signal.spec();
    let kind = SignalRegistry::builtin().kind(signal.kind())?;
    let rebuilt = || -> Result<Option<TfForm>, SignalError> {
        let r = SpecReader::new(kind, &spec)?;
        Ok(match signal.kind() {
            "zpk" => Some(TfForm::of(&Zpk::new(
                r.f64("gain")?,
                r.roots("zeros")?,
                r.roots("poles")?,
            )?)),
            "tf" => Some(TfForm::of(&TransferFunction::new(
                &r.f64_list("num")?,
                &r.f64_list("den")?,
            )?)),
            _ => None,
        })
    };
    rebuilt().ok().flatten()
}

/// The fitted model in every export form, `None` for signals that are not rational systems.
pub fn model_forms(signal: &AnySignal) -> Option<ModelForms> {
    let tf = tf_of(signal)?;
    Some(ModelForms {
        zpk: tf.to_zpk().ok()?,
        ss: tf.to_state_space(),
        tf,
    })
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

/// The signal's system as a [`Zpk`] in the signal's own parameterisation (so that the rows of
/// its covariance match), `None` for other kinds.
fn zpk_of(signal: &AnySignal) -> Option<Zpk> {
    let kind = SignalRegistry::builtin().kind("zpk")?;
    let spec = signal.spec();
    let r = SpecReader::new(kind, &spec).ok()?;
    (signal.kind() == "zpk")
        .then(|| {
            Zpk::new(
                r.f64("gain").ok()?,
                r.roots("zeros").ok()?,
                r.roots("poles").ok()?,
            )
            .ok()
        })
        .flatten()
}

/// The signal's system as a [`TransferFunction`], `None` for other kinds.
fn transfer_function_of(signal: &AnySignal) -> Option<TransferFunction> {
    let kind = SignalRegistry::builtin().kind("tf")?;
    let spec = signal.spec();
    let r = SpecReader::new(kind, &spec).ok()?;
    (signal.kind() == "tf")
        .then(|| TransferFunction::new(&r.f64_list("num").ok()?, &r.f64_list("den").ok()?).ok())
        .flatten()
}

/// The Bode diagram of a rational signal's system at `freqs` with delta-method bands from the
/// covariance of its parameters; `None` for other signal kinds.
pub fn bode_of(
    signal: &AnySignal,
    freqs: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Option<Result<Vec<validation::BodePoint>, EstimateError>> {
    if let Some(z) = zpk_of(signal) {
        return Some(validation::bode(&z, freqs, covariance));
    }
    transfer_function_of(signal).map(|t| validation::bode(&t, freqs, covariance))
}

/// The unit-step response of a rational signal's system with delta-method bands; `None` for
/// other signal kinds.
pub fn step_of(
    signal: &AnySignal,
    times: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Option<Result<Vec<validation::StepPoint>, EstimateError>> {
    if let Some(z) = zpk_of(signal) {
        return Some(validation::step_response(&z, times, covariance));
    }
    transfer_function_of(signal).map(|t| validation::step_response(&t, times, covariance))
}
