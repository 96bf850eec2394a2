//! Which derived quantities a design report gives: `[design] derived` (`jitterid design
//! --derived`, `jitterid.design(derived=…)`), each entry one quantity or, `pole_frequency`,
//! the natural frequency of every pole. Without the key the report gives what it always has
//! ([`derived_stds`](super::derived_stds)), so existing reports do not change.

use super::derived::{derived_std, pole_frequencies, Derived};
use super::predict::Prediction;
use super::report::PredictedStd;
use crate::error::StudyResult;
use crate::fit::Structure;
use crate::study_err;
use std::fmt;

/// One entry of `[design] derived`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DerivedRequest {
    /// One quantity.
    One(Derived),
    /// `pole_frequency`: the natural frequency of every pole (complex pairs once), in
    /// increasing order, `pole1.frequency`, `pole2.frequency`, ….
    PoleFrequencies,
}

/// What an entry may be, for messages.
pub const DERIVED_EXPECTED: &str = "static_gain, pole_frequency (every pole), poleK.frequency (K = 1, 2, …, in increasing frequency), gain@F (|G| at F Hz) or jitter.sigma";

impl DerivedRequest {
    /// `static_gain`, `pole_frequency`, `poleK.frequency` (`K ≥ 1`), `gain@F` (or `|G|@FHz`,
    /// the name it is reported under; `F ≥ 0` Hz) or `jitter.sigma`.
    ///
    /// # Errors
    ///
    /// The text that was not understood, with what was expected.
    pub fn parse(text: &str) -> Result<Self, String> {
        let t = text.trim();
        let bad = || format!("unknown derived quantity \"{text}\"; expected {DERIVED_EXPECTED}");
        match t {
            "static_gain" => return Ok(Self::One(Derived::StaticGain)),
            "jitter.sigma" => return Ok(Self::One(Derived::JitterStd)),
            "pole_frequency" => return Ok(Self::PoleFrequencies),
            _ => {}
        }
        if let Some(k) = t
            .strip_prefix("pole")
            .and_then(|r| r.strip_suffix(".frequency"))
        {
            return match k.parse::<usize>() {
                Ok(k) if k >= 1 => Ok(Self::One(Derived::PoleFrequency(k - 1))),
                _ => Err(format!(
                    "\"{text}\": expected poleK.frequency with K a whole number from 1"
                )),
            };
        }
        let frequency = t
            .strip_prefix("gain@")
            .or_else(|| t.strip_prefix("|G|@").map(|r| r.trim_end_matches("Hz")));
        if let Some(f) = frequency {
            return match f.trim().parse::<f64>() {
                Ok(f) if f.is_finite() && f >= 0.0 => Ok(Self::One(Derived::Magnitude(f))),
                _ => Err(format!(
                    "\"{text}\": expected gain@F with F a finite frequency >= 0 Hz"
                )),
            };
        }
        Err(bad())
    }

    /// The quantities this entry stands for at `model`.
    fn expand(&self, model: &Structure) -> Vec<Derived> {
        match *self {
            Self::One(q) => vec![q],
            Self::PoleFrequencies => (0..pole_frequencies(model).map_or(0, |f| f.len()))
                .map(Derived::PoleFrequency)
                .collect(),
        }
    }
}

impl fmt::Display for DerivedRequest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::One(Derived::Magnitude(hz)) => write!(f, "gain@{hz}"),
            Self::One(q) => f.write_str(&q.name()),
            Self::PoleFrequencies => f.write_str("pole_frequency"),
        }
    }
}

/// The quantities of `requests` at `model`, in order, each once.
fn quantities(requests: &[DerivedRequest], model: &Structure) -> Vec<Derived> {
    let mut out: Vec<Derived> = Vec::new();
    for q in requests.iter().flat_map(|r| r.expand(model)) {
        if !out.contains(&q) {
            out.push(q);
        }
    }
    out
}

/// Checks that every quantity of `requests` is defined at `model` (the prior model), before
/// a search spends its time: `pole_frequency` needs a pole, the others a value.
///
/// # Errors
///
/// The first entry that is not defined, naming `[design] derived` (in `file`).
pub(crate) fn check_defined(
    file: &str,
    requests: &[DerivedRequest],
    model: &Structure,
) -> StudyResult<()> {
    for r in requests {
        let qs = r.expand(model);
        if qs.is_empty() {
            return Err(study_err!(
                "{file}: [design] derived: \"{r}\" is not defined at the prior model: it needs a system with a transfer function and at least one pole"
            ));
        }
        for q in qs {
            if q.value(model).is_none() {
                return Err(study_err!(
                    "{file}: [design] derived: \"{r}\" is not defined at the prior model: {}",
                    match q {
                        Derived::PoleFrequency(k) => format!(
                            "it needs a system with a transfer function and at least {} poles or complex pairs",
                            k + 1
                        ),
                        Derived::JitterStd => "the jitter has no finite standard deviation".into(),
                        _ => "it needs a system with a transfer function and a finite static gain".into(),
                    }
                ));
            }
        }
    }
    Ok(())
}

/// The predicted standard deviation of each quantity of `requests` at `p`, named; `None`
/// where it cannot be computed (a quantity that [`design`](super::design()) checked at the
/// prior model has one there, but a finite difference can still fail at another design).
pub fn requested_stds(p: &Prediction, requests: &[DerivedRequest]) -> Vec<PredictedStd> {
    quantities(requests, p.model())
        .into_iter()
        .map(|q| PredictedStd {
            name: q.name(),
            std: derived_std(p, q).ok(),
        })
        .collect()
}
