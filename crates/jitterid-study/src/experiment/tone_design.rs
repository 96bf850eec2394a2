//! The multisine part of `[design]`: a `multisine` input whose frequencies, amplitudes and
//! phases are free (`band`, `tones`, `power`, `peak`, `phases`, `dac_rate`).
//!
//! The tones are harmonics of `1/(N T)`, so that the input is periodic over the record and
//! its sample sequence loops on a signal generator. Everything that can be judged before a
//! search is judged here, naming its key: a band outside `(0, 1/(2T))` or without harmonics, a
//! power or peak that is not positive, a peak below the power's root mean square (no signal
//! has a crest factor below 1), a DAC rate that cannot reproduce the band.

use super::diagnostics::Source;
use super::raw::RawDesign;
use crate::error::StudyResult;
use jitterid::signal::Tone;
use toml::Spanned;

const S: &str = "design";

/// Largest number of candidate tones of a multisine design (each costs one prediction per
/// step of the search).
pub const MAX_DESIGN_TONES: usize = 64;

/// Number of candidate tones when `[design] tones` is absent (fewer when the band holds
/// fewer harmonics).
pub const DEFAULT_TONES: usize = 8;

/// Largest number of samples a DAC sequence may have.
pub const MAX_DAC_SAMPLES: f64 = 1e7;

/// The validated multisine part of `[design]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ToneDesignSpec {
    /// The band `[fmin, fmax]` (Hz) the tones lie in, `0 < fmin ≤ fmax < 1/(2T)`.
    pub band: (f64, f64),
    /// The number of tones: harmonics of `1/(N T)` log-spaced over the band.
    pub tones: usize,
    /// The total mean power `Σ aᵢ²/2` every design has (`[design] power`, else the file's own
    /// multisine's), `None` under a peak bound alone (the power is then the largest the
    /// bound allows).
    pub power: Option<f64>,
    /// The bound on the peak `max |u(t)|` (`[design] peak`), if any.
    pub peak: Option<f64>,
    /// The DAC rate (Hz) of the written sample sequence (`[design] dac_rate`), if given.
    pub dac_rate: Option<f64>,
    /// What the phases are chosen for (`[design] phases`).
    pub phases: PhaseChoice,
}

/// What a designed multisine's phases are chosen for (`[design] phases`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PhaseChoice {
    /// The criterion, under the constraint (`"criterion"`, the default): the phases are
    /// design variables like the powers, and a peak bound, when given, is what limits the
    /// crest factor.
    #[default]
    Criterion,
    /// The lowest crest factor the clipping algorithm reaches (`"crest"`): a signal
    /// generator's or actuator's range used best, whatever the criterion says of the phases.
    Crest,
}

/// The harmonics `k` of `f0 = 1/(N T)` with `k f0` in `[lo, hi]`: `(first, last)`, empty when
/// `first > last`.
pub fn harmonics_in(band: (f64, f64), f0: f64) -> (u64, u64) {
    let first = ((band.0 / f0) * (1.0 - 1e-12)).ceil().max(1.0) as u64;
    let last = ((band.1 / f0) * (1.0 + 1e-12)).floor() as u64;
    (first, last)
}

/// A positive finite number, when given.
fn positive(cx: &Source, key: &str, v: &Option<Spanned<f64>>) -> StudyResult<Option<f64>> {
    match v {
        None => Ok(None),
        Some(s) if s.get_ref().is_finite() && *s.get_ref() > 0.0 => Ok(Some(*s.get_ref())),
        Some(s) => Err(cx.err(
            S,
            key,
            &s.span(),
            format!("expected a finite number > 0, found {}", s.get_ref()),
        )),
    }
}

/// The multisine part of `[design]`, `None` without `band`. `file_tones` are the file's own
/// multisine's tones (`None` for another input kind), `interval` and `samples` the record
/// every design has, `interval_free` whether `[design] interval` is given.
pub(super) fn parse_tone_design(
    cx: &Source,
    r: &RawDesign,
    file_tones: Option<&[Tone]>,
    interval: f64,
    samples: usize,
    interval_free: bool,
) -> StudyResult<Option<ToneDesignSpec>> {
    let Some(band_value) = &r.band else {
        // Every other multisine key needs the band: name the first one given.
        let stray = [
            ("tones", r.tones.as_ref().map(|v| v.span())),
            ("power", r.power.as_ref().map(|v| v.span())),
            ("peak", r.peak.as_ref().map(|v| v.span())),
            ("dac_rate", r.dac_rate.as_ref().map(|v| v.span())),
            ("phases", r.phases.as_ref().map(|v| v.span())),
        ];
        if let Some((key, Some(span))) = stray.into_iter().find(|(_, s)| s.is_some()) {
            return Err(cx.err(
                S,
                key,
                &span,
                "is a key of a multisine design; expected band = [fmin, fmax] (Hz) beside it",
            ));
        }
        return Ok(None);
    };
    let span = band_value.span();
    let Some(file_tones) = file_tones else {
        return Err(cx.err(
            S,
            "band",
            &span,
            "is a design variable of a multisine input; expected [input] kind = \"multisine\"",
        ));
    };
    if interval_free {
        return Err(cx.err(
            S,
            "band",
            &span,
            "a multisine design keeps the sampling (its tones are harmonics of 1/(N T)); leave [design] interval out",
        ));
    }
    let nyquist = 0.5 / interval;
    let band = match band_value.get_ref().as_slice() {
        &[lo, hi] if lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi && hi < nyquist => {
            (lo, hi)
        }
        other => {
            return Err(cx.err(
                S,
                "band",
                &span,
                format!(
                    "expected [fmin, fmax] (Hz) with 0 < fmin <= fmax < {nyquist} (the Nyquist frequency 1/(2T)), found {other:?}"
                ),
            ))
        }
    };
    let f0 = 1.0 / (samples as f64 * interval);
    let (first, last) = harmonics_in(band, f0);
    let available = last.saturating_sub(first) + u64::from(last >= first);
    if available == 0 {
        return Err(cx.err(
            S,
            "band",
            &span,
            format!(
                "the band [{}, {}] Hz holds no harmonic of 1/(N T) = {f0} Hz; expected a wider band or a longer record",
                band.0, band.1
            ),
        ));
    }
    let tones = match &r.tones {
        None => (DEFAULT_TONES as u64).min(available) as usize,
        Some(t) => {
            let k = *t.get_ref();
            if !(1..=MAX_DESIGN_TONES as i64).contains(&k) {
                return Err(cx.err(
                    S,
                    "tones",
                    &t.span(),
                    format!("expected a number of tones in [1, {MAX_DESIGN_TONES}], found {k}"),
                ));
            }
            if k as u64 > available {
                return Err(cx.err(
                    S,
                    "tones",
                    &t.span(),
                    format!(
                        "the band [{}, {}] Hz holds only {available} harmonics of 1/(N T) = {f0} Hz; expected at most that many tones",
                        band.0, band.1
                    ),
                ));
            }
            k as usize
        }
    };
    let power = positive(cx, "power", &r.power)?;
    let peak = positive(cx, "peak", &r.peak)?;
    let own_power: f64 = file_tones.iter().map(|t| t.amplitude.powi(2) / 2.0).sum();
    let power = match (power, peak) {
        (Some(p), _) => Some(p),
        (None, Some(_)) => None,
        (None, None) if own_power > 0.0 => Some(own_power),
        (None, None) => return Err(cx.err(
            S,
            "band",
            &span,
            "the file's multisine has no power (all amplitudes 0); expected [design] power or peak",
        )),
    };
    if let (Some(p), Some(a), Some(v)) = (power, peak, &r.peak) {
        // max |u| ≥ rms = √P for every signal: a crest factor below 1 does not exist.
        if a < p.sqrt() {
            return Err(cx.err(
                S,
                "peak",
                &v.span(),
                format!(
                    "cannot hold the power {p}: a peak of {a} is below its root mean square {} (no signal has a crest factor below 1)",
                    p.sqrt()
                ),
            ));
        }
    }
    let dac_rate = positive(cx, "dac_rate", &r.dac_rate)?;
    if let (Some(fs), Some(v)) = (dac_rate, &r.dac_rate) {
        if fs <= 2.0 * band.1 {
            return Err(cx.err(
                S,
                "dac_rate",
                &v.span(),
                format!(
                    "expected a rate above twice the band's top, {} Hz, found {fs}",
                    2.0 * band.1
                ),
            ));
        }
        if fs * samples as f64 * interval > MAX_DAC_SAMPLES {
            return Err(cx.err(
                S,
                "dac_rate",
                &v.span(),
                format!(
                    "{fs} Hz over the record of {} s gives more than {MAX_DAC_SAMPLES:e} samples",
                    samples as f64 * interval
                ),
            ));
        }
    }
    let phases = match &r.phases {
        None => PhaseChoice::default(),
        Some(v) => match v.get_ref().as_str() {
            "criterion" => PhaseChoice::Criterion,
            "crest" => PhaseChoice::Crest,
            other => {
                return Err(cx.err(
                    S,
                    "phases",
                    &v.span(),
                    format!("expected \"criterion\" or \"crest\", found {other:?}"),
                ))
            }
        },
    };
    Ok(Some(ToneDesignSpec {
        band,
        tones,
        power,
        peak,
        dac_rate,
        phases,
    }))
}
