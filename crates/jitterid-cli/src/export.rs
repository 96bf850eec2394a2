//! The fitted model taken out of the command line: transfer-function coefficients, zeros,
//! poles and gain, and a state-space realisation (`fit --json`'s `model`), and the covariance
//! of the reported parameters.

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
