//! The multisine design: which tones, how much power in each, and which phases.
//!
//! The candidate frequencies are `[design] tones` harmonics of `f0 = 1/(N T)` spread
//! log-uniformly over `[design] band` (so the input is periodic over the record). A design is
//! a power distribution `w` on the simplex over them: amplitudes `aᵢ = √(2 P wᵢ)` under a
//! power constraint (`Σ aᵢ²/2 = P` exactly), or scaled so that the peak is exactly the bound
//! under an amplitude constraint alone. Without jitter the information would be linear in `w`
//! and the classical multiplicative algorithms would apply; with jitter the noise after every
//! slope (`σ_τ² s′(t)²`) makes it nonlinear, so every candidate is judged by the exact
//! prediction ([`evaluate`]). On a support `S` of the tones, `w` is parametrised by the
//! squares of unconstrained coordinates (`wᵢ = zᵢ² / Σ_{j∈S} zⱼ²` for `i ∈ S`, 0 elsewhere),
//! which keeps it on the simplex and lets a share reach exactly 0 at a regular point (a
//! softmax only approaches a face of the simplex asymptotically, and the best designs lie on
//! faces: most tones get no power). The criterion is minimised over `z` by the solvers' BFGS
//! ([`Bfgs`], which takes an infeasible candidate as `+∞`) from the flat spectrum, with central
//! differences whose components are evaluated in parallel: a deterministic descent that
//! accepts only steps that lower the criterion.
//!
//! A tone whose share reaches 0 cannot come back by the gradient (`∂w/∂zᵢ = 0` at `zᵢ = 0`),
//! and a tone the descent leaves a little power may be better without any, so an exchange
//! step follows (the vertex exchange of classical optimal design): the support is changed by
//! dropping a tone (its power shared out over the rest) or adding one (a share of
//! [`ADD_SHARE`] moved to it), whichever change lowers the criterion most, and the descent is
//! run again on the new support, until no single change lowers it.
//!
//! Where the descent starts matters (the criterion under jitter is not convex in the shares):
//! it starts from the flat spectrum and from the jitter-blind design's shares (cheap to find:
//! its information has no jitter noise), and the better end is kept.
//!
//! During the descent the phases are Schroeder's for the current `w` (a smooth function of
//! it, so the differences are smooth). At the end the phases are chosen as `[design] phases`
//! says: for the criterion (the default), BFGS on the phases of the tones with power from the
//! better of Schroeder's and the clipping algorithm's low-crest phases ([`low_crest_phases`]),
//! a phase set that breaks a peak bound being infeasible; or for the lowest crest factor
//! alone (`"crest"`). Tones left without power are not part of the design. The file's own
//! multisine, when it meets the constraint, is a candidate beside the result, so the result
//! is never worse than the baseline it is compared with.

use super::blind::evaluate;
use super::candidate::Design;
use super::crest::{harmonic_tones, low_crest_phases, peak, rms, schroeder_phases};
use super::plan::Plan;
use super::predict::Prediction;
use super::progress::DesignProgress;
use super::search::Optimum;
use crate::error::StudyResult;
use crate::experiment::{harmonics_in, DesignCriterion, PhaseChoice, ToneDesignSpec};
use crate::study_err;
use jitterid::estimate::solver::{Bfgs, Objective, Solver};
use jitterid::signal::Tone;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};

/// BFGS iterations on the power distribution.
const ITERATIONS: u64 = 40;

/// Step in the coordinates `zᵢ` (about `√wᵢ`, so of order `1/√tones`) of the central
/// differences: large enough that a criterion computed by quadrature (exact ML's Fisher
/// information) does not turn the gradient into noise, small enough that the differences' own
/// error (second order) is negligible.
const DIFFERENCE: f64 = 1e-3;

/// The share a tone outside the support is given when the exchange step tries adding it
/// (the others scaled down to make room): large enough that the criterion's change is far
/// above the prediction's rounding, small enough to say where the criterion goes from the
/// face.
const ADD_SHARE: f64 = 0.02;

/// A share below which a tone is dropped at the end when that costs nothing (`1e-6` of the
/// power is an amplitude `10⁻³` of the others').
const NEGLIGIBLE_SHARE: f64 = 1e-6;

/// Rounds of the exchange step per candidate tone, at most.
const EXCHANGES: usize = 2;

/// BFGS iterations of a scouting descent (one that the exchange step may follow).
const SCOUT_ITERATIONS: u64 = 8;

/// How far a descent goes.
#[derive(Debug, Clone, Copy)]
enum Depth {
    /// [`SCOUT_ITERATIONS`], no restarts: enough to say which tones matter.
    Scout,
    /// [`ITERATIONS`] and [`RESTARTS`]: the shares on a settled support.
    Full,
}

/// BFGS iterations on the phases (a multimodal function of them: a local descent from good
/// phases, not a global search).
const PHASE_ITERATIONS: u64 = 20;

/// BFGS restarts from its own result (a fresh inverse Hessian), while a restart still lowers
/// the criterion: a quasi-Newton run can stall on a stale curvature estimate.
const RESTARTS: usize = 3;

/// Predicted decrease of the criterion below which the descent stops (the criterion's Monte
/// Carlo error is orders of magnitude larger).
const DECREMENT: f64 = 1e-7;

/// A designed multisine `u(t) = Σ aᵢ sin(2π fᵢ t + φᵢ)`, as `[input] kind = "multisine"`
/// writes it, with its crest factor and power.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MultisineDesign {
    /// The tones' frequencies (Hz).
    pub frequencies: Vec<f64>,
    /// Their amplitudes.
    pub amplitudes: Vec<f64>,
    /// Their phases (rad).
    pub phases: Vec<f64>,
    /// The crest factor `max |u(t)| / rms` over the record.
    pub crest_factor: f64,
    /// The total mean power `Σ aᵢ²/2`.
    pub power: f64,
}

impl MultisineDesign {
    /// The design of `tones`, its peak taken over `span` (the record).
    pub fn of_tones(tones: &[Tone], span: (f64, f64)) -> Self {
        let r = rms(tones);
        MultisineDesign {
            frequencies: tones.iter().map(|t| t.frequency).collect(),
            amplitudes: tones.iter().map(|t| t.amplitude).collect(),
            phases: tones.iter().map(|t| t.phase).collect(),
            crest_factor: if r > 0.0 { peak(tones, span) / r } else { 0.0 },
            power: r * r,
        }
    }

    /// The same multisine without its tones of amplitude 0 (they add nothing to the signal,
    /// and a signal generator need not be told of them).
    pub fn without_silent_tones(&self) -> Self {
        let keep: Vec<usize> = (0..self.amplitudes.len())
            .filter(|&i| self.amplitudes[i] != 0.0)
            .collect();
        let pick = |xs: &[f64]| keep.iter().map(|&i| xs[i]).collect();
        MultisineDesign {
            frequencies: pick(&self.frequencies),
            amplitudes: pick(&self.amplitudes),
            phases: pick(&self.phases),
            ..self.clone()
        }
    }

    /// The tones.
    pub fn tones(&self) -> Vec<Tone> {
        self.frequencies
            .iter()
            .zip(&self.amplitudes)
            .zip(&self.phases)
            .map(|((&frequency, &amplitude), &phase)| Tone {
                frequency,
                amplitude,
                phase,
            })
            .collect()
    }

    /// The peak `max |u(t)|` over the record, `crest_factor · √power`.
    pub fn peak(&self) -> f64 {
        self.crest_factor * self.power.sqrt()
    }
}

/// `count` distinct harmonics in `[first, last]`, log-spaced (all of them when the range
/// holds no more).
pub fn log_spaced_harmonics(first: u64, last: u64, count: usize) -> Vec<u64> {
    let available = (last - first + 1) as usize;
    if count >= available {
        return (first..=last).collect();
    }
    if count == 1 {
        return vec![((first as f64 * last as f64).sqrt().round() as u64).clamp(first, last)];
    }
    let (a, b) = ((first as f64).ln(), (last as f64).ln());
    let mut out: Vec<u64> = Vec::with_capacity(count);
    for j in 0..count {
        let target = (a + (b - a) * j as f64 / (count - 1) as f64).exp().round() as u64;
        // Distinct and increasing, with room left for the harmonics still to place.
        let lo = out.last().map_or(first, |k| k + 1);
        let hi = last - (count - 1 - j) as u64;
        out.push(target.clamp(lo, hi));
    }
    out
}

/// What the search knows about the record and the constraint.
struct Tones<'a> {
    spec: &'a ToneDesignSpec,
    f0: f64,
    k: Vec<u64>,
    span: (f64, f64),
    base: Design,
}

impl Tones<'_> {
    /// The multisine of power shares `w` with `phases` (Schroeder's for `w` when `None`),
    /// scaled to the constraint; `None` when a power and a peak bound are both given and this
    /// spectrum's crest factor cannot hold the power under the peak.
    fn multisine(&self, w: &[f64], phases: Option<&[f64]>) -> Option<MultisineDesign> {
        let p = self.spec.power.unwrap_or(1.0);
        let mut a: Vec<f64> = w.iter().map(|wi| (2.0 * p * wi).sqrt()).collect();
        let phases = match phases {
            Some(ph) => ph.to_vec(),
            None => schroeder_phases(&self.k, w),
        };
        let top = peak(&harmonic_tones(self.f0, &self.k, &a, &phases), self.span);
        match (self.spec.power, self.spec.peak) {
            (Some(_), Some(bound)) if top > bound => return None,
            (None, Some(bound)) => a.iter_mut().for_each(|ai| *ai *= bound / top),
            _ => {}
        }
        let tones = harmonic_tones(self.f0, &self.k, &a, &phases);
        let mut m = MultisineDesign::of_tones(&tones, self.span);
        if let (None, Some(bound)) = (self.spec.power, self.spec.peak) {
            // The peak is the bound by construction; the crest factor says the power.
            m.crest_factor = bound / rms(&tones);
        }
        Some(m)
    }

    fn design(&self, m: MultisineDesign) -> Design {
        Design {
            multisine: Some(m),
            ..self.base.clone()
        }
    }
}

/// One evaluated candidate.
type Candidate = (Design, f64, Prediction);

/// The criterion at power shares `w` (`+∞` where the design is infeasible).
fn value_at(
    plan: &Plan,
    criterion: &DesignCriterion,
    tones: &Tones,
    w: &[f64],
    phases: Option<&[f64]>,
) -> Option<Candidate> {
    let m = tones.multisine(w, phases)?;
    let d = tones.design(m);
    let (p, v) = evaluate(plan, &d, criterion).ok()?;
    (!v.is_nan() && v < f64::INFINITY).then_some((d, v, p))
}

/// The power shares of coordinates `z` on `support` (`n` tones in all): `zᵢ² / Σ zⱼ²` on the
/// support, 0 elsewhere; `None` when every coordinate is 0.
fn shares(n: usize, support: &[usize], z: &[f64]) -> Option<Vec<f64>> {
    let sum: f64 = z.iter().map(|zi| zi * zi).sum();
    if !(sum > 0.0 && sum.is_finite()) {
        return None;
    }
    let mut w = vec![0.0; n];
    for (&i, zi) in support.iter().zip(z) {
        w[i] = zi * zi / sum;
    }
    Some(w)
}

/// The criterion as a function of the coordinates of the power shares on a support.
struct Shares<'s, 'a> {
    plan: &'s Plan,
    criterion: &'s DesignCriterion,
    tones: &'s Tones<'a>,
    evaluations: &'s Evaluations<'s>,
    support: &'s [usize],
}

/// The designs the search has evaluated, each reported to the plan's observer as it starts
/// (from the thread that evaluates it: the gradient's components run in parallel).
struct Evaluations<'p> {
    plan: &'p Plan,
    count: AtomicUsize,
}

impl Evaluations<'_> {
    /// Counts and reports one more evaluation.
    fn tick(&self) {
        let evaluations = self.count.fetch_add(1, Ordering::Relaxed) + 1;
        self.plan.observe(DesignProgress::Evaluated {
            jitter_blind: self.plan.is_jitter_blind(),
            evaluations,
            // A multisine search has no grid: its size is not known before it runs.
            grid_points: 0,
        });
    }
}

impl Objective for Shares<'_, '_> {
    fn num_params(&self) -> usize {
        self.support.len()
    }

    fn cost(&self, z: &[f64]) -> f64 {
        self.evaluations.tick();
        shares(self.tones.k.len(), self.support, z)
            .and_then(|w| value_at(self.plan, self.criterion, self.tones, &w, None))
            .map_or(f64::INFINITY, |c| c.1)
    }

    fn cost_gradient(&self, z: &[f64]) -> (f64, Vec<f64>) {
        central_differences(self, z)
    }
}

/// The cost and its central differences at `x`, the components in parallel (one-sided beside
/// an infeasible point).
fn central_differences<O: Objective + Sync + ?Sized>(objective: &O, x: &[f64]) -> (f64, Vec<f64>) {
    let f = objective.cost(x);
    let g = (0..x.len())
        .into_par_iter()
        .map(|j| {
            let at = |h: f64| {
                let mut y = x.to_vec();
                y[j] += h;
                objective.cost(&y)
            };
            let (up, down) = (at(DIFFERENCE), at(-DIFFERENCE));
            match (up.is_finite(), down.is_finite()) {
                (true, true) => (up - down) / (2.0 * DIFFERENCE),
                (true, false) => (up - f) / DIFFERENCE,
                (false, true) => (f - down) / DIFFERENCE,
                (false, false) => 0.0,
            }
        })
        .collect();
    (f, g)
}

/// The criterion as a function of the phases of the tones with power, at fixed shares.
struct PhaseObjective<'s, 'a> {
    plan: &'s Plan,
    criterion: &'s DesignCriterion,
    tones: &'s Tones<'a>,
    evaluations: &'s Evaluations<'s>,
    w: &'s [f64],
    support: &'s [usize],
    /// The phases of the tones without power (they do not change the signal).
    rest: &'s [f64],
}

impl PhaseObjective<'_, '_> {
    fn phases(&self, phi: &[f64]) -> Vec<f64> {
        let mut all = self.rest.to_vec();
        for (&i, &p) in self.support.iter().zip(phi) {
            all[i] = p;
        }
        all
    }

    fn candidate(&self, phi: &[f64]) -> Option<Candidate> {
        value_at(
            self.plan,
            self.criterion,
            self.tones,
            self.w,
            Some(&self.phases(phi)),
        )
    }
}

impl Objective for PhaseObjective<'_, '_> {
    fn num_params(&self) -> usize {
        self.support.len()
    }

    fn cost(&self, phi: &[f64]) -> f64 {
        self.evaluations.tick();
        self.candidate(phi).map_or(f64::INFINITY, |c| c.1)
    }

    fn cost_gradient(&self, phi: &[f64]) -> (f64, Vec<f64>) {
        central_differences(self, phi)
    }
}

/// The phases at shares `w`, chosen as `spec.phases` says, and the design they make:
/// for the criterion, BFGS on the phases of the tones with power from the better of the
/// search's phases (`searched`, evaluated) and the low-crest phases, under the constraint
/// (a phase set that breaks a peak bound is infeasible); for the crest factor, the low-crest
/// phases (the search's, when those break the bound).
fn choose_phases(
    plan: &Plan,
    criterion: &DesignCriterion,
    tones: &Tones,
    evaluations: &Evaluations,
    w: &[f64],
    searched: Candidate,
) -> Candidate {
    let amplitudes: Vec<f64> = w.iter().map(|wi| wi.sqrt()).collect();
    let crest = low_crest_phases(&tones.k, &amplitudes);
    evaluations.tick();
    let low_crest = value_at(plan, criterion, tones, w, Some(&crest));
    if tones.spec.phases == PhaseChoice::Crest {
        return low_crest.unwrap_or(searched);
    }
    let start = match low_crest {
        Some(c) if c.1 < searched.1 => c,
        _ => searched,
    };
    let Some(m) = &start.0.multisine else {
        return start;
    };
    let rest = m.phases.clone();
    let support: Vec<usize> = (0..w.len()).filter(|&i| w[i] > 0.0).collect();
    let phi: Vec<f64> = support.iter().map(|&i| rest[i]).collect();
    let objective = PhaseObjective {
        plan,
        criterion,
        tones,
        evaluations,
        w,
        support: &support,
        rest: &rest,
    };
    let bfgs = Bfgs {
        max_iters: PHASE_ITERATIONS,
        decrement_tol: DECREMENT,
        initial_step: 0.5,
        ..Bfgs::default()
    };
    // A descent that fails, or ends no lower, leaves the start.
    match bfgs.minimize(&objective as &dyn Objective, &phi) {
        Ok(r) => match objective.candidate(&r.params) {
            Some(c) if c.1 < start.1 => c,
            _ => start,
        },
        Err(_) => start,
    }
}

/// The power shares of the jitter-blind design on the same tones (its amplitudes squared,
/// normalised), or `None` when that search fails or settles on other tones (the file's own
/// multisine).
fn blind_shares(
    plan: &Plan,
    criterion: &DesignCriterion,
    spec: &ToneDesignSpec,
    tones: &Tones,
) -> Option<Vec<f64>> {
    let blind = plan.jitter_blind().ok()?;
    let m = optimise_tones(&blind, criterion, spec)
        .ok()?
        .design
        .multisine?;
    let total: f64 = m.amplitudes.iter().map(|a| a * a).sum();
    if !(total > 0.0) {
        return None;
    }
    let mut w = vec![0.0; tones.k.len()];
    for (f, a) in m.frequencies.iter().zip(&m.amplitudes) {
        let i = tones
            .k
            .iter()
            .position(|&k| (f - k as f64 * tones.f0).abs() <= 1e-9 * f.abs())?;
        w[i] = a * a / total;
    }
    Some(w)
}

/// The descent on the power shares and the exchange of tones around it: the best design so
/// far (`best`, evaluated) and its shares (`w`).
struct Descent<'s, 'a> {
    plan: &'s Plan,
    criterion: &'s DesignCriterion,
    tones: &'s Tones<'a>,
    evaluations: &'s Evaluations<'s>,
    best: Candidate,
    w: Vec<f64>,
}

impl Descent<'_, '_> {
    /// BFGS on the shares of `support` from the current `w` (restarted from its own result
    /// while a restart still lowers the criterion); keeps any point that lowers it.
    fn descend(&mut self, support: &[usize], depth: Depth) {
        if support.len() < 2 {
            return;
        }
        let objective = Shares {
            plan: self.plan,
            criterion: self.criterion,
            tones: self.tones,
            evaluations: self.evaluations,
            support,
        };
        let (iterations, restarts) = match depth {
            Depth::Scout => (SCOUT_ITERATIONS, 0),
            Depth::Full => (ITERATIONS, RESTARTS),
        };
        let bfgs = Bfgs {
            max_iters: iterations,
            decrement_tol: DECREMENT,
            initial_step: 0.5,
            ..Bfgs::default()
        };
        let n = self.tones.k.len();
        let mut z: Vec<f64> = support.iter().map(|&i| self.w[i].sqrt()).collect();
        for _ in 0..=restarts {
            // A descent that fails leaves the best point so far, which is already evaluated.
            let Ok(r) = bfgs.minimize(&objective as &dyn Objective, &z) else {
                break;
            };
            let Some(moved) = shares(n, support, &r.params) else {
                break;
            };
            match value_at(self.plan, self.criterion, self.tones, &moved, None) {
                Some(c) if c.1 < self.best.1 - DECREMENT => {
                    self.w = moved;
                    self.best = c;
                    z = r.params;
                }
                _ => break,
            }
        }
    }

    /// The exchange step (see the module docs): while dropping or adding one tone lowers the
    /// criterion, make the change that lowers it most and descend again on the new support.
    /// `support` becomes the tones with power.
    fn exchange(&mut self, support: &mut Vec<usize>, depth: Depth) {
        let n = self.tones.k.len();
        // A tone the descent left without power is outside the support.
        support.retain(|&i| self.w[i] > 0.0);
        // Each accepted change lowers the criterion, so a support never returns; the bound
        // only caps the work on a criterion that keeps finding tiny improvements.
        for _ in 0..EXCHANGES * n {
            let mut moves: Vec<(Vec<usize>, Vec<f64>)> = Vec::new();
            if support.len() > 1 {
                for &j in support.iter() {
                    let rest = 1.0 - self.w[j];
                    if !(rest > 0.0) {
                        continue;
                    }
                    let w: Vec<f64> = (0..n)
                        .map(|i| if i == j { 0.0 } else { self.w[i] / rest })
                        .collect();
                    let s: Vec<usize> = support.iter().copied().filter(|&i| i != j).collect();
                    moves.push((s, w));
                }
            }
            for j in (0..n).filter(|j| !support.contains(j)) {
                let mut w: Vec<f64> = self.w.iter().map(|wi| wi * (1.0 - ADD_SHARE)).collect();
                w[j] = ADD_SHARE;
                let mut s = support.clone();
                s.push(j);
                s.sort_unstable();
                moves.push((s, w));
            }
            let values: Vec<Option<Candidate>> = moves
                .par_iter()
                .map(|(_, w)| {
                    self.evaluations.tick();
                    value_at(self.plan, self.criterion, self.tones, w, None)
                })
                .collect();
            // The change that lowers the criterion most (ties to the first: deterministic).
            let mut chosen: Option<(usize, Candidate)> = None;
            for (m, c) in values.into_iter().enumerate() {
                let Some(c) = c else { continue };
                let bar = chosen.as_ref().map_or(self.best.1 - DECREMENT, |b| b.1 .1);
                if c.1 < bar {
                    chosen = Some((m, c));
                }
            }
            let Some((m, c)) = chosen else {
                break;
            };
            let (s, w) = moves.swap_remove(m);
            *support = s;
            self.w = w;
            self.best = c;
            self.descend(support, depth);
            support.retain(|&i| self.w[i] > 0.0);
        }
        self.prune(support);
    }

    /// Tones the descent left a share below [`NEGLIGIBLE_SHARE`] get none, when that does not
    /// raise the criterion by more than the descent's own resolution: a designed multisine
    /// does not carry tones at amplitudes no generator would reproduce.
    fn prune(&mut self, support: &mut Vec<usize>) {
        let small: Vec<usize> = support
            .iter()
            .copied()
            .filter(|&i| self.w[i] < NEGLIGIBLE_SHARE)
            .collect();
        let rest: f64 = support
            .iter()
            .filter(|i| !small.contains(i))
            .map(|&i| self.w[i])
            .sum();
        if small.is_empty() || !(rest > 0.0) {
            return;
        }
        let w: Vec<f64> = (0..self.w.len())
            .map(|i| {
                if small.contains(&i) {
                    0.0
                } else {
                    self.w[i] / rest
                }
            })
            .collect();
        self.evaluations.tick();
        if let Some(c) = value_at(self.plan, self.criterion, self.tones, &w, None) {
            if c.1 <= self.best.1 + DECREMENT {
                support.retain(|i| !small.contains(i));
                self.w = w;
                self.best = c;
            }
        }
    }
}

/// The multisine design of `plan` under `criterion` (see the module docs).
///
/// # Errors
///
/// The flat spectrum's prediction fails (an unknown parameter in the criterion, a singular
/// information matrix); no candidate meets the constraint (a peak bound that this band's
/// crest factors cannot hold with the power).
pub(crate) fn optimise_tones(
    plan: &Plan,
    criterion: &DesignCriterion,
    spec: &ToneDesignSpec,
) -> StudyResult<Optimum> {
    let base = plan.budget_design();
    let duration = base.samples as f64 * base.interval;
    let f0 = 1.0 / duration;
    let (first, last) = harmonics_in(spec.band, f0);
    let start = plan.baseline.grid.start();
    let tones = Tones {
        spec,
        f0,
        k: log_spaced_harmonics(first, last, spec.tones),
        span: (start, start + duration),
        base,
    };
    let file = &plan.baseline.file;
    let n = tones.k.len();
    let flat_shares = vec![1.0 / n as f64; n];
    // The flat spectrum: where the descent starts, and what tells a criterion that cannot be
    // evaluated at all.
    let flat = tones.multisine(&flat_shares, None).ok_or_else(|| {
        study_err!(
            "{file}: [design] peak: cannot hold the power {} with the flat spectrum's Schroeder phases over the band; expected a larger peak or a smaller power",
            spec.power.unwrap_or_default()
        )
    })?;
    let (p, v) = evaluate(plan, &tones.design(flat.clone()), criterion)
        .map_err(|e| study_err!("{file}: [design] band: the flat spectrum over the band: {e}"))?;
    let evaluations = Evaluations {
        plan,
        count: AtomicUsize::new(0),
    };
    evaluations.tick();
    // Where the descent starts: the flat spectrum, and the design of a user who ignores the
    // jitter (cheap: its information has no jitter noise), whose support the jitter-aware
    // criterion often keeps. The criterion under jitter is not convex in the shares, so each
    // start is descended and exchanged and the best result is kept (ties to the first:
    // deterministic).
    let mut starts = vec![(flat_shares, (tones.design(flat), v, p))];
    if !plan.is_jitter_blind() {
        if let Some(w) = blind_shares(plan, criterion, spec, &tones) {
            evaluations.tick();
            if let Some(c) = value_at(plan, criterion, &tones, &w, None) {
                starts.push((w, c));
            }
        }
    }
    let mut results = Vec::with_capacity(starts.len());
    for (w, c) in starts {
        let mut support: Vec<usize> = (0..n).filter(|&i| w[i] > 0.0).collect();
        let mut search = Descent {
            plan,
            criterion,
            tones: &tones,
            evaluations: &evaluations,
            best: c,
            w,
        };
        // Scouting descents find the support (a full descent on a support that the exchange
        // then changes is wasted work), full ones the shares on it.
        search.descend(&support, Depth::Scout);
        search.exchange(&mut support, Depth::Scout);
        search.descend(&support, Depth::Full);
        search.exchange(&mut support, Depth::Full);
        results.push((search.w, search.best));
    }
    let (w, best) = results
        .into_iter()
        .reduce(|a, b| if b.1 .1 < a.1 .1 { b } else { a })
        .ok_or_else(|| study_err!("{file}: [design] band: no start for the search"))?;
    let mut chosen = choose_phases(plan, criterion, &tones, &evaluations, &w, best);
    // The tones the design gives no power are not part of it.
    if let Some(m) = &mut chosen.0.multisine {
        *m = m.without_silent_tones();
    }
    // The file's own multisine, when it meets the constraint.
    let own = plan.baseline_design();
    if let Some(m) = &own.multisine {
        let meets_power = spec.power.is_none_or(|p| (m.power - p).abs() <= 1e-9 * p);
        let meets_peak = spec.peak.is_none_or(|a| m.peak() <= a);
        let same_record = own.samples == chosen.0.samples && own.interval == chosen.0.interval;
        if meets_power && meets_peak && same_record {
            evaluations.tick();
            if let Ok((p, v)) = evaluate(plan, &own, criterion) {
                if v < chosen.1 {
                    chosen = (own, v, p);
                }
            }
        }
    }
    Ok(Optimum {
        design: chosen.0,
        value: chosen.1,
        prediction: chosen.2,
        evaluations: evaluations.count.into_inner(),
    })
}

#[cfg(test)]
mod tests {
    use super::log_spaced_harmonics;

    #[test]
    fn harmonics_are_distinct_increasing_and_in_range() {
        for (a, b, k) in [(1, 100, 8), (3, 12, 10), (5, 5, 1), (1, 3, 5), (2, 1000, 1)] {
            let h = log_spaced_harmonics(a, b, k);
            assert_eq!(h.len(), k.min((b - a + 1) as usize));
            assert!(h.windows(2).all(|p| p[0] < p[1]), "{h:?}");
            assert!(h.iter().all(|x| (a..=b).contains(x)), "{h:?}");
        }
    }
}
