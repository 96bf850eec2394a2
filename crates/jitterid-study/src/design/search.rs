//! The design search: a deterministic minimisation of the criterion over the free design
//! variables within their ranges.
//!
//! The criterion of a random input is an average over a fixed set of seeded draws, so it is a
//! deterministic, piecewise smooth function of the design; it can have several minima (a dwell
//! that excites one mode against one that excites another). A grid over every free variable
//! finds the basin, and Brent's method ([`Brent`], the solvers' own) then refines each variable
//! in turn between the best grid point's neighbours. The dwell and the interval are scales
//! (seconds) whose useful ranges span decades, so they are gridded and refined on a log scale;
//! the random binary input's levels may be 0 or negative and are searched on a linear one (a
//! level's draws share their switch times, since a level does not enter the input's random
//! stream, so the criterion is smooth in it). The file's own design, when inside the ranges,
//! is a candidate beside the refined point. A design that cannot be evaluated (a dwell with too
//! many switches, a singular information matrix, levels `low = high` that never switch) counts
//! as infinitely bad; only a range without any evaluable design is an error.

use super::candidate::Design;
use super::criterion::criterion_value;
use super::plan::Plan;
use super::predict::Prediction;
use super::progress::DesignProgress;
use crate::error::{StudyError, StudyResult};
use crate::experiment::DesignCriterion;
use crate::study_err;
use jitterid::estimate::solver::{Brent, Objective, Solver};
use std::sync::Mutex;

/// Tolerance of the refinement on each variable: absolute in a scale's logarithm (a relative
/// tolerance on the scale), and relative to the range's width for a level.
const REFINE_TOLERANCE: f64 = 1e-3;

/// Iteration limit of each refinement.
const REFINE_ITERATIONS: u64 = 40;

/// The best design found and what was predicted there.
#[derive(Debug, Clone)]
pub struct Optimum {
    /// The design.
    pub design: Design,
    /// Its criterion value.
    pub value: f64,
    /// Its predicted precision.
    pub prediction: Prediction,
    /// Designs evaluated in the search.
    pub evaluations: usize,
}

/// A free variable.
#[derive(Debug, Clone, Copy)]
enum Var {
    MeanDwell,
    Low,
    High,
    Interval,
}

impl Var {
    /// The `[design]` key that frees it.
    fn key(self) -> &'static str {
        match self {
            Var::MeanDwell => "mean_dwell",
            Var::Low => "low",
            Var::High => "high",
            Var::Interval => "interval",
        }
    }

    /// Whether the search's coordinate is the variable's logarithm (a scale) rather than the
    /// variable itself (a level, which may be 0 or negative).
    fn is_log(self) -> bool {
        matches!(self, Var::MeanDwell | Var::Interval)
    }

    /// The search's coordinate of the value `x`.
    fn coordinate(self, x: f64) -> f64 {
        if self.is_log() {
            x.ln()
        } else {
            x
        }
    }

    /// The value at the search's coordinate `u`.
    fn value(self, u: f64) -> f64 {
        if self.is_log() {
            u.exp()
        } else {
            u
        }
    }

    /// The variable's value in `d` (NaN where `d` has none, which no range holds).
    fn of(self, d: &Design) -> f64 {
        match self {
            Var::MeanDwell => d.mean_dwell,
            Var::Low => d.low,
            Var::High => d.high,
            Var::Interval => Some(d.interval),
        }
        .unwrap_or(f64::NAN)
    }
}

/// What one evaluation gave: a value, or why the design is not feasible.
type Evaluated = Result<(f64, Prediction), StudyError>;

struct Search<'a> {
    plan: &'a Plan,
    criterion: &'a DesignCriterion,
    /// Every design evaluated, in order (the search is short: a linear memo suffices).
    memo: Mutex<Vec<(Design, Evaluated)>>,
    /// A criterion that cannot be evaluated at all (an unknown parameter's name).
    fatal: Mutex<Option<StudyError>>,
    /// Points of the grid, for the progress reports.
    grid_points: usize,
}

impl Search<'_> {
    /// The design at the search's coordinates `u` of `vars` ([`Var::coordinate`]), the other
    /// variables at `base`.
    fn design(&self, base: &Design, vars: &[Var], u: &[f64]) -> Design {
        let mut d = base.clone();
        for (&v, &x) in vars.iter().zip(u) {
            let x = v.value(x);
            match v {
                Var::MeanDwell => d.mean_dwell = Some(x),
                Var::Low => d.low = Some(x),
                Var::High => d.high = Some(x),
                Var::Interval => {
                    d.interval = x;
                    d.samples = self.plan.spec.budget.samples_at(d.interval);
                }
            }
        }
        d
    }

    /// The criterion at `d` (`+∞` where it is not feasible), memoised.
    fn value(&self, d: &Design) -> f64 {
        if let Some(v) = self.lookup(d) {
            return v;
        }
        let out = self.plan.predict(d);
        let out = match out {
            Ok(p) => match criterion_value(self.criterion, &p) {
                // A robust design's value is the criterion over the prior's draws.
                Ok(v) => self.plan.robust_value(d, self.criterion, v).map(|v| (v, p)),
                Err(e) => {
                    let mut fatal = self.fatal.lock().unwrap_or_else(|e| e.into_inner());
                    fatal.get_or_insert(e.clone());
                    Err(e)
                }
            },
            Err(e) => Err(e),
        };
        let v = match &out {
            Ok((v, _)) if !v.is_nan() => *v,
            _ => f64::INFINITY,
        };
        let evaluations = {
            let mut memo = self.memo.lock().unwrap_or_else(|e| e.into_inner());
            memo.push((d.clone(), out));
            memo.len()
        };
        self.plan.observe(DesignProgress::Evaluated {
            jitter_blind: self.plan.is_jitter_blind(),
            evaluations,
            grid_points: self.grid_points,
        });
        v
    }

    fn lookup(&self, d: &Design) -> Option<f64> {
        let memo = self.memo.lock().unwrap_or_else(|e| e.into_inner());
        memo.iter().find(|(m, _)| m == d).map(|(_, out)| match out {
            Ok((v, _)) if !v.is_nan() => *v,
            _ => f64::INFINITY,
        })
    }
}

/// One variable of the search as an objective of its coordinate, infinite outside `[lo, hi]`.
struct Line<'s, 'a> {
    search: &'s Search<'a>,
    base: Design,
    var: Var,
    lo: f64,
    hi: f64,
}

impl Objective for Line<'_, '_> {
    fn num_params(&self) -> usize {
        1
    }
    fn cost(&self, u: &[f64]) -> f64 {
        match u.first() {
            Some(&x) if x >= self.lo && x <= self.hi => {
                self.search
                    .value(&self.search.design(&self.base, &[self.var], &[x]))
            }
            _ => f64::INFINITY,
        }
    }
}

/// The best design under `criterion` over the plan's free variables (see the module docs).
///
/// # Errors
///
/// A criterion that names no estimated parameter; no design in the ranges that can be
/// evaluated (the message gives the first reason and names the `[design]` keys).
pub fn optimise(plan: &Plan, criterion: &DesignCriterion) -> StudyResult<Optimum> {
    // A multisine's tones are a power distribution, searched on the simplex instead.
    if let Some(tones) = &plan.spec.multisine {
        return super::multisine::optimise_tones(plan, criterion, tones);
    }
    let spec = &plan.spec;
    let free = [
        (Var::MeanDwell, spec.mean_dwell),
        (Var::Low, spec.low),
        (Var::High, spec.high),
        (Var::Interval, spec.interval),
    ];
    let (vars, ranges): (Vec<Var>, Vec<(f64, f64)>) = free
        .into_iter()
        .filter_map(|(v, r)| r.map(|(lo, hi)| (v, (v.coordinate(lo), v.coordinate(hi)))))
        .unzip();
    let base = plan.budget_design();
    // The grid: every combination of `spec.grid` points per variable, evenly spaced in its
    // coordinate (log-spaced for a scale).
    let g = spec.grid;
    let axis = |(lo, hi): (f64, f64)| -> Vec<f64> {
        (0..g)
            .map(|i| lo + (hi - lo) * i as f64 / (g - 1) as f64)
            .collect()
    };
    let axes: Vec<Vec<f64>> = ranges.iter().map(|&r| axis(r)).collect();
    let total: usize = axes.iter().map(Vec::len).product();
    let search = Search {
        plan,
        criterion,
        memo: Mutex::new(Vec::new()),
        fatal: Mutex::new(None),
        grid_points: total,
    };
    let mut best: Option<(f64, Vec<f64>)> = None;
    for flat in 0..total {
        let mut rest = flat;
        let u: Vec<f64> = axes
            .iter()
            .map(|a| {
                let x = a[rest % a.len()];
                rest /= a.len();
                x
            })
            .collect();
        let v = search.value(&search.design(&base, &vars, &u));
        if let Some(e) = search
            .fatal
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
        {
            return Err(e);
        }
        if v < best.as_ref().map_or(f64::INFINITY, |b| b.0) {
            best = Some((v, u));
        }
    }
    let Some((_, mut u)) = best else {
        return Err(infeasible(&search, &vars));
    };
    // Refine each variable between its best grid point's neighbours.
    let brent = Brent {
        tolerance: REFINE_TOLERANCE,
        max_iters: REFINE_ITERATIONS,
        from_bracket: true,
        ..Brent::default()
    };
    for (k, &var) in vars.iter().enumerate() {
        let (lo, hi) = ranges[k];
        let step = if g > 1 {
            (hi - lo) / (g - 1) as f64
        } else {
            0.0
        };
        if !(step > 0.0) {
            continue;
        }
        let line = Line {
            search: &search,
            base: search.design(&base, &vars, &u),
            var,
            lo: (u[k] - step).max(lo),
            hi: (u[k] + step).min(hi),
        };
        // A level's tolerance is relative to its range (its coordinate has no natural unit).
        let tolerance = if var.is_log() {
            REFINE_TOLERANCE
        } else {
            REFINE_TOLERANCE * (hi - lo)
        };
        let brent = Brent {
            bracket_step: step / 2.0,
            tolerance,
            ..brent.clone()
        };
        // A refinement that fails leaves the grid's point, which is already evaluated.
        if let Ok(report) = brent.minimize(&line, &[u[k]]) {
            if line.cost(&report.params) <= line.cost(&[u[k]]) {
                u[k] = report.params[0];
            }
        }
    }
    let design = search.design(&base, &vars, &u);
    search.value(&design);
    // The file's own design, where it lies in the ranges, is a candidate too (not a start of
    // the refinement: the criterion of a random input is bumpy on a small scale, and the
    // grid's basin is the better start): the result is then never worse than the baseline it
    // is compared with, whatever the grid's spacing.
    let own: Vec<f64> = vars.iter().map(|v| v.coordinate(v.of(&base))).collect();
    if own
        .iter()
        .zip(&ranges)
        .all(|(x, (lo, hi))| x >= lo && x <= hi)
    {
        search.value(&search.design(&base, &vars, &own));
    }
    let memo = search.memo.into_inner().unwrap_or_else(|e| e.into_inner());
    let evaluations = memo.len();
    // The best evaluated design (the refinement's last point is its best, but the memo
    // decides: ties go to the earliest).
    let mut chosen: Option<(Design, f64, Prediction)> = None;
    for (d, out) in memo {
        if let Ok((v, p)) = out {
            if v < chosen.as_ref().map_or(f64::INFINITY, |c| c.1) {
                chosen = Some((d, v, p));
            }
        }
    }
    let (design, value, prediction) = chosen.ok_or_else(|| {
        study_err!(
            "{}: [design]: no design could be evaluated",
            plan.baseline.file
        )
    })?;
    Ok(Optimum {
        design,
        value,
        prediction,
        evaluations,
    })
}

/// The error of a search without one feasible design: the first reason, and the keys.
fn infeasible(search: &Search, vars: &[Var]) -> StudyError {
    let mut keys: Vec<&str> = vars.iter().map(|v| v.key()).collect();
    // A budget narrows every design's record: it may be why none is feasible.
    keys.extend(search.plan.spec.budget_key);
    let memo = search.memo.lock().unwrap_or_else(|e| e.into_inner());
    let why = memo
        .iter()
        .find_map(|(_, out)| out.as_ref().err().map(|e| e.to_string()))
        .unwrap_or_else(|| "the criterion is infinite everywhere".into());
    study_err!(
        "{}: [design] {}: no feasible design in the given range: {why}",
        search.plan.baseline.file,
        keys.join(", ")
    )
}
