//! Frequency and step responses of a rational model with an input delay, `G(s) e^{−sD}`, with
//! bands from a covariance that includes the delay.

use super::response::{
    bode, check_covariance, delta_method_variance, log_response_gradient, non_negative, step_point,
    step_value_and_gradient, BodePoint, StepPoint, BAND_SIGMAS,
};
use jitterid_estimate::EstimateError;
use jitterid_signal::RationalModel;
use std::f64::consts::LN_10;

/// The covariance without its last (the delay's) row and column, checked to be `(p + 1)`
/// square.
fn without_delay(
    covariance: Option<&[Vec<f64>]>,
    p: usize,
) -> Result<Option<Vec<Vec<f64>>>, EstimateError> {
    check_covariance(covariance, p + 1)?;
    Ok(covariance.map(|c| c[..p].iter().map(|r| r[..p].to_vec()).collect()))
}

/// [`bode`] of `G(i2πf) e^{−i2πfD}`: `G`'s diagram with the delay's phase `−360 f D` degrees.
/// `covariance` is over `G`'s parameters then the delay (`(p + 1) × (p + 1)`, the order of a
/// delayed signal's parameters); the phase band includes the delay's variance and its
/// covariances with `G`'s parameters (`∂ arg/∂D = −360 f` degrees per second), and the
/// magnitude does not depend on `D`.
///
/// Errors: those of [`bode`]; a delay that is not finite and ≥ 0; a covariance that is not
/// `(p + 1) × (p + 1)` and finite.
pub fn delayed_bode<M: RationalModel>(
    model: &M,
    delay: f64,
    freqs: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Result<Vec<BodePoint>, EstimateError> {
    non_negative("delay", delay)?;
    let p = model.params().len();
    let own = without_delay(covariance, p)?;
    let mut points = bode(model, freqs, own.as_deref())?;
    let to_deg = 180.0 / std::f64::consts::PI;
    for point in &mut points {
        let f = point.f_hz;
        point.phase_deg -= 360.0 * f * delay;
        let Some(c) = covariance else { continue };
        let (_, dlog) = log_response_gradient(model, f);
        let mut phase: Vec<f64> = dlog.iter().map(|g| to_deg * g.im).collect();
        phase.push(-360.0 * f);
        let mut magnitude: Vec<f64> = dlog.iter().map(|g| 20.0 / LN_10 * g.re).collect();
        magnitude.push(0.0);
        let dm = BAND_SIGMAS * delta_method_variance(c, &magnitude).max(0.0).sqrt();
        let dp = BAND_SIGMAS * delta_method_variance(c, &phase).max(0.0).sqrt();
        point.magnitude_db_lo = Some(point.magnitude_db - dm);
        point.magnitude_db_hi = Some(point.magnitude_db + dm);
        point.phase_deg_lo = Some(point.phase_deg - dp);
        point.phase_deg_hi = Some(point.phase_deg + dp);
    }
    Ok(points)
}

/// The unit-step response of `G(s) e^{−sD}`: `G`'s shifted by `D` (zero before), with the
/// band of `(∇_θ y_G(t − D), −h(t − D))`, `h` the impulse response `Σ r_i e^{p_i t}` (modal
/// form). `covariance` is over `G`'s parameters then the delay.
///
/// Errors: a time that is not finite and ≥ 0; a delay that is not finite and ≥ 0; a
/// covariance that is not `(p + 1) × (p + 1)` and finite.
pub fn delayed_step_response<M: RationalModel>(
    model: &M,
    delay: f64,
    times: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Result<Vec<StepPoint>, EstimateError> {
    non_negative("delay", delay)?;
    let p = model.params().len();
    check_covariance(covariance, p + 1)?;
    times
        .iter()
        .map(|&t| {
            non_negative("time", t)?;
            let shifted = t - delay;
            let (value, mut grad) = if shifted >= 0.0 {
                step_value_and_gradient(model, shifted)
            } else {
                (0.0, vec![0.0; p])
            };
            let impulse: f64 = if shifted > 0.0 {
                model.rational().impulse_response(shifted)
            } else {
                0.0
            };
            grad.push(-impulse);
            Ok(step_point(t, value, &grad, covariance))
        })
        .collect()
}
