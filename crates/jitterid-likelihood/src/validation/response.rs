//! Frequency and step responses of a fitted rational model with delta-method confidence bands
//! from the estimator's covariance.

use jitterid_estimate::EstimateError;
use jitterid_signal::RationalModel;
use num_complex::Complex64;
use std::f64::consts::{LN_10, TAU};

/// The half-width of the bands in standard deviations (about 95 % for a Gaussian estimate).
pub const BAND_SIGMAS: f64 = 2.0;

/// One frequency of a Bode diagram (the columns of the frequency-response CSV).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BodePoint {
    /// Frequency (Hz).
    pub f_hz: f64,
    /// Angular frequency `2πf` (rad/s).
    pub omega_rad_s: f64,
    /// `20 log10 |G(i2πf)|`.
    pub magnitude_db: f64,
    /// `arg G(i2πf)` in degrees, unwrapped along the grid.
    pub phase_deg: f64,
    /// Lower end of the magnitude band, `magnitude_db − 2σ` (`None` without a covariance).
    pub magnitude_db_lo: Option<f64>,
    /// Upper end of the magnitude band.
    pub magnitude_db_hi: Option<f64>,
    /// Lower end of the phase band.
    pub phase_deg_lo: Option<f64>,
    /// Upper end of the phase band.
    pub phase_deg_hi: Option<f64>,
}

/// One instant of a step response.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StepPoint {
    /// Time after the step (s).
    pub t: f64,
    /// The response to a unit step at 0.
    pub value: f64,
    /// `value − 2σ` (`None` without a covariance).
    pub lo: Option<f64>,
    /// `value + 2σ`.
    pub hi: Option<f64>,
}

/// `Σ_ij g_i C_ij g_j`, the delta-method variance of a quantity with gradient `g`.
pub fn delta_method_variance(covariance: &[Vec<f64>], g: &[f64]) -> f64 {
    g.iter()
        .zip(covariance)
        .map(|(gi, row)| gi * row.iter().zip(g).map(|(c, gj)| c * gj).sum::<f64>())
        .sum()
}

/// Checks that `covariance` is `p × p` and finite.
///
/// Errors: [`EstimateError::WrongParamCount`] for another shape, [`EstimateError::BadArgument`]
/// naming the first entry that is not finite.
pub fn check_covariance(covariance: Option<&[Vec<f64>]>, p: usize) -> Result<(), EstimateError> {
    let Some(c) = covariance else { return Ok(()) };
    if c.len() != p || c.iter().any(|row| row.len() != p) {
        return Err(EstimateError::WrongParamCount {
            expected: p,
            got: c.iter().map(Vec::len).find(|&l| l != p).unwrap_or(c.len()),
        });
    }
    if let Some(v) = c.iter().flatten().find(|v| !v.is_finite()) {
        return Err(EstimateError::BadArgument {
            name: "covariance",
            value: *v,
            reason: "every entry must be finite",
        });
    }
    Ok(())
}

/// `(ln|G|, arg G)` gradients: `∂ln|G|/∂θ = Re(∂G/∂θ / G)`, `∂arg G/∂θ = Im(∂G/∂θ / G)`.
pub fn log_response_gradient<M: RationalModel>(model: &M, f: f64) -> (Complex64, Vec<Complex64>) {
    let s = Complex64::new(0.0, TAU * f);
    let g = model.response(s);
    let mut dg = vec![Complex64::new(0.0, 0.0); model.params().len()];
    model.rational().response_gradient(s, &mut dg);
    (g, dg.into_iter().map(|d| d / g).collect())
}

/// The Bode diagram of `model` at frequencies `freqs` (Hz, increasing), with ±2σ bands from
/// `covariance` (of the model's parameters, in their order) by the delta method:
/// `σ² = ∇ᵀ C ∇` with `∇ = ∂(20 log10|G|)/∂θ = (20/ln 10) Re(∂G/∂θ / G)` for the magnitude and
/// `(180/π) Im(∂G/∂θ / G)` for the phase.
///
/// Errors: a frequency that is not finite and ≥ 0, a covariance that is not `p × p` or not
/// finite, a frequency where `G = 0` (no finite magnitude in dB).
pub fn bode<M: RationalModel>(
    model: &M,
    freqs: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Result<Vec<BodePoint>, EstimateError> {
    check_covariance(covariance, model.params().len())?;
    let mut out = Vec::with_capacity(freqs.len());
    let mut previous: Option<f64> = None;
    for &f in freqs {
        if !(f.is_finite() && f >= 0.0) {
            return Err(EstimateError::BadArgument {
                name: "frequency",
                value: f,
                reason: "must be finite and >= 0",
            });
        }
        let (g, dlog) = log_response_gradient(model, f);
        if !(g.norm() > 0.0 && g.norm().is_finite()) {
            return Err(EstimateError::BadArgument {
                name: "frequency",
                value: f,
                reason: "the response is zero or not finite there",
            });
        }
        let magnitude_db = 20.0 * g.norm().log10();
        let mut phase_deg = g.arg().to_degrees();
        if let Some(q) = previous {
            phase_deg -= 360.0 * ((phase_deg - q) / 360.0).round();
        }
        previous = Some(phase_deg);
        let band = |scale: f64, part: fn(&Complex64) -> f64| {
            covariance.map(|c| {
                let grad: Vec<f64> = dlog.iter().map(|d| scale * part(d)).collect();
                BAND_SIGMAS * delta_method_variance(c, &grad).max(0.0).sqrt()
            })
        };
        let dm = band(20.0 / LN_10, |d| d.re);
        let dp = band(180.0 / std::f64::consts::PI, |d| d.im);
        out.push(BodePoint {
            f_hz: f,
            omega_rad_s: TAU * f,
            magnitude_db,
            phase_deg,
            magnitude_db_lo: dm.map(|d| magnitude_db - d),
            magnitude_db_hi: dm.map(|d| magnitude_db + d),
            phase_deg_lo: dp.map(|d| phase_deg - d),
            phase_deg_hi: dp.map(|d| phase_deg + d),
        });
    }
    Ok(out)
}

/// The unit-step response `y(t)` from rest and its gradient ([`Rational::step_response`]:
/// modal form, or the model's realisation for repeated poles and integrators).
///
/// [`Rational::step_response`]: jitterid_signal::Rational::step_response
pub fn step_value_and_gradient<M: RationalModel>(model: &M, t: f64) -> (f64, Vec<f64>) {
    let mut grad = vec![0.0; model.params().len()];
    let value = model.rational().step_response(t, &mut grad);
    (value, grad)
}

/// The unit-step response of `model` at times `times` (s after the step, ≥ 0) with ±2σ bands
/// from `covariance` by the delta method.
///
/// Errors: a time that is not finite and ≥ 0, a covariance that is not `p × p` or not finite.
pub fn step_response<M: RationalModel>(
    model: &M,
    times: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> Result<Vec<StepPoint>, EstimateError> {
    check_covariance(covariance, model.params().len())?;
    times
        .iter()
        .map(|&t| {
            non_negative("time", t)?;
            let (value, grad) = step_value_and_gradient(model, t);
            Ok(step_point(t, value, &grad, covariance))
        })
        .collect()
}

/// An argument that must be finite and ≥ 0 (a time, a delay).
pub(super) fn non_negative(name: &'static str, value: f64) -> Result<(), EstimateError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(EstimateError::BadArgument {
            name,
            value,
            reason: "must be finite and >= 0",
        })
    }
}

/// The point at `t` with its band from the gradient `grad` and `covariance`.
pub(super) fn step_point(
    t: f64,
    value: f64,
    grad: &[f64],
    covariance: Option<&[Vec<f64>]>,
) -> StepPoint {
    let d = covariance.map(|c| BAND_SIGMAS * delta_method_variance(c, grad).max(0.0).sqrt());
    StepPoint {
        t,
        value,
        lo: d.map(|d| value - d),
        hi: d.map(|d| value + d),
    }
}
