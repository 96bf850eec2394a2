//! Model-order and jitter-family selection.
//!
//! [`select`] fits every candidate of a [`SelectionGrid`] — a number of zeros and poles (a
//! transfer function `N(s)/A(s)`, `A` monic) and a jitter family taken from a
//! [`JitterRegistry`] by name, `"none"` included — with BCLS, each started by the data-driven
//! initializer ([`jitterid_estimate::initial_model`]) with the jitter at a standard deviation of
//! `f · T` through [`JitterRegistry::from_std_dev`], once for every fraction `f` of
//! [`SelectionOptions::jitter_fractions`], keeping the lowest-cost converged fit. Several jitter
//! starts because the BCLS cost is not convex in the jitter's scale for families whose `γ(f)`
//! oscillates (periodic: `J₀`, two-point: `cos`): from one start the fit of the true family can
//! end in a local minimum with the scale far off, and a wrong family would then win.
//!
//! Two stages rank the candidates.
//!
//! 1. **BCLS screen.** Every candidate gets the BIC of a Gaussian quasi-likelihood of the
//!    frequency-domain residuals: with independent samples the residual `D(f) = Y(f) − μ_Y(f)`
//!    has the same variance `Σ_k λ_k` at every frequency, even though the jittered samples are
//!    heteroscedastic in time, so one common variance is the right nuisance parameter and
//!    `N ln(cost) + k ln N` (with `k` the number of estimated parameters: gain, numerator and
//!    denominator coefficients, the jitter's free parameters) is, up to a constant shared by
//!    all candidates, `−2 log L + k ln N`. It picks the order well (the order shapes the first
//!    moment) but not always the family: families whose `γ(f)` differ only where the signal
//!    has little power give nearly the same first moment.
//! 2. **Exact-likelihood final** ([`SelectionOptions::refine_by_likelihood`]). Within each
//!    family the candidate the screen ranks first is refitted by exact maximum likelihood
//!    ([`ExactMl`](crate::ExactMl), the noise level estimated), started at its BCLS
//!    estimate; so is every jittered family's candidate at the screen winner's order, started
//!    at the winner's system with the family's jitter at the winner's standard deviation
//!    (families of equal spread have nearly the same first moment, so this start does not
//!    depend on the family's own BCLS fits, which can end in a wrong local minimum of the
//!    jitter's scale). These finalists are ranked by Schwarz's BIC `−2 log L̂ + k ln N` of the
//!    exact likelihood of independent samples (`k` now counts `σ_v` too). That likelihood
//!    sees the jitter's whole law through the spread of `s(t_k + τ)`, not only `γ(f)`.
//!
//! The ranking: finalists whose likelihood fit converged, by that BIC; then the other
//! converged candidates by the screen's BIC, those with a pole beyond the sampling's reach
//! ([`FailureKind::PoleBeyondSampling`], never finalists) after the rest; then the failed ones,
//! with their reason.
//! The two BICs are never compared with each other.

use jitterid_jitter::{registry::JitterRegistry, AnyJitter};
use jitterid_signal::forms::TfForm;
use jitterid_signal::registry::{KindReader, SignalRegistry, SpecTable};
use jitterid_signal::{AnySignal, Input, LtiResponse, Signal, TransferFunction};
use rayon::prelude::*;
use serde_json::json;

use crate::validation::{fit_percent, on_record};
use jitterid_estimate::{
    fit, initialize, offset_start, Bcls, FitOptions, InitOptions, ModelStructure, Record,
};

mod channels;
mod likelihood;

pub use channels::select_channels;

/// A rectangular grid of candidate model orders and jitter families.
#[derive(Debug, Clone, PartialEq)]
pub struct SelectionGrid {
    /// Inclusive range of the number of poles.
    pub poles: (usize, usize),
    /// Inclusive range of the number of zeros.
    pub zeros: (usize, usize),
    /// Jitter family names, as the registry knows them (`"none"` for no jitter).
    pub families: Vec<String>,
}

/// The candidate orders of one input of a multi-input system: with one per input, the
/// candidates of [`select_channels`] are every combination of one order per input (the
/// grid's `poles` and `zeros` are then not read), each fitted jointly as a superposition.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelOrders {
    /// The input's name (the prefix of its channel's parameters).
    pub input: String,
    /// Its candidate orders, `(poles, zeros)`.
    pub orders: Vec<(usize, usize)>,
}

/// Settings of [`select`].
#[derive(Debug, Clone, PartialEq)]
pub struct SelectionOptions {
    /// Starting jitter standard deviations as fractions of the sampling interval `T`: every
    /// jittered candidate is fitted from each, and the lowest-cost converged fit is kept.
    pub jitter_fractions: Vec<f64>,
    /// Whether the best candidate of each family is refitted by exact maximum likelihood and
    /// the finalists ranked by the likelihood's BIC (default true); false ranks by the BCLS
    /// screen alone.
    pub refine_by_likelihood: bool,
    /// An input delay (dead time, s, `≥ 0`) every candidate carries as its parameter `delay`,
    /// estimated with the system from this start (the initializer fits the response to the
    /// input delayed by it); `None`: no delay. A known delay is not a parameter: pass the
    /// input delayed by it instead.
    pub delay: Option<f64>,
    /// Whether every candidate carries the free response from an unknown state at the record's
    /// first instant (parameters `initial.0 … initial.{n−1}` for `n` poles, started at 0).
    pub initial_state: bool,
    /// The record's output offset `(y₀, estimated)` every candidate carries (the keys `offset`
    /// and `estimate_offset` of its spec table): a known `y₀` is part of each candidate's model,
    /// an estimated one is the parameter `offset`, started at `mean(y) − mean(m_k)` for the
    /// candidate's initial system ([`offset_start`]). Without
    /// it a record around an operating point would be ranked by how well each order's DC gain
    /// and slow poles imitate a constant. `None`: no offset.
    pub offset: Option<(f64, bool)>,
    /// The input's level `(u₀, estimated)` every candidate carries (the keys `level` and
    /// `estimate_level` of its spec table, [`jitterid_signal::InputLevel`]): a known `u₀` is
    /// part of each candidate's model, an estimated one the parameter `level`, started at the
    /// given `u₀`. The initializer fits each candidate's response to the deviation `u − u₀`.
    /// `None`: no level.
    pub level: Option<(f64, bool)>,
}

impl Default for SelectionOptions {
    fn default() -> Self {
        Self {
            jitter_fractions: vec![0.1, 0.25, 0.4],
            refine_by_likelihood: true,
            delay: None,
            initial_state: false,
            offset: None,
            level: None,
        }
    }
}

/// One fitted (or failed) candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Number of poles (of a multi-input candidate: of all its channels).
    pub poles: usize,
    /// Number of zeros (of a multi-input candidate: of all its channels).
    pub zeros: usize,
    /// A multi-input candidate's order per input, `(input, poles, zeros)`; empty for one input.
    pub channels: Vec<(String, usize, usize)>,
    /// Jitter family name.
    pub family: String,
    /// The information criterion the candidate is ranked by: the exact likelihood's BIC if
    /// [`ranked_by_likelihood`](Self::ranked_by_likelihood), else the BCLS BIC; `+∞` for a
    /// failed candidate.
    pub criterion: f64,
    /// Whether the fit that gives [`criterion`](Self::criterion) converged.
    pub converged: bool,
    /// Whether the candidate is a finalist whose exact maximum-likelihood fit converged: then
    /// [`criterion`](Self::criterion), [`parameters`](Self::parameters) and
    /// [`fitted`](Self::fitted) are those of the likelihood fit.
    pub ranked_by_likelihood: bool,
    /// The BIC of the BCLS screen (`+∞` for a candidate whose BCLS fit failed).
    pub bcls_criterion: f64,
    /// Whether the BCLS fit converged.
    pub bcls_converged: bool,
    /// The exact likelihood's BIC `−2 log L̂ + k ln N` of a finalist, converged or not.
    pub likelihood_criterion: Option<f64>,
    /// Why a finalist's likelihood fit failed or did not converge, if it did.
    pub likelihood_failure: Option<String>,
    /// The estimated parameters by name (empty for a failed candidate).
    pub parameters: Vec<(String, f64)>,
    /// Why the candidate failed, if it did.
    pub failure: Option<String>,
    /// What kind of failure [`failure`](Self::failure) is.
    pub failure_kind: Option<FailureKind>,
    /// The fitted system and jitter (absent for a failed candidate): the rational model
    /// (registry kind `tf`), with the [`SelectionOptions::delay`] and
    /// [`SelectionOptions::initial_state`] the selection ran with.
    pub fitted: Option<(AnySignal, AnyJitter)>,
}

/// What kind of outcome a failed candidate's screen fit had.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FailureKind {
    /// The search reached the imaginary axis (a pole with real part 0, an undamped mode) and
    /// every step beyond was refused, since the candidates are stable models. A candidate
    /// that needs an undamped mode to approach the record is not a model of it: typically an
    /// order with a pole to spare, its extra pair pushed to the axis while the jitter's
    /// spread grows to absorb the misfit.
    StabilityBoundary,
    /// The fit converged with a pole so fast that the samples do not determine it: `|p|·T`
    /// above `10π`, so that its mode decays by more than `e^{−10π} ≈ 2·10⁻¹⁴`
    /// within one sampling interval. Typically an order with a pole to spare, placed far
    /// beyond the sampling rate where it changes the sampled response by a small lag only. The
    /// candidate keeps its screen BIC but ranks after the identifiable converged ones and is
    /// never a likelihood finalist (its exact-likelihood refit would tabulate the response at
    /// that time scale around every input switch, for parameters the data do not fix).
    PoleBeyondSampling,
    /// The fit ran but did not converge (the solver's reason in the failure).
    NotConverged,
    /// The fit could not be made (the start, the initializer or the criterion failed).
    FitError,
}

impl Candidate {
    /// The normalised fit percent ([`fit_percent`]) of the candidate's expected samples
    /// `m_k = E[s(t_k + τ)]` against a validation `record` driven by `input`. The fitted
    /// delay is kept. A candidate with a free response starts from the validation record's own
    /// state, re-estimated on that record with everything else held
    /// ([`on_record`], as `jitterid validate` does): the
    /// estimation record's state says nothing about another record's. A multi-input
    /// candidate is driven by `inputs`, one per input; one input's by the first. `None` for a failed
    /// candidate, where that re-estimation or the rebuilt model fails, or where the fit percent
    /// is undefined (constant data).
    pub fn validation_fit(&self, record: &Record, inputs: &[Input]) -> Option<f64> {
        let (signal, jitter) = self.fitted.as_ref()?;
        let m = if self.channels.is_empty() {
            let fitted = ModelStructure::oe(signal.clone(), jitter.clone());
            let carried = on_record(&fitted, record.grid(), record.y(), inputs.first()).ok()?;
            carried
                .signal
                .expected_values(record.grid(), &carried.jitter)
        } else {
            // A multi-input candidate has no free response: only its inputs change.
            let registry = SignalRegistry::builtin();
            jitterid_signal::superposition::build(registry, &signal.spec(), inputs)
                .ok()?
                .expected_values(record.grid(), jitter)
        };
        fit_percent(record.y(), &m).ok()
    }
}

/// Why a selection could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SelectionError {
    /// A key of the grid holds an invalid value.
    #[error("select.{key}: {message}")]
    InvalidKey {
        /// The offending key.
        key: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A multi-input grid whose combinations of orders and families exceed
    /// [`MAX_CANDIDATES`].
    #[error("select.orders: {candidates} candidates (the product of each input's orders and the families), at most {MAX_CANDIDATES}: list fewer orders per input")]
    TooManyCandidates {
        /// The grid's number of candidates.
        candidates: usize,
    },
}

/// Most candidates of a multi-input grid: each is a joint fit of every channel, and the
/// product of the inputs' order lists grows fast (four orders for each of three inputs and two
/// families are 128 fits).
pub const MAX_CANDIDATES: usize = 64;

fn invalid(key: &'static str, message: impl Into<String>) -> SelectionError {
    SelectionError::InvalidKey {
        key,
        message: message.into(),
    }
}

impl SelectionGrid {
    /// The (poles, zeros, family) triples of the grid, rejecting bad input by key: an empty
    /// range, no proper order (zeros > poles everywhere), an unknown family, more parameters
    /// than the record of `len` samples supports.
    ///
    /// # Errors
    ///
    /// [`SelectionError::InvalidKey`] naming `poles`, `zeros` or `families`.
    pub fn candidates(
        &self,
        registry: &JitterRegistry,
        len: usize,
    ) -> Result<Vec<(usize, usize, String)>, SelectionError> {
        let (p0, p1) = self.poles;
        let (z0, z1) = self.zeros;
        if p0 == 0 || p0 > p1 {
            return Err(invalid(
                "poles",
                format!("[{p0}, {p1}] must be 1 ≤ min ≤ max"),
            ));
        }
        if z0 > z1 {
            return Err(invalid("zeros", format!("[{z0}, {z1}] must be min ≤ max")));
        }
        if z0 > p1 {
            return Err(invalid(
                "zeros",
                format!("at least {z0} zeros but at most {p1} poles: no proper model"),
            ));
        }
        self.check_families(registry)?;
        // Levy's linear fit needs 2n + m + 1 real equations from bins below N/2.
        let needed = 2 * p1 + p1.min(z1) + 2;
        if needed > len {
            return Err(invalid(
                "poles",
                format!("{p1} poles need at least {needed} samples; the record has {len}"),
            ));
        }
        let mut out = Vec::new();
        for poles in p0..=p1 {
            for zeros in z0..=z1.min(poles) {
                for family in &self.families {
                    out.push((poles, zeros, family.clone()));
                }
            }
        }
        Ok(out)
    }
}

impl SelectionGrid {
    /// Every family is known to `registry` and can be started from a standard deviation.
    fn check_families(&self, registry: &JitterRegistry) -> Result<(), SelectionError> {
        if self.families.is_empty() {
            return Err(invalid("families", "the list is empty"));
        }
        let known: Vec<&str> = registry.families().map(|f| f.name()).collect();
        for name in &self.families {
            let Some(family) = registry.family(name) else {
                return Err(invalid(
                    "families",
                    format!("unknown family {name:?}; known: {}", known.join(", ")),
                ));
            };
            // Every candidate is started from standard deviations alone: a composite needs its
            // terms, which a grid of names cannot give.
            if family.takes_terms() || !family.has_std_dev_form() {
                return Err(invalid(
                    "families",
                    format!(
                        "family {name:?} cannot be started from a standard deviation alone \
                         (a composite needs its terms); list the families of its terms instead"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Monic `(s+1)(s+2)…(s+n)`: a stable template of distinct poles (its values are ignored).
fn template(zeros: usize, poles: usize) -> Result<TransferFunction, String> {
    let mut den = vec![1.0];
    for r in 1..=poles {
        let mut next = vec![0.0; den.len() + 1];
        for (i, c) in den.iter().enumerate() {
            next[i] += c;
            next[i + 1] += c * r as f64;
        }
        den = next;
    }
    TransferFunction::new(&vec![1.0; zeros + 1], &den).map_err(|e| e.to_string())
}

type Structure = ModelStructure<AnySignal, AnyJitter, jitterid_estimate::WhiteNoise>;

/// The structure a candidate of `family` is fitted in: its system estimated, its jitter too
/// unless the family is `"none"`.
fn structure_of(family: &str, signal: AnySignal, jitter: AnyJitter) -> Structure {
    if family == "none" {
        ModelStructure::oe(signal, jitter)
    } else {
        ModelStructure::joe(signal, jitter)
    }
}

/// `spec` with the options' output offset: a known `y₀` as it is, an estimated one started at
/// `mean(y) − mean(m_k)` of the candidate's response `bare` (the spec without the offset) under
/// `jitter`.
fn with_offset(
    mut spec: SpecTable,
    bare: &dyn Fn(&SpecTable) -> Result<AnySignal, String>,
    record: &Record,
    jitter: &AnyJitter,
    options: &SelectionOptions,
) -> Result<SpecTable, String> {
    let Some((y0, estimated)) = options.offset else {
        return Ok(spec);
    };
    let y0 = if estimated {
        let start = offset_start(&bare(&spec)?, record, jitter);
        if !start.is_finite() {
            return Err("offset start: not finite".into());
        }
        start
    } else {
        y0
    };
    spec.insert("offset".into(), json!(y0));
    if estimated {
        spec.insert("estimate_offset".into(), json!(true));
    }
    Ok(spec)
}

/// The candidate's signal: `model` driven by `input`, with the options' delay, free response
/// from an unknown state at the record's first instant (coefficients at 0) and output offset.
fn candidate_signal(
    model: &TransferFunction,
    input: &Input,
    record: &Record,
    jitter: &AnyJitter,
    options: &SelectionOptions,
) -> Result<AnySignal, String> {
    let mut spec = SpecTable::new();
    spec.insert("kind".into(), json!("tf"));
    spec.insert("num".into(), json!(model.num()));
    spec.insert("den".into(), json!(model.den()));
    if let Some(d) = options.delay {
        spec.insert("delay".into(), json!(d));
    }
    if let Some((u0, estimated)) = options.level {
        spec.insert("level".into(), json!(u0));
        if estimated {
            spec.insert("estimate_level".into(), json!(true));
        }
    }
    if options.initial_state {
        spec.insert("initial".into(), json!(vec![0.0; model.den().len() - 1]));
        spec.insert("origin".into(), json!(record.grid().start()));
    }
    let build = |spec: &SpecTable| {
        SignalRegistry::builtin()
            .build(spec, Some(input))
            .map_err(|e| e.to_string())
    };
    build(&with_offset(spec, &build, record, jitter, options)?)
}

/// The jitter start of a candidate of `family`: a standard deviation of `fraction · T`.
fn jitter_at(
    registry: &JitterRegistry,
    family: &str,
    record: &Record,
    fraction: f64,
) -> Result<AnyJitter, String> {
    let sigma = fraction * record.grid().interval();
    registry
        .from_std_dev(family, sigma, &serde_json::Map::new())
        .map_err(|e| format!("jitter start: {e}"))
}

/// The BCLS fit of a candidate of `family` from the start `signal`, `jitter`.
fn bcls_from(
    record: &Record,
    family: &str,
    signal: AnySignal,
    jitter: AnyJitter,
) -> Result<(Structure, jitterid_estimate::Fit), String> {
    let structure = structure_of(family, signal, jitter);
    // The ranking needs the cost only; the sandwich covariance would dominate the time.
    let options = FitOptions::default().with_covariance(false);
    let estimate = fit(&structure, record, &Bcls, &options).map_err(|e| format!("fit: {e}"))?;
    Ok((structure, estimate))
}

/// The initializer's options for the candidates: an output offset moves the bin `f = 0`
/// only, which the initializer then leaves out.
fn init_options(options: &SelectionOptions) -> InitOptions {
    InitOptions {
        offset: options.offset.is_some(),
        ..InitOptions::default()
    }
}

/// One BCLS fit of a candidate from the initializer's model with the jitter at `fraction · T`.
fn fit_from(
    record: &Record,
    input: &Input,
    registry: &JitterRegistry,
    options: &SelectionOptions,
    (family, poles, zeros): (&str, usize, usize),
    fraction: f64,
) -> Result<(Structure, jitterid_estimate::Fit), String> {
    let jitter = jitter_at(registry, family, record, fraction)?;
    let model = template(zeros, poles).map_err(|e| format!("template: {e}"))?;
    // The initializer fits the response to the input as the system sees it (around its
    // level, delayed), so that the rational model does not absorb the delay's phase as well.
    let around = match options.level {
        Some((u0, _)) => input.deviation(u0).map_err(|e| format!("level: {e}"))?,
        None => input.clone(),
    };
    let driven = match options.delay {
        Some(d) => around.delayed(d).map_err(|e| format!("delay: {e}"))?,
        None => around,
    };
    let rational = ModelStructure::oe(LtiResponse::new(model, driven), jitter.clone());
    let rational = initialize(&rational, record, &init_options(options))
        .map_err(|e| format!("initializer: {e}"))?;
    let signal = candidate_signal(
        rational.signal.model(),
        input,
        record,
        &rational.jitter,
        options,
    )
    .map_err(|e| format!("candidate system: {e}"))?;
    bcls_from(record, family, signal, rational.jitter)
}

/// A candidate before its fit: its orders and jitter family.
struct Label {
    poles: usize,
    zeros: usize,
    channels: Vec<(String, usize, usize)>,
    family: String,
}

/// A candidate's BCLS fit from the jitter start `fraction · T`.
type FitAt<'a> = dyn Fn(f64) -> Result<(Structure, jitterid_estimate::Fit), String> + 'a;

/// The screened candidate `label`, fitted by `fit_at` from every jitter start of `options`
/// (one for `"none"`), keeping the best fit, with its BIC and the kind of its failure.
fn fit_candidate(
    record: &Record,
    options: &SelectionOptions,
    label: Label,
    fit_at: &FitAt<'_>,
) -> Candidate {
    let Label {
        poles,
        zeros,
        channels,
        family,
    } = label;
    let failed = |reason: String| Candidate {
        poles,
        zeros,
        channels: channels.clone(),
        family: family.clone(),
        criterion: f64::INFINITY,
        converged: false,
        ranked_by_likelihood: false,
        bcls_criterion: f64::INFINITY,
        bcls_converged: false,
        likelihood_criterion: None,
        likelihood_failure: None,
        parameters: Vec::new(),
        failure: Some(reason),
        failure_kind: Some(FailureKind::FitError),
        fitted: None,
    };
    // "none" has no scale: one start is enough.
    let fractions: &[f64] = if family == "none" {
        &options.jitter_fractions[..1]
    } else {
        &options.jitter_fractions
    };
    let mut best: Option<(Structure, jitterid_estimate::Fit)> = None;
    let mut last_error = String::new();
    for &fraction in fractions {
        match fit_at(fraction) {
            Ok((s, fit)) => {
                let better = match &best {
                    None => true,
                    Some((_, b)) => (fit.converged, -fit.cost) > (b.converged, -b.cost),
                };
                if better {
                    best = Some((s, fit));
                }
            }
            Err(e) => last_error = e,
        }
    }
    let Some((structure, fit)) = best else {
        return failed(last_error);
    };
    let n = record.y().len() as f64;
    let k = fit.params.len() as f64;
    let criterion = if fit.cost > 0.0 && fit.cost.is_finite() {
        n * fit.cost.ln() + k * n.ln()
    } else {
        return failed(format!("cost {} is not positive and finite", fit.cost));
    };
    let (failure, failure_kind) = if fit.converged {
        match fast_poles(&structure, &fit.params, record.grid().interval()) {
            Some(fast) => (
                Some(format!(
                    "pole(s) {fast} beyond the sampling's reach (|p|·T above 10π = {BEYOND_SAMPLING:.1}): the samples do not determine them; ranked after the identifiable candidates and not refitted by exact likelihood"
                )),
                Some(FailureKind::PoleBeyondSampling),
            ),
            None => (None, None),
        }
    } else {
        match axis_poles(&structure, &fit.params) {
            Some(on_axis) => (
                Some(format!(
                    "reached the stability boundary: pole(s) {on_axis} on the imaginary axis, every step beyond refused (a candidate that needs an undamped mode is not a model of this record)"
                )),
                Some(FailureKind::StabilityBoundary),
            ),
            None => (
                Some(fit.termination.to_string()),
                Some(FailureKind::NotConverged),
            ),
        }
    };
    Candidate {
        poles,
        zeros,
        channels,
        family,
        criterion,
        converged: fit.converged,
        ranked_by_likelihood: false,
        bcls_criterion: criterion,
        bcls_converged: fit.converged,
        likelihood_criterion: None,
        likelihood_failure: None,
        parameters: fit
            .names
            .iter()
            .cloned()
            .zip(fit.params.iter().copied())
            .collect(),
        failure,
        failure_kind,
        fitted: structure
            .with_params(&fit.params)
            .ok()
            .map(|s| (s.signal, s.jitter)),
    }
}

/// A pole's real part within this fraction of its magnitude (at least 1 rad/s) of 0 is on the
/// imaginary axis: far inside the search's refused steps, far outside any damping a record of
/// at most 10⁷ samples resolves.
const ON_AXIS: f64 = 1e-6;

/// `|p|·T` above which a pole is beyond the sampling's reach ([`FailureKind::PoleBeyondSampling`]):
/// `10π`, where its mode decays by `e^{−10π} ≈ 2·10⁻¹⁴` within one interval, below the
/// resolution of the samples in double precision.
const BEYOND_SAMPLING: f64 = 10.0 * std::f64::consts::PI;

/// The poles of the candidate at `params` that satisfy `keep`, written out, or `None` when
/// there are none (or the system is not a transfer function).
fn poles_where(
    structure: &Structure,
    params: &[f64],
    keep: impl Fn(&num_complex::Complex64) -> bool,
) -> Option<String> {
    let at = structure.with_params(params).ok()?;
    let spec = at.signal.spec();
    // A multi-input candidate's poles are those of its channels, each a `tf` table.
    let parts: Vec<(&str, SpecTable)> = match spec.get("channels").and_then(|c| c.as_array()) {
        Some(channels) => channels
            .iter()
            .filter_map(|c| c.as_object().map(|t| ("tf", t.clone())))
            .collect(),
        None => vec![(at.signal.kind(), spec)],
    };
    let mut kept: Vec<String> = Vec::new();
    for (kind, spec) in &parts {
        let r = SignalRegistry::builtin().kind(kind)?.reader(spec).ok()?;
        let tf = TfForm::new(&r.f64_list("num").ok()?, &r.f64_list("den").ok()?).ok()?;
        kept.extend(
            tf.to_zpk()
                .ok()?
                .poles()
                .iter()
                .filter(|p| keep(p))
                .map(|p| format!("{:.4}{:+.4}i", p.re, p.im)),
        );
    }
    (!kept.is_empty()).then(|| kept.join(", "))
}

/// The poles of the candidate at `params` that lie on the imaginary axis.
fn axis_poles(structure: &Structure, params: &[f64]) -> Option<String> {
    poles_where(structure, params, |p| {
        p.re.abs() <= ON_AXIS * p.norm().max(1.0)
    })
}

/// The poles of the candidate at `params` beyond the sampling's reach at interval `t`.
fn fast_poles(structure: &Structure, params: &[f64], t: f64) -> Option<String> {
    poles_where(structure, params, |p| p.norm() * t > BEYOND_SAMPLING)
}

/// The options' jitter starts are a non-empty list of positive finite fractions.
fn check_fractions(options: &SelectionOptions) -> Result<(), SelectionError> {
    let fractions = &options.jitter_fractions;
    if fractions.is_empty() || !fractions.iter().all(|f| f.is_finite() && *f > 0.0) {
        return Err(invalid(
            "jitter_fractions",
            format!("{fractions:?} must be a non-empty list of positive finite numbers"),
        ));
    }
    Ok(())
}

/// Fit every candidate of `grid` on `record` (driven by `input`) and return them best first
/// (see the [module docs](self)): the finalists ranked by the exact likelihood's BIC, then the
/// other converged candidates by the BCLS BIC, then the failed ones. Candidates are fitted in
/// parallel; the order is deterministic (ties broken by grid order).
///
/// # Errors
///
/// Those of [`SelectionGrid::candidates`].
pub fn select(
    record: &Record,
    input: &Input,
    grid: &SelectionGrid,
    registry: &JitterRegistry,
    options: &SelectionOptions,
) -> Result<Vec<Candidate>, SelectionError> {
    check_fractions(options)?;
    let list = grid.candidates(registry, record.y().len())?;
    let budget = jitterid_numeric::budget::current();
    let out: Vec<Candidate> = list
        .into_par_iter()
        .map(|(poles, zeros, family)| {
            jitterid_numeric::budget::run_with(budget.clone(), || {
                let fit_at = |fraction| {
                    fit_from(
                        record,
                        input,
                        registry,
                        options,
                        (&family, poles, zeros),
                        fraction,
                    )
                };
                let label = Label {
                    poles,
                    zeros,
                    channels: Vec::new(),
                    family: family.clone(),
                };
                fit_candidate(record, options, label, &fit_at)
            })
        })
        .collect();
    Ok(rank(record, registry, options, out))
}

/// The screened candidates `out`, their finalists refitted by exact likelihood when the
/// options say so, best first (see [`select`]).
fn rank(
    record: &Record,
    registry: &JitterRegistry,
    options: &SelectionOptions,
    mut out: Vec<Candidate>,
) -> Vec<Candidate> {
    if options.refine_by_likelihood {
        likelihood::refine_finalists(record, registry, &mut out);
    }
    // A stable sort keeps grid order among equal keys: deterministic for any thread count.
    let group = |c: &Candidate| match (c.ranked_by_likelihood, c.converged) {
        (true, _) => 0,
        (false, true) if c.failure_kind == Some(FailureKind::PoleBeyondSampling) => 2,
        (false, true) => 1,
        (false, false) => 3,
    };
    out.sort_by(|a, b| {
        group(a)
            .cmp(&group(b))
            .then(a.criterion.total_cmp(&b.criterion))
    });
    out
}

#[cfg(test)]
mod tests;
