//! `[design]`: the experiment's free design variables and their ranges, for `jitterid design`.
//!
//! The section names what the user may still choose before the experiment is run (the random
//! binary input's mean dwell and levels, the sampling interval) and how a design is judged. Ranges are
//! checked here against what the rest of the file fixes, so that a range without one feasible
//! point is refused at the door, naming its key, rather than found empty by the optimiser.

use super::diagnostics::Source;
use super::range::{self as limits, MAX_INTERVAL, MIN_INTERVAL};
use super::raw::RawDesign;
use super::sampling::MAX_SAMPLES;
use super::tone_design::{parse_tone_design, ToneDesignSpec};
use crate::design::DerivedRequest;
use crate::error::StudyResult;
use jitterid::signal::{SampleGrid, MAX_SWITCHES};
use std::fmt;
use toml::Spanned;

const S: &str = "design";

/// Largest number of input realisations a prediction averages over.
pub const MAX_DRAWS: usize = 1024;

/// Largest number of grid points per free variable of the design search.
pub const MAX_GRID: usize = 64;

/// What a design is judged by: a scalar function of the predicted covariance `C` of the
/// estimated parameters, smaller is better.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DesignCriterion {
    /// D-optimality, `log det C`: the volume of the confidence ellipsoid, invariant to the
    /// parameters' units.
    D,
    /// A-optimality, `trace C`: the summed variances (depends on the parameters' units).
    A,
    /// The variance of one named parameter (as the fit names it, `p1.re`, `jitter.a`).
    Param(String),
}

impl DesignCriterion {
    /// `d`, `a` or `param:NAME`.
    ///
    /// # Errors
    ///
    /// The text that was not understood, with what was expected.
    pub fn parse(text: &str) -> Result<Self, String> {
        match text.trim() {
            "d" | "D" => Ok(Self::D),
            "a" | "A" => Ok(Self::A),
            t => match t.strip_prefix("param:").map(str::trim) {
                Some(name) if !name.is_empty() => Ok(Self::Param(name.to_string())),
                _ => Err(format!(
                    "expected \"d\", \"a\" or \"param:NAME\" (a parameter's name), found \"{text}\""
                )),
            },
        }
    }
}

impl fmt::Display for DesignCriterion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::D => f.write_str("d"),
            Self::A => f.write_str("a"),
            Self::Param(name) => write!(f, "param:{name}"),
        }
    }
}

/// The estimator whose precision a design is predicted for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DesignEstimator {
    /// Bias-compensated least squares: the sandwich covariance.
    Bcls,
    /// Exact maximum likelihood: the inverse exact Fisher information (the Cramér–Rao bound).
    Ml,
}

impl DesignEstimator {
    /// The name in files and on the command line (`bcls`, `ml`).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Bcls => "bcls",
            Self::Ml => "ml",
        }
    }
}

/// What stays fixed when the sampling interval `T` is a design variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hold {
    /// The number of samples `N`: the record's duration `N T` changes with `T`.
    Samples,
    /// The record's duration `N T` (the file's): `N = round(duration / T)`.
    Duration,
}

/// The record a design may use: a fixed duration `N T` (then `N = round(duration / T)`) or a
/// fixed number of samples `N`, whatever `T` the design chooses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Budget {
    /// The record's duration (s).
    Duration(f64),
    /// The number of samples.
    Samples(usize),
}

impl Budget {
    /// The number of samples at sampling interval `interval`.
    pub fn samples_at(&self, interval: f64) -> usize {
        match *self {
            Budget::Duration(d) => ((d / interval).round() as usize).max(1),
            Budget::Samples(n) => n,
        }
    }
}

/// The edit of the command line's `--budget duration=SECONDS` or `--budget samples=N`: the
/// `[design]` key of that name, named `--budget …` in messages, so that a budget is checked
/// exactly as the key written in the file is.
///
/// # Errors
///
/// Text that is not `duration=NUMBER` or `samples=WHOLE NUMBER`.
pub fn budget_edit(text: &str) -> StudyResult<super::Override> {
    let origin = format!("--budget {text}");
    let bad = || {
        crate::study_err!(
            "{origin}: expected duration=SECONDS (the record's duration held) or samples=N (the number of samples held)"
        )
    };
    let (key, value) = text.split_once('=').ok_or_else(bad)?;
    let value = value.trim();
    let value: toml_edit::Value = match key.trim() {
        "duration" => value.parse::<f64>().map_err(|_| bad())?.into(),
        "samples" => value.parse::<i64>().map_err(|_| bad())?.into(),
        _ => return Err(bad()),
    };
    Ok(super::Override::from_source(
        &[S, key.trim()],
        value,
        origin,
    ))
}

/// The edit of the command line's `--dac-rate HZ`: the `[design] dac_rate` key, named
/// `--dac-rate …` in messages, so that the rate is checked exactly as the key written in the
/// file is.
pub fn dac_rate_edit(rate: f64) -> super::Override {
    super::Override::from_source(&[S, "dac_rate"], rate.into(), format!("--dac-rate {rate}"))
}

/// The validated `[design]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSpec {
    /// The random binary input's mean dwell range `[min, max]` (s), when it is free.
    pub mean_dwell: Option<(f64, f64)>,
    /// The random binary input's `low` level's range `[min, max]`, when it is free.
    pub low: Option<(f64, f64)>,
    /// The random binary input's `high` level's range `[min, max]`, when it is free.
    pub high: Option<(f64, f64)>,
    /// The sampling interval's range `[min, max]` (s), when it is free; the part of the range
    /// where the held quantity allows a record (see [`Hold`]).
    pub interval: Option<(f64, f64)>,
    /// How the jitter's spread follows the sampling interval (`jitter_exponent`, `α`): at
    /// interval `T` the jitter is the file's family with standard deviation
    /// `σ₀ (T / T₀)^α`, `σ₀` and `T₀` the file's (0, the default: the jitter does not depend
    /// on `T`).
    pub jitter_exponent: f64,
    /// What stays fixed when the interval changes.
    pub hold: Hold,
    /// The record every design has: `[design] duration` or `samples` when given (the budget),
    /// else the file's `N` or `N T`, as `hold` says.
    pub budget: Budget,
    /// The key that gave the budget (`duration`, `samples`), `None` for the file's record.
    pub budget_key: Option<&'static str>,
    /// The criterion (the command line's `--criterion` replaces it).
    pub criterion: DesignCriterion,
    /// The estimator whose precision is predicted.
    pub estimator: DesignEstimator,
    /// Input realisations averaged over for a random input.
    pub draws: usize,
    /// Grid points per free variable before the refinement.
    pub grid: usize,
    /// Master seed of the input realisations (realisation `r` is Monte Carlo run `r`'s input).
    pub seed: u64,
    /// The prior spread of a robust design (`prior_spread`, `prior_jitter_spread`,
    /// `prior_draws`), `None` for a design at the prior's values alone.
    pub prior: Option<PriorSpread>,
    /// The derived quantities reported (`derived`), `None` for the default (the static gain,
    /// and the jitter's σ when it is estimated).
    pub derived: Option<Vec<DerivedRequest>>,
    /// A multisine input's free tones (`band`, `tones`, `power`, `peak`, `dac_rate`), `None`
    /// when its frequencies, amplitudes and phases are the file's.
    pub multisine: Option<ToneDesignSpec>,
}

/// Largest number of prior draws a robust design averages over.
pub const MAX_PRIOR_DRAWS: usize = 256;

/// The spread of the prior a robust design averages its criterion over: each estimated
/// system parameter `θ_j` is drawn as `θ_j (1 + system z_j)` and the jitter's standard
/// deviation as `σ (1 + jitter z)`, with `z` standard normal cut at ±3, independently for each
/// of `draws` prior draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PriorSpread {
    /// Relative standard deviation of each estimated system parameter.
    pub system: f64,
    /// Relative standard deviation of the jitter's standard deviation.
    pub jitter: f64,
    /// Prior draws averaged over.
    pub draws: usize,
}

/// A relative spread in `[0, 1/3)` (so that a draw cut at three spreads keeps its sign), 0
/// when absent.
fn spread(cx: &Source, key: &str, v: &Option<Spanned<f64>>) -> StudyResult<f64> {
    match v {
        None => Ok(0.0),
        Some(s) if (0.0..1.0 / 3.0).contains(s.get_ref()) => Ok(*s.get_ref()),
        Some(s) => Err(cx.err(
            S,
            key,
            &s.span(),
            format!(
                "expected a relative spread in [0, 1/3) (a draw is cut at three spreads and must keep its sign), found {}",
                s.get_ref()
            ),
        )),
    }
}

/// The robust design's prior: `None` when both spreads are 0 (or absent).
fn parse_prior(cx: &Source, r: &RawDesign) -> StudyResult<Option<PriorSpread>> {
    let system = spread(cx, "prior_spread", &r.prior_spread)?;
    let jitter = spread(cx, "prior_jitter_spread", &r.prior_jitter_spread)?;
    let draws = whole(
        cx,
        "prior_draws",
        &r.prior_draws,
        (1, MAX_PRIOR_DRAWS as i64),
        8,
    )? as usize;
    if system == 0.0 && jitter == 0.0 {
        if let Some(d) = &r.prior_draws {
            return Err(cx.err(
                S,
                "prior_draws",
                &d.span(),
                "a robust design's prior draws need a spread; expected prior_spread or prior_jitter_spread above 0",
            ));
        }
        return Ok(None);
    }
    Ok(Some(PriorSpread {
        system,
        jitter,
        draws,
    }))
}

/// `[min, max]` of two finite numbers with `0 < min ≤ max`.
fn range(cx: &Source, key: &str, v: &Spanned<Vec<f64>>) -> StudyResult<(f64, f64)> {
    match v.get_ref().as_slice() {
        &[lo, hi] if lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi => Ok((lo, hi)),
        other => Err(cx.err(
            S,
            key,
            &v.span(),
            format!(
                "expected [min, max] of two finite numbers with 0 < min <= max, found {other:?}"
            ),
        )),
    }
}

/// `[min, max]` of a random binary input's level: two finite numbers with `min ≤ max`, each
/// within the magnitude the input's own `low` and `high` may have ([`limits::level`]). Unlike
/// a time scale, a level may be 0 or negative.
fn level_range(cx: &Source, key: &str, v: &Spanned<Vec<f64>>) -> StudyResult<(f64, f64)> {
    let bad = |why: String| cx.err(S, key, &v.span(), why);
    match v.get_ref().as_slice() {
        &[lo, hi] if lo.is_finite() && hi.is_finite() && lo <= hi => {
            limits::level(lo).map_err(|m| bad(format!("min: {m}")))?;
            limits::level(hi).map_err(|m| bad(format!("max: {m}")))?;
            Ok((lo, hi))
        }
        other => Err(bad(format!(
            "expected [min, max] of two finite levels with min <= max, found {other:?}"
        ))),
    }
}

/// A free level of the random binary input (`[design] low` or `high`), refused for any other
/// input since only a random binary input has the keys it edits.
fn free_level(
    cx: &Source,
    key: &str,
    v: &Option<Spanned<Vec<f64>>>,
    input_kind: Option<&str>,
) -> StudyResult<Option<(f64, f64)>> {
    let Some(v) = v else {
        return Ok(None);
    };
    if input_kind != Some("random-binary") {
        return Err(cx.err(
            S,
            key,
            &v.span(),
            "is a design variable of a random binary input; expected [input] kind = \"random-binary\"",
        ));
    }
    level_range(cx, key, v).map(Some)
}

/// A whole number in `[lo, hi]`, or `default` when absent.
fn whole(
    cx: &Source,
    key: &str,
    v: &Option<Spanned<i64>>,
    (lo, hi): (i64, i64),
    default: i64,
) -> StudyResult<i64> {
    match v {
        None => Ok(default),
        Some(s) if (lo..=hi).contains(s.get_ref()) => Ok(*s.get_ref()),
        Some(s) => Err(cx.err(
            S,
            key,
            &s.span(),
            format!(
                "expected a whole number in [{lo}, {hi}], found {}",
                s.get_ref()
            ),
        )),
    }
}

/// The budget: `[design] duration` or `samples` (not both), each a record that can be
/// sampled; without either, the file's `N`. Returns the key that gave it.
fn parse_budget(
    cx: &Source,
    r: &RawDesign,
    grid: &SampleGrid,
) -> StudyResult<(Budget, Option<&'static str>)> {
    let unmet = |key: &str, span: std::ops::Range<usize>, why: String| {
        cx.err(S, key, &span, format!("a budget that cannot be met: {why}"))
    };
    match (&r.duration, &r.samples) {
        (Some(_), Some(k)) => Err(unmet(
            "samples",
            k.span(),
            "give either duration or samples, not both".into(),
        )),
        (Some(d), None) => {
            let d_value = *d.get_ref();
            let longest = MAX_INTERVAL * MAX_SAMPLES as f64;
            if !(d_value.is_finite() && (MIN_INTERVAL..=longest).contains(&d_value)) {
                return Err(unmet(
                    "duration",
                    d.span(),
                    format!("expected a record duration in [{MIN_INTERVAL:e}, {longest:e}] s, found {d_value}"),
                ));
            }
            if r.interval.is_none() {
                // T is fixed: the duration must hold a whole number of its intervals.
                let t = grid.interval();
                let k = (d_value / t).round();
                if !(1.0..=MAX_SAMPLES as f64).contains(&k) {
                    return Err(unmet(
                        "duration",
                        d.span(),
                        format!("{d_value} s holds {k} samples of the interval {t} s; expected 1 to {MAX_SAMPLES}"),
                    ));
                }
            }
            Ok((Budget::Duration(d_value), Some("duration")))
        }
        (None, Some(k)) => {
            let n = *k.get_ref();
            if !(1..=MAX_SAMPLES).contains(&n) {
                return Err(unmet(
                    "samples",
                    k.span(),
                    format!("expected a number of samples in [1, {MAX_SAMPLES}], found {n}"),
                ));
            }
            Ok((Budget::Samples(n as usize), Some("samples")))
        }
        (None, None) => Ok((Budget::Samples(grid.len()), None)),
    }
}

/// The `[design]` section, checked against the file's grid, input kind (`input_kind`, as
/// written) and input history: every range must hold a feasible point.
pub(super) fn parse_design(
    cx: &Source,
    r: &RawDesign,
    input_kind: Option<&str>,
    file_tones: Option<&[jitterid::signal::Tone]>,
    grid: &SampleGrid,
    history: f64,
) -> StudyResult<DesignSpec> {
    let mean_dwell = match &r.mean_dwell {
        Some(v) => {
            if input_kind != Some("random-binary") {
                return Err(cx.err(
                    S,
                    "mean_dwell",
                    &v.span(),
                    "is a design variable of a random binary input; expected [input] kind = \"random-binary\"",
                ));
            }
            Some((v, range(cx, "mean_dwell", v)?))
        }
        None => None,
    };
    let low = free_level(cx, "low", &r.low, input_kind)?;
    let high = free_level(cx, "high", &r.high, input_kind)?;
    let n = grid.len() as f64;
    let (budget, budget_key) = parse_budget(cx, r, grid)?;
    let hold = match (&r.hold, budget) {
        (None, Budget::Duration(_)) => Hold::Duration,
        (None, Budget::Samples(_)) => Hold::Samples,
        (Some(h), _) => {
            let hold = match h.get_ref().as_str() {
                "samples" => Hold::Samples,
                "duration" => Hold::Duration,
                other => {
                    return Err(cx.err(
                        S,
                        "hold",
                        &h.span(),
                        format!("expected \"samples\" or \"duration\", found \"{other}\""),
                    ))
                }
            };
            match (hold, budget_key) {
                (Hold::Samples, Some("duration")) | (Hold::Duration, Some("samples")) => {
                    return Err(cx.err(
                        S,
                        "hold",
                        &h.span(),
                        format!(
                            "\"{}\" contradicts the budget [design] {}; leave hold out (the budget says what is held)",
                            h.get_ref(),
                            budget_key.unwrap_or_default()
                        ),
                    ))
                }
                _ => {}
            }
            hold
        }
    };
    // Without a budget, `hold` says which of the file's N and N T is kept.
    let budget = match (budget_key, hold) {
        (None, Hold::Duration) => Budget::Duration(n * grid.interval()),
        _ => budget,
    };
    let interval = match &r.interval {
        Some(v) => {
            let (lo, hi) = range(cx, "interval", v)?;
            // The feasible part: a representable interval, and under a held duration a whole
            // number of samples in [1, MAX_SAMPLES].
            let (mut a, mut b) = (lo.max(MIN_INTERVAL), hi.min(MAX_INTERVAL));
            if let Budget::Duration(duration) = budget {
                a = a.max(duration / MAX_SAMPLES as f64);
                b = b.min(duration);
            }
            if !(a <= b) {
                if let (Some(key), Some(span)) = (budget_key, r.duration.as_ref().map(|d| d.span()))
                {
                    return Err(cx.err(
                        S,
                        key,
                        &span,
                        format!("a budget that cannot be met: no interval in [{lo}, {hi}] s gives a record of 1 to {MAX_SAMPLES} samples in this duration"),
                    ));
                }
                return Err(cx.err(
                    S,
                    "interval",
                    &v.span(),
                    format!(
                        "no feasible interval in [{lo}, {hi}] s: it must lie in [{MIN_INTERVAL:e}, {MAX_INTERVAL:e}] s{}",
                        if let Budget::Duration(duration) = budget {
                            format!(
                                " and, with the duration {duration} s held, give 1 to {MAX_SAMPLES} samples"
                            )
                        } else {
                            String::new()
                        }
                    ),
                ));
            }
            Some((a, b))
        }
        None => None,
    };
    if let Some((v, (_, hi))) = &mean_dwell {
        // The shortest record the design allows, with the longest dwell: the fewest switches.
        let shortest = match (interval, budget) {
            (_, Budget::Duration(d)) => d,
            (Some((t, _)), Budget::Samples(k)) => k as f64 * t,
            (None, Budget::Samples(k)) => k as f64 * grid.interval(),
        };
        let switches = (shortest + history) / hi;
        if !(switches <= MAX_SWITCHES) {
            return Err(cx.err(
                S,
                "mean_dwell",
                &v.span(),
                format!(
                    "no feasible mean dwell: even the longest, {hi} s, gives {switches:e} expected switches over the input's span, more than {MAX_SWITCHES:e}"
                ),
            ));
        }
    }
    let mean_dwell = mean_dwell.map(|(_, r)| r);
    let multisine = parse_tone_design(
        cx,
        r,
        file_tones,
        grid.interval(),
        budget.samples_at(grid.interval()),
        r.interval.is_some(),
    )?;
    if mean_dwell.is_none()
        && low.is_none()
        && high.is_none()
        && interval.is_none()
        && multisine.is_none()
    {
        return Err(cx.err_section(
            S,
            "mean_dwell",
            "the section names no free variable; expected mean_dwell = [min, max], low = [min, max], high = [min, max], interval = [min, max] or band = [fmin, fmax]",
        ));
    }
    let criterion = match &r.criterion {
        None => DesignCriterion::D,
        Some(c) => {
            DesignCriterion::parse(c.get_ref()).map_err(|e| cx.err(S, "criterion", &c.span(), e))?
        }
    };
    let estimator = match &r.estimator {
        None => DesignEstimator::Bcls,
        Some(e) => match e.get_ref().as_str() {
            "bcls" => DesignEstimator::Bcls,
            "ml" => DesignEstimator::Ml,
            other => {
                return Err(cx.err(
                    S,
                    "estimator",
                    &e.span(),
                    format!("expected \"bcls\" or \"ml\", found \"{other}\""),
                ))
            }
        },
    };
    let draws = whole(cx, "draws", &r.draws, (1, MAX_DRAWS as i64), 16)? as usize;
    let points = whole(cx, "grid", &r.grid, (3, MAX_GRID as i64), 9)? as usize;
    let seed = whole(
        cx,
        "seed",
        &r.seed,
        (0, i64::MAX),
        crate::montecarlo::DEFAULT_SEED as i64,
    )? as u64;
    let prior = parse_prior(cx, r)?;
    let jitter_exponent = parse_jitter_exponent(cx, r, prior.as_ref())?;
    let derived = parse_derived(cx, r)?;
    Ok(DesignSpec {
        mean_dwell,
        low,
        high,
        interval,
        jitter_exponent,
        hold,
        budget,
        budget_key,
        criterion,
        estimator,
        draws,
        grid: points,
        seed,
        prior,
        derived,
        multisine,
    })
}

/// Largest `[design] jitter_exponent`: a spread growing faster than `T²` is no timing
/// mechanism (a clock's jitter is `T`-independent, a drifting oscillator's accumulates as
/// `√T`, a rate-proportional one as `T`).
pub const MAX_JITTER_EXPONENT: f64 = 2.0;

/// `[design] jitter_exponent`: a number in `[0, MAX_JITTER_EXPONENT]`, meaningful only with
/// the interval free and not beside a prior spread of the jitter (whose draws are spreads at
/// the file's interval).
fn parse_jitter_exponent(
    cx: &Source,
    r: &RawDesign,
    prior: Option<&PriorSpread>,
) -> StudyResult<f64> {
    let Some(v) = &r.jitter_exponent else {
        return Ok(0.0);
    };
    let alpha = *v.get_ref();
    if !(alpha.is_finite() && (0.0..=MAX_JITTER_EXPONENT).contains(&alpha)) {
        return Err(cx.err(
            S,
            "jitter_exponent",
            &v.span(),
            format!(
                "expected an exponent in [0, {MAX_JITTER_EXPONENT}] (the jitter's σ at T is σ₀ (T/T₀)^α), found {alpha}"
            ),
        ));
    }
    if r.interval.is_none() {
        return Err(cx.err(
            S,
            "jitter_exponent",
            &v.span(),
            "says how the jitter follows the sampling interval; expected interval = [min, max] beside it",
        ));
    }
    if prior.is_some_and(|p| p.jitter > 0.0) {
        return Err(cx.err(
            S,
            "jitter_exponent",
            &v.span(),
            "cannot be combined with prior_jitter_spread (its draws are spreads at the file's interval); leave one out",
        ));
    }
    Ok(alpha)
}

/// `[design] derived`: each entry a quantity [`DerivedRequest::parse`] knows.
fn parse_derived(cx: &Source, r: &RawDesign) -> StudyResult<Option<Vec<DerivedRequest>>> {
    let Some(list) = &r.derived else {
        return Ok(None);
    };
    list.get_ref()
        .iter()
        .map(|t| DerivedRequest::parse(t).map_err(|e| cx.err(S, "derived", &list.span(), e)))
        .collect::<StudyResult<Vec<_>>>()
        .map(Some)
}

/// The edit that sets `[design] derived` to `names` (the command line's `--derived`, Python's
/// `derived=`), named `origin` in messages, so that the list is checked as the key written in
/// the file is.
pub fn derived_edit(names: &[String], origin: String) -> super::Override {
    let value: toml_edit::Value = names
        .iter()
        .map(String::as_str)
        .collect::<toml_edit::Array>()
        .into();
    super::Override::from_source(&[S, "derived"], value, origin)
}

#[cfg(test)]
mod tests {
    use super::super::raw::{docs_table_keys, RawDesign};

    /// The `[design]` table of `docs/experiments.md` lists exactly the keys the reader takes,
    /// in order: the reference cannot drift from the reader.
    #[test]
    fn the_docs_design_table_lists_the_reader_s_keys() {
        assert_eq!(docs_table_keys("### `[design]`"), RawDesign::KEYS);
    }

    /// Criteria read back as written.
    #[test]
    fn criteria_parse_and_print_alike() {
        use super::DesignCriterion;
        for text in ["d", "a", "param:pole0.re"] {
            assert_eq!(DesignCriterion::parse(text).unwrap().to_string(), text);
        }
        for bad in ["", "e", "param:", "param: "] {
            assert!(DesignCriterion::parse(bad).is_err(), "{bad}");
        }
    }
}
