//! The multisine design: which tones, how much power in each, and which phases.
//!
//! The candidate frequencies are `[design] tones` harmonics of `f0 = 1/(N T)` spread
//! log-uniformly over `[design] band` (so the input is periodic over the record). A design is
//! a power distribution `w` on the simplex over them: amplitudes `aᵢ = √(2 P wᵢ)` under a
//! power constraint (`Σ aᵢ²/2 = P` exactly), or scaled so that the peak is exactly the bound
//! under an amplitude constraint alone. Without jitter the information would be linear in `w`
//! and the classical multiplicative algorithms would apply; with jitter the noise after every
//! slope (`σ_τ² s′(t)²`) makes it nonlinear, so every candidate is judged by the exact
//! prediction ([`evaluate`]). `w` is the softmax of unconstrained coordinates `x`
//! (`wᵢ = e^{xᵢ} / Σ e^{xⱼ}`, `x₀ = 0`), which keeps it on the simplex and positive, and the
//! criterion is minimised over `x` by the solvers' BFGS ([`Bfgs`], which takes an infeasible
//! candidate as `+∞`) from the flat spectrum, with central differences whose components are
//! evaluated in parallel: a deterministic descent that accepts only steps that lower the
//! criterion.
//!
//! During the descent the phases are Schroeder's for the current `w` (a smooth function of
//! it, so the differences are smooth); at the end the clipping algorithm lowers the crest
//! factor ([`low_crest_phases`]) and the result is evaluated again. The file's own multisine,
//! when it meets the constraint, is a candidate beside it, so the result is never worse than
//! the baseline it is compared with.

use super::blind::evaluate;
use super::candidate::Design;
use super::crest::{harmonic_tones, low_crest_phases, peak, rms, schroeder_phases};
use super::plan::Plan;
use super::predict::Prediction;
use super::progress::DesignProgress;
use super::search::Optimum;
use crate::error::StudyResult;
use crate::experiment::{harmonics_in, DesignCriterion, ToneDesignSpec};
use crate::study_err;
use jitterid::estimate::solver::{Bfgs, Objective, Solver};
use jitterid::signal::Tone;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};

/// BFGS iterations on the power distribution.
const ITERATIONS: u64 = 40;

/// Step in `xᵢ = log wᵢ + const` of the central differences: large enough that a criterion
/// computed by quadrature (exact ML's Fisher information) does not turn the gradient into
/// noise, small enough that the differences' own error (second order) is negligible.
const DIFFERENCE: f64 = 1e-3;

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

/// The power shares of coordinates `x`: the softmax of `(0, x₁, …)`.
fn shares(x: &[f64]) -> Vec<f64> {
    let top = x.iter().copied().fold(0.0, f64::max);
    let e: Vec<f64> = std::iter::once(0.0)
        .chain(x.iter().copied())
        .map(|xi| (xi - top).exp())
        .collect();
    let sum: f64 = e.iter().sum();
    e.iter().map(|ei| ei / sum).collect()
}

/// The criterion as a function of the softmax coordinates of the power shares.
struct Shares<'s, 'a> {
    plan: &'s Plan,
    criterion: &'s DesignCriterion,
    tones: &'s Tones<'a>,
    evaluations: &'s Evaluations<'s>,
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
        self.tones.k.len() - 1
    }

    fn cost(&self, x: &[f64]) -> f64 {
        self.evaluations.tick();
        value_at(self.plan, self.criterion, self.tones, &shares(x), None)
            .map_or(f64::INFINITY, |c| c.1)
    }

    /// Central differences, the components in parallel (one-sided beside an infeasible
    /// point).
    fn cost_gradient(&self, x: &[f64]) -> (f64, Vec<f64>) {
        let f = self.cost(x);
        let g = (0..x.len())
            .into_par_iter()
            .map(|j| {
                let at = |h: f64| {
                    let mut y = x.to_vec();
                    y[j] += h;
                    self.cost(&y)
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
    let mut best: Candidate = (tones.design(flat), v, p);
    let mut w = flat_shares;
    if n > 1 {
        let objective = Shares {
            plan,
            criterion,
            tones: &tones,
            evaluations: &evaluations,
        };
        let bfgs = Bfgs {
            max_iters: ITERATIONS,
            decrement_tol: DECREMENT,
            initial_step: 0.5,
            ..Bfgs::default()
        };
        // A descent that fails leaves the best point so far, which is already evaluated.
        let mut x = vec![0.0; n - 1];
        for _ in 0..=RESTARTS {
            let Ok(r) = bfgs.minimize(&objective as &dyn Objective, &x) else {
                break;
            };
            let moved = shares(&r.params);
            match value_at(plan, criterion, &tones, &moved, None) {
                Some(c) if c.1 < best.1 => {
                    w = moved;
                    best = c;
                    x = r.params;
                }
                _ => break,
            }
        }
    }
    // The phases that lower the crest factor, at the chosen power shares.
    let amplitudes: Vec<f64> = w.iter().map(|wi| wi.sqrt()).collect();
    let phases = low_crest_phases(&tones.k, &amplitudes);
    evaluations.tick();
    // The delivered design has these phases (the constraint is on power or peak, and the
    // phases are chosen for the crest factor), unless they break the peak bound.
    let mut chosen = value_at(plan, criterion, &tones, &w, Some(&phases)).unwrap_or(best);
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
