//! Predicted precision of quantities derived from the parameters: what a user plans for is
//! often not a pole's real part but the static gain, the gain at an operating frequency or the
//! jitter's standard deviation. Their standard deviations follow from a prediction by the delta
//! method, `√(gᵀ C g)` with `g` the quantity's gradient in the estimated parameters (central
//! differences of the model rebuilt at shifted parameters, so any system kind with a transfer
//! function and any jitter family work alike).

use super::predict::Prediction;
use crate::error::StudyResult;
use crate::export::tf_of;
use crate::fit::Structure;
use crate::study_err;
use jitterid::estimate::ml::delta_method_std;
use jitterid::estimate::solver::finite_diff::{central_difference_vec, MOMENT_FD_STEP};
use jitterid::jitter::JitterModel;
use jitterid::num_complex::Complex64;
use std::f64::consts::TAU;

/// A quantity derived from the model's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Derived {
    /// The static gain `G(0)`.
    StaticGain,
    /// The gain `|G(i2πf)|` at `f` Hz.
    Magnitude(f64),
    /// The jitter's standard deviation (s).
    JitterStd,
}

impl Derived {
    /// The name reported beside the parameters (`static_gain`, `|G|@0.05Hz`, `jitter.sigma`).
    pub fn name(&self) -> String {
        match self {
            Self::StaticGain => "static_gain".into(),
            Self::Magnitude(f) => format!("|G|@{f}Hz"),
            Self::JitterStd => "jitter.sigma".into(),
        }
    }

    /// Its value at `model`, `None` where it is not defined (a system without a transfer
    /// function, an integrator's infinite static gain).
    fn value(&self, model: &Structure) -> Option<f64> {
        let g = |s: Complex64| -> Option<f64> {
            let tf = tf_of(&model.signal).ok()??;
            Some(tf.response(s))
                .filter(|g| g.is_finite())
                .map(|g| match self {
                    Self::StaticGain => g.re,
                    _ => g.norm(),
                })
        };
        match self {
            Self::StaticGain => g(Complex64::new(0.0, 0.0)),
            Self::Magnitude(f) => g(Complex64::new(0.0, TAU * f)),
            Self::JitterStd => Some(model.jitter.std_dev()).filter(|s| s.is_finite()),
        }
    }
}

/// The predicted standard deviation of `quantity` by the delta method.
///
/// # Errors
///
/// The quantity is not defined at the truth (a signal without a transfer function, an
/// integrator's static gain, a frequency that is not finite) or has no finite-difference
/// gradient there.
pub fn derived_std(prediction: &Prediction, quantity: Derived) -> StudyResult<f64> {
    let name = quantity.name();
    if let Derived::Magnitude(f) = quantity {
        if !(f.is_finite() && f >= 0.0) {
            return Err(study_err!(
                "{name}: expected a finite frequency >= 0 Hz, found {f}"
            ));
        }
    }
    let model = &prediction.model;
    quantity.value(model).ok_or_else(|| {
        study_err!("{name}: not defined at the prior model (it needs a system with a transfer function and a finite static gain)")
    })?;
    let theta = model.params();
    let at = |t: &[f64]| -> Option<Vec<f64>> {
        let m = model.with_params(t).ok()?;
        quantity.value(&m).map(|v| vec![v])
    };
    let mut gradient = vec![0.0; prediction.names.len()];
    for (j, g) in gradient.iter_mut().enumerate().take(theta.len()) {
        let d = central_difference_vec(&theta, j, MOMENT_FD_STEP, at).ok_or_else(|| {
            study_err!(
                "{name}: no finite difference in {} at the prior model",
                prediction.names[j]
            )
        })?;
        *g = d[0];
    }
    delta_method_std(&prediction.covariance, &gradient).map_err(|e| study_err!("{name}: {e}"))
}
