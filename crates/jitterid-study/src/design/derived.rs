//! Predicted precision of quantities derived from the parameters: what a user plans for is
//! often not a pole's real part but the static gain, a pole's natural frequency, the gain at an
//! operating frequency or the jitter's standard deviation. Their standard deviations follow from a prediction by the delta
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
    /// The natural frequency `|p|/2π` (Hz) of the `k`-th pole (from 0), a complex pair counted
    /// once, the poles ordered by `|p|` (an order a small change of the parameters keeps);
    /// named `pole{k+1}.frequency`.
    PoleFrequency(usize),
}

/// How close to the real axis, relative to `|p|`, a pole counts as real: a real pole comes
/// out of the root finder with at most rounding in its imaginary part.
const REAL_POLE: f64 = 1e-9;

/// The natural frequencies `|p|/2π` (Hz) of the poles of `G`, a complex pair once (its member
/// with positive imaginary part), in increasing order: an order that a small change of the
/// parameters keeps unless two frequencies are equal, unlike the root finder's.
pub(crate) fn pole_frequencies(model: &Structure) -> Option<Vec<f64>> {
    let tf = tf_of(&model.signal).ok()??;
    let zpk = tf.to_zpk().ok()?;
    let mut f: Vec<f64> = zpk
        .poles()
        .iter()
        .filter(|p| p.im > -REAL_POLE * p.norm())
        .map(|p| p.norm() / TAU)
        .collect();
    f.sort_by(f64::total_cmp);
    f.iter().all(|v| v.is_finite()).then_some(f)
}

impl Derived {
    /// The name reported beside the parameters (`static_gain`, `|G|@0.05Hz`, `jitter.sigma`,
    /// `pole1.frequency`).
    pub fn name(&self) -> String {
        match self {
            Self::StaticGain => "static_gain".into(),
            Self::Magnitude(f) => format!("|G|@{f}Hz"),
            Self::JitterStd => "jitter.sigma".into(),
            Self::PoleFrequency(k) => format!("pole{}.frequency", k + 1),
        }
    }

    /// Its value at `model`, `None` where it is not defined (a system without a transfer
    /// function, an integrator's infinite static gain, a pole the model does not have).
    pub(crate) fn value(&self, model: &Structure) -> Option<f64> {
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
            Self::PoleFrequency(k) => pole_frequencies(model)?.get(*k).copied(),
        }
    }
}

/// The predicted standard deviation of `quantity` by the delta method.
///
/// # Errors
///
/// The quantity is not defined at the truth (a signal without a transfer function, an
/// integrator's static gain, a frequency that is not finite, a pole beyond the model's order)
/// or has no finite-difference gradient there (a pole frequency's order changes within the
/// step: two poles of equal `|p|`).
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
    quantity.value(model).ok_or_else(|| match quantity {
        Derived::PoleFrequency(k) => study_err!(
            "{name}: not defined at the prior model (it needs a system with a transfer function and at least {} poles or complex pairs)",
            k + 1
        ),
        _ => study_err!("{name}: not defined at the prior model (it needs a system with a transfer function and a finite static gain)"),
    })?;
    let theta = model.params();
    let count = pole_frequencies(model).map(|f| f.len());
    let at = |t: &[f64]| -> Option<Vec<f64>> {
        let m = model.with_params(t).ok()?;
        // A pole pair that splits into two real poles (or two that merge) within the step
        // renumbers the frequencies: no difference across it.
        if matches!(quantity, Derived::PoleFrequency(_))
            && pole_frequencies(&m).map(|f| f.len()) != count
        {
            return None;
        }
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
