//! A multisine's sample sequence at a DAC rate: what a signal generator plays.
//!
//! The designed tones are harmonics of `1/(N T)`, so one record is one period: the sequence
//! `u(t₀ + m/f_s)`, `m = 0 … round(N T f_s) − 1`, loops without a jump when the record length
//! is a whole number of DAC periods.

use super::multisine::MultisineDesign;
use crate::csvio::{format, Column};
use crate::error::StudyResult;
use crate::experiment::MAX_DAC_SAMPLES;
use crate::study_err;

/// The CSV `t,u` of `multisine` sampled at `rate` Hz from `start` over `duration` seconds.
///
/// # Errors
///
/// A rate that is not above twice the highest tone's frequency (the DAC could not reproduce
/// the tones) or that gives more than [`MAX_DAC_SAMPLES`] samples (the message names
/// `[design] dac_rate`, which `--dac-rate` replaces).
pub fn dac_samples(
    multisine: &MultisineDesign,
    rate: f64,
    start: f64,
    duration: f64,
) -> StudyResult<String> {
    let fmax = multisine.frequencies.iter().copied().fold(0.0, f64::max);
    if !(rate.is_finite() && rate > 2.0 * fmax) {
        return Err(study_err!(
            "[design] dac_rate: expected a rate above twice the highest tone, {} Hz, found {rate}",
            2.0 * fmax
        ));
    }
    let count = (duration * rate).round();
    if !(1.0..=MAX_DAC_SAMPLES).contains(&count) {
        return Err(study_err!(
            "[design] dac_rate: {rate} Hz over the record of {duration} s gives {count} samples; expected 1 to {MAX_DAC_SAMPLES:e}"
        ));
    }
    let tones = multisine.tones();
    let t: Vec<f64> = (0..count as usize)
        .map(|m| start + m as f64 / rate)
        .collect();
    let u: Vec<f64> = t
        .iter()
        .map(|&t| {
            tones
                .iter()
                .map(|c| c.amplitude * (std::f64::consts::TAU * c.frequency * t + c.phase).sin())
                .sum()
        })
        .collect();
    Ok(format(&[Column::Real("t", &t), Column::Real("u", &u)]))
}
