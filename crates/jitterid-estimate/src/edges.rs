//! Searches that stop short of a domain edge they are heading for: a jitter width creeping
//! towards 0 until the iteration limit, a pole pushed onto the imaginary axis (the edge of the
//! stable models when `unstable` is not set). The edge is tried as the answer: the parameter is
//! held on it, the others refitted, and the result kept when it is a constrained minimum.
//!
//! Why this is separate from [`boundary`](crate::boundary): there the solver has already put
//! the parameter below [`BOUND_FRACTION`] of its start, and holding it is enough. Here the
//! solver stopped elsewhere: a width's criterion depends on it through its square, so its
//! Jacobian column vanishes at 0 and Levenberg–Marquardt approaches 0 only linearly (some
//! records stop at the iteration limit with the width at a tenth of its start); a pole on the
//! axis stops the search at its first refused step, wherever the other parameters are.

use crate::boundary::{converged_inside, settle_at_bounds, BOUND_FRACTION};
use crate::noise::NoiseModel;
use crate::solver::{LeastSquares, SolverError, SolverReport, Termination};
use crate::structure::ModelStructure;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;

/// A width below this fraction of its start when the search stopped is tried at its bound. On
/// its way to 0 Levenberg–Marquardt shrinks a width by a roughly constant factor per
/// iteration, so one that the iteration limit leaves at a tenth of its start is a slow search
/// in the interior, not an edge (and its refit on the edge can wander where the model is costly
/// to evaluate: a pair of poles near coincidence).
const WIDTH_EDGE: f64 = 1e-3;

/// A system parameter within this fraction of its start's scale (at least 1) of 0 when every
/// nearby step was refused is tried on the axis. Only there: holding a pole's real part at 0
/// from far away puts a lightly damped pair on the axis, whose response costs the realisation
/// `|p|/|Re p|` quadrature nodes, for a refit that the cost test would then reject.
const AXIS_EDGE: f64 = 1e-3;

/// A parameter's edge: the value it is held at, and the sign of the steps that stay inside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Edge {
    /// Index of the free parameter.
    pub index: usize,
    /// The value it is held at on the edge.
    pub value: f64,
    /// `+1` when the domain lies above the edge, `−1` when below.
    pub inside: f64,
}

/// Which edge a search reached: a positive width's (jitter or noise shape, held at
/// [`BOUND_FRACTION`] of its start), or the stability boundary of the system (a system
/// parameter held at 0 with a pole on the imaginary axis).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EdgeKind {
    /// A jitter or noise-shape width at 0.
    Width,
    /// A system parameter at 0 that puts a pole on the imaginary axis.
    Axis,
}

/// The edges a fit that stopped at `report` (the iteration limit, every nearby step refused,
/// or converged) may be heading for: positive widths below [`WIDTH_EDGE`] of their start,
/// and, when every nearby step was refused, system parameters near 0 ([`AXIS_EDGE`])
/// for which 0 is in the domain and one side of 0 is not.
pub(crate) fn candidate_edges<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    report: &SolverReport,
    start: &[f64],
    positive: &[bool],
) -> Vec<(Edge, EdgeKind)>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let stalled = matches!(
        report.termination,
        Termination::NonFinite | Termination::MaxIterations
    );
    // A search that converged with a width next to 0 may have stopped there on its
    // cost-change test while the width was still shrinking towards the bound (each step then
    // changes the criterion by the square of a small width): the bound is tried too, and kept
    // only when it is a constrained minimum no worse than where the search stopped.
    if !stalled && !converged_inside(&report.termination) {
        return Vec::new();
    }
    let (ns, _, _) = structure.blocks();
    let theta = &report.params;
    let valid_with = |i: usize, v: f64| {
        let mut t = theta.clone();
        t[i] = v;
        structure.with_params(&t).is_ok()
    };
    let mut out = Vec::new();
    for i in 0..theta.len() {
        if positive.get(i).copied().unwrap_or(false) && theta[i] <= WIDTH_EDGE * start[i] {
            let edge = Edge {
                index: i,
                // Never above where the search stopped: the bound's refit must not cost more
                // than the point it replaces for being held further out.
                value: (BOUND_FRACTION * start[i]).min(theta[i]),
                inside: 1.0,
            };
            out.push((edge, EdgeKind::Width));
        } else if stalled
            && i < ns
            && report.termination == Termination::NonFinite
            && theta[i].abs() <= AXIS_EDGE * start[i].abs().max(1.0)
            && valid_with(i, 0.0)
        {
            // A step of a millionth of the parameter's scale past 0: refused on one side only
            // for a coefficient (or a pole's real part) that puts a pole on the axis at 0.
            let h = 1e-6 * start[i].abs().max(theta[i].abs()).max(1.0);
            match (valid_with(i, h), valid_with(i, -h)) {
                (true, false) => out.push((
                    Edge {
                        index: i,
                        value: 0.0,
                        inside: 1.0,
                    },
                    EdgeKind::Axis,
                )),
                (false, true) => out.push((
                    Edge {
                        index: i,
                        value: 0.0,
                        inside: -1.0,
                    },
                    EdgeKind::Axis,
                )),
                _ => {}
            }
        }
    }
    out
}

/// What the edges of a stopped search give: a constrained minimum on one of them, or a point
/// on an edge from which the criterion falls back into the domain (the search stopped only
/// because its first steps pointed out of it: it goes on from there), or nothing.
#[derive(Debug)]
pub(crate) enum EdgeOutcome {
    /// Converged on the edge: the refit, and the edge.
    AtEdge(SolverReport, Edge, EdgeKind),
    /// The refit on an edge whose slope points inside: a feasible point to search on from.
    Inside(SolverReport),
    /// No edge gives a refit no worse than where the search stopped.
    Nothing,
}

/// Tries each edge in turn: the parameter held on it, the others refitted from `report`. A
/// refit counts when it converged at a cost no higher than where the search stopped; the best
/// such (lowest cost) on an edge that is a constrained minimum (the criterion's slope in the
/// parameter points out of the domain, or is 0) is [`EdgeOutcome::AtEdge`], otherwise the best
/// other one is [`EdgeOutcome::Inside`].
///
/// # Errors
///
/// Those of the solver.
pub(crate) fn settle_on_edge<P: LeastSquares + ?Sized>(
    problem: &P,
    report: &SolverReport,
    edges: &[(Edge, EdgeKind)],
) -> Result<EdgeOutcome, SolverError> {
    let mut best: Option<(SolverReport, Edge, EdgeKind)> = None;
    let mut inside: Option<SolverReport> = None;
    for &(edge, kind) in edges {
        let mut params = report.params.clone();
        params[edge.index] = edge.value;
        let residuals = problem.residuals(&params)?;
        if !residuals.iter().all(|r| r.is_finite()) {
            continue;
        }
        let cost = 0.5 * residuals.iter().map(|r| r * r).sum::<f64>();
        let moved = SolverReport {
            params,
            cost,
            ..report.clone()
        };
        let settled = settle_at_bounds(problem, moved, &[edge.index])?;
        if !settled.converged || !(settled.cost <= report.cost) {
            continue;
        }
        // The constrained minimum's condition: the cost does not fall into the domain.
        let r = problem.residuals(&settled.params)?;
        let slope = problem.normal_equations(&settled.params, &r)?.gradient[edge.index];
        if !(slope * edge.inside >= 0.0) {
            if inside.as_ref().is_none_or(|b| settled.cost < b.cost) {
                inside = Some(settled);
            }
            continue;
        }
        if best.as_ref().is_none_or(|(b, _, _)| settled.cost < b.cost) {
            best = Some((settled, edge, kind));
        }
    }
    Ok(match (best, inside) {
        (Some((report, edge, kind)), _) => EdgeOutcome::AtEdge(report, edge, kind),
        (None, Some(report)) => EdgeOutcome::Inside(report),
        (None, None) => EdgeOutcome::Nothing,
    })
}
