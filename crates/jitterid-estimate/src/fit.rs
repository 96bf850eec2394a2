//! The one entry point: [`estimate`] a model structure from a record with a criterion and a
//! solver, with the asymptotic covariance of the estimate.

use crate::boundary::{bound_params, positive_params, settle_at_bounds};
use crate::covariance::sandwich;
use crate::criterion::Criterion;
use crate::data::Record;
use crate::edges::{candidate_edges, settle_on_edge, EdgeKind, EdgeOutcome};
use crate::evaluation_memo::{EvaluationMemo, MEMO_MAX_SAMPLES};
use crate::even_widths::add_even_curvature;
use crate::frequency_data::FrequencyData;
use crate::noise::NoiseModel;
use crate::result::{CostKind, Fit};
use crate::solver::{LeastSquares, NormalEquations, Solver, SolverError, SolverReport};
use crate::structure::ModelStructure;
use crate::EstimateError;
use faer::Mat;
use jitterid_jitter::JitterModel;
use jitterid_numeric::budget;
use jitterid_signal::{SampleGrid, Signal};
use jitterid_window::{FrequencySet, Window};

/// Which frequencies a criterion uses.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Frequencies {
    /// The DFT grid `j/(NT)`, `0 ≤ j ≤ N/2` (the default).
    Dft,
    /// The DFT-grid points in `[min, max]` Hz.
    Band {
        /// Lowest frequency (Hz).
        min: f64,
        /// Highest frequency (Hz).
        max: f64,
    },
    /// Any list of frequencies in `[0, 1/T)`.
    List(Vec<f64>),
}

impl Frequencies {
    /// The validated set for a record.
    pub fn resolve(&self, record: &Record) -> Result<FrequencySet, EstimateError> {
        let grid = record.grid();
        Ok(match self {
            Frequencies::Dft => FrequencySet::dft(grid),
            Frequencies::Band { min, max } => FrequencySet::band(grid, *min, *max)?,
            Frequencies::List(f) => FrequencySet::list(grid, f.clone())?,
        })
    }
}

/// The typed options of [`estimate`]: what [`FitOptions`](crate::FitOptions) resolves to
/// for a first-moment criterion, with the solver and window as types so that the search is
/// monomorphised.
#[derive(Debug, Clone)]
pub(crate) struct MomentOptions<V, W> {
    /// The frequency set.
    pub frequencies: Frequencies,
    /// The window (taper) of the DTFT.
    pub window: W,
    /// The solver.
    pub solver: V,
    /// Whether to compute the asymptotic covariance.
    pub covariance: bool,
}

/// Relative residual size below which a fit is exact to rounding and not checked for flatness.
const EXACT_FIT: f64 = 1e-9;

/// A criterion and its data as a [`LeastSquares`] problem in the structure's free parameters.
///
/// A parameter vector outside the model's domain (an unstable pole, `a ≤ 0`, …) gives NaN
/// residuals, which the solvers treat as a rejected trial point. On short records the last
/// evaluated point is memoised (see [`FitProblem::new`]).
#[derive(Debug)]
pub struct FitProblem<'a, S, J, N, C: ?Sized, W> {
    /// The structure at the start (fixed parts and the template for `with_params`).
    pub structure: &'a ModelStructure<S, J, N>,
    /// The criterion.
    pub criterion: &'a C,
    /// The data.
    pub data: &'a FrequencyData<W>,
    memo: EvaluationMemo<ModelStructure<S, J, N>>,
    /// The free parameters that are even jitter widths ([`crate::even_widths`]).
    even: Vec<usize>,
}

impl<'a, S, J, N, C: ?Sized, W> FitProblem<'a, S, J, N, C, W>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    /// The problem of fitting `structure`'s free parameters to `data` by `criterion`.
    ///
    /// On records of up to a few thousand samples the residuals of the last point evaluated
    /// are kept, with the time-domain sensitivities computed in the same pass, so that the
    /// normal equations that a solver asks for next at that point (and a repeated residual
    /// evaluation) cost no second pass over the model. The results are the same numbers as
    /// without it.
    pub fn new(
        structure: &'a ModelStructure<S, J, N>,
        criterion: &'a C,
        data: &'a FrequencyData<W>,
    ) -> Self {
        let (ns, nj, _) = structure.blocks();
        let even = if nj > 0 {
            structure
                .jitter
                .even_params()
                .iter()
                .enumerate()
                .filter(|(_, &e)| e)
                .map(|(j, _)| ns + j)
                .collect()
        } else {
            Vec::new()
        };
        FitProblem {
            structure,
            criterion,
            data,
            memo: EvaluationMemo::default(),
            even,
        }
    }

    /// The time-domain sensitivities at `theta` if the last evaluation was there.
    pub(crate) fn memoised_sensitivities(&self, theta: &[f64]) -> Option<Vec<Vec<f64>>> {
        self.memo.sensitivities(theta)
    }
}

impl<S, J, N, C, W> FitProblem<'_, S, J, N, C, W>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: ?Sized,
    W: Window,
{
    /// The structure at `theta` if it lies in the model's domain: parameters that its
    /// constructors accept and a jitter whose reach fits in the record
    /// ([`reach_beyond`]). Outside it the residuals are NaN, which a solver treats as a point to
    /// step back from.
    fn model_at(&self, theta: &[f64]) -> Option<ModelStructure<S, J, N>> {
        self.structure
            .with_params(theta)
            .ok()
            .filter(|m| reach_beyond(&m.jitter, self.data.record().grid()).is_none())
    }
}

impl<S, J, N, C, W> LeastSquares for FitProblem<'_, S, J, N, C, W>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    fn num_params(&self) -> usize {
        self.structure.num_params()
    }

    fn num_residuals(&self) -> usize {
        self.data.num_residuals()
    }

    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        if let Some(r) = self.memo.residuals(theta) {
            return Ok(r);
        }
        let Some(m) = self.model_at(theta) else {
            return Ok(vec![f64::NAN; self.num_residuals()]);
        };
        if self.data.record().y().len() > MEMO_MAX_SAMPLES {
            return Ok(self.data.residuals(self.criterion, &m));
        }
        let (r, sensitivities) =
            if crate::parseval::parseval_weight(self.criterion, self.data, &m).is_some() {
                let (values, cols) =
                    crate::parseval::moment_and_sensitivities(self.criterion, self.data, &m);
                let r = self.data.residuals_of_moment(self.criterion, &m, values);
                (r, Some(cols))
            } else {
                (self.data.residuals(self.criterion, &m), None)
            };
        self.memo.store(theta, &r, sensitivities, m);
        Ok(r)
    }

    fn jacobian(&self, theta: &[f64]) -> Result<Mat<f64>, SolverError> {
        Ok(match self.model_at(theta) {
            Some(m) => self.data.jacobian(self.criterion, &m),
            None => Mat::from_fn(self.num_residuals(), self.num_params(), |_, _| f64::NAN),
        })
    }

    fn normal_equations(
        &self,
        theta: &[f64],
        residuals: &[f64],
    ) -> Result<NormalEquations, SolverError> {
        // The model the residuals just built at this point, when they did.
        let model = match self.memo.take_model(theta) {
            Some(m) => Some(m),
            None => self.model_at(theta),
        };
        Ok(match model {
            Some(m) => {
                let mut ne = crate::parseval::criterion_normal_equations(
                    self.criterion,
                    self.data,
                    &m,
                    residuals,
                    self.memo.sensitivities(theta),
                );
                add_even_curvature(&mut ne, theta, &self.even);
                ne
            }
            None => NormalEquations::not_finite(self.num_params()),
        })
    }
}

/// The solver's search from `start`, with the domain's edges: a width that went to 0 stalls
/// the solver at the edge, and a search may stop short of an edge it was heading for (a width
/// creeping to 0, a pole pushed onto the axis); the edge is the answer when it is a constrained
/// minimum, and otherwise the search goes on from the point on the edge it reached (at most
/// [`EDGE_ROUNDS`] times). Returns the report, the parameters held on their edge, and the one
/// held on the stability boundary, if any.
fn search<P, V>(
    problem: &P,
    structure: &ModelStructure<impl Signal + Clone, impl JitterModel + Clone, impl NoiseModel>,
    solver: &V,
    start: &[f64],
) -> Result<(SolverReport, Vec<usize>, Option<usize>), EstimateError>
where
    P: LeastSquares,
    V: Solver<P>,
{
    let positive = positive_params(structure);
    let mut from = start.to_vec();
    // Iterations of the rounds before the current one.
    let mut before = 0;
    let total = |r: SolverReport, before: u64| SolverReport {
        iterations: before + r.iterations,
        ..r
    };
    // Ends: the last round tries no edge, so it ends as `Nothing` at the latest.
    let mut round = 0;
    loop {
        let report = solver.minimize(problem, &from)?;
        let held = bound_params(&report, start, &positive);
        // Its iterations include the refit's.
        let report = settle_at_bounds(problem, report, &held)?;
        let edges = if round < EDGE_ROUNDS {
            candidate_edges(structure, &report, start, &positive)
        } else {
            Vec::new()
        };
        match settle_on_edge(problem, &report, &edges)? {
            EdgeOutcome::AtEdge(settled, edge, kind) => {
                let on_axis = (kind == EdgeKind::Axis).then_some(edge.index);
                return Ok((total(settled, before), vec![edge.index], on_axis));
            }
            EdgeOutcome::Inside(settled) => {
                before += settled.iterations;
                from = settled.params;
                round += 1;
            }
            EdgeOutcome::Nothing => return Ok((total(report, before), held, None)),
        }
    }
}

/// How many times a search goes on from an edge it stopped against (see [`search`]).
const EDGE_ROUNDS: usize = 3;

/// The jitter's reach `(lo, hi)` and the grid's duration when the reach does not fit in the
/// record (not finite, or wider than the duration): outside the model's domain for every
/// criterion ([`EstimateError::ReachExceedsRecord`], `MlError::ReachExceedsRecord`).
pub fn reach_beyond<J: JitterModel + ?Sized>(
    jitter: &J,
    grid: &SampleGrid,
) -> Option<(f64, f64, f64)> {
    let (lo, hi) = jitter.reach();
    let duration = grid.duration();
    (!(lo.is_finite() && hi.is_finite()) || hi - lo > duration).then_some((lo, hi, duration))
}

/// Estimates the free parameters of `structure` from `record` by minimising `criterion` with
/// `options.solver`, starting from the structure's current parameters: what
/// [`fit`](crate::fit) runs for a first-moment criterion.
///
/// # Errors
///
/// No free parameter; a criterion that ignores jitter asked to estimate it; fewer samples or
/// residuals than parameters; a jitter whose reach is wider than the record; an invalid
/// frequency set or weights; a criterion not finite at the start; invalid solver options. A search that stops without converging is not an error:
/// see [`Fit::converged`] and [`Fit::termination`].
///
/// `criterion` may be a trait object (`&dyn Criterion`, `Box<dyn Criterion>`); `options.solver`
/// any solver of least-squares problems (see [`Solver`]).
pub(crate) fn estimate<S, J, N, C, V, W>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &MomentOptions<V, W>,
) -> Result<Fit, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    V: for<'a> Solver<FitProblem<'a, S, J, N, C, W>>,
    W: Window + Clone,
{
    let p = structure.num_params();
    if p == 0 {
        return Err(EstimateError::NothingToEstimate);
    }
    if structure.estimate_jitter && !criterion.models_jitter() {
        return Err(EstimateError::JitterNotModelled {
            criterion: criterion.name(),
        });
    }
    if record.y().len() < p {
        return Err(EstimateError::TooFewData {
            what: "samples",
            available: record.y().len(),
            params: p,
        });
    }
    let freqs = options.frequencies.resolve(record)?;
    criterion.validate(&freqs)?;
    let data = FrequencyData::new(record.clone(), options.window.clone(), freqs)?;
    if data.num_residuals() < p {
        return Err(EstimateError::TooFewData {
            what: "residuals",
            available: data.num_residuals(),
            params: p,
        });
    }
    if let Some((lo, hi, duration)) = reach_beyond(&structure.jitter, record.grid()) {
        return Err(EstimateError::ReachExceedsRecord { lo, hi, duration });
    }
    let problem = FitProblem::new(structure, criterion, &data);
    let start = structure.params();
    // Through the problem, so that the solver's first evaluation at the start is memoised.
    let r0 = problem.residuals(&start)?;
    // A budget spent already (a time limit of 0, a cancel before the start was evaluated)
    // leaves the start unevaluated: the fit stops there, as a solver would at its first check.
    if let Some(stop) = jitterid_optim::budget_termination() {
        return Ok(Fit {
            criterion: criterion.name().to_string(),
            names: structure.param_names(),
            params: start,
            covariance: None,
            std_errors: None,
            cost: f64::NAN,
            cost_kind: CostKind::SumOfSquares,
            iterations: 0,
            termination: stop.into(),
            converged: false,
            residuals: Vec::new(),
            noise_std: structure.noise_std.unwrap_or(f64::NAN),
            residual_flatness: None,
        });
    }
    if let Some((index, &value)) = r0.iter().enumerate().find(|(_, r)| !r.is_finite()) {
        return Err(EstimateError::NonFiniteAtStart { index, value });
    }
    drop(r0);
    let (report, held, on_axis) = search(&problem, structure, &options.solver, &start)?;
    let fitted = structure.with_params(&report.params)?;
    let residuals = problem.residuals(&report.params)?;
    let (mut covariance, noise_std) = if options.covariance && !budget::spent() {
        let known = problem.memoised_sensitivities(&report.params);
        sandwich(&data, &fitted, criterion, &held, known)
    } else {
        (None, fitted.noise_std.unwrap_or(f64::NAN))
    };
    // A budget spent in the search or in the covariance leaves the fit unfinished: its point
    // is reported, not converged, with the reason and without a covariance.
    let stopped = jitterid_optim::budget_termination();
    if stopped.is_some() {
        covariance = None;
    }
    let std_errors = covariance
        .as_ref()
        .map(|c: &Vec<Vec<f64>>| (0..p).map(|i| c[i][i].max(0.0).sqrt()).collect());
    // Residuals at the rounding level of the data (noise-free data fitted exactly) carry no
    // spectrum to judge.
    let data_power: f64 = data.dtft().iter().map(|y| y.norm_sqr()).sum();
    let exact = 2.0 * report.cost <= EXACT_FIT * EXACT_FIT * data_power;
    let residual_flatness = if criterion.flat_residuals() && !exact {
        crate::residual_flatness(&residuals)
    } else {
        None
    };
    // A converged fit that leaves a band of frequencies unexplained is not a solution.
    let (converged, termination) = match (stopped, residual_flatness) {
        (Some(stop), _) => (false, stop.into()),
        (None, Some(f)) if report.converged && f > crate::FLATNESS_LIMIT => {
            (false, crate::FitTermination::ResidualNotFlat)
        }
        _ => match on_axis {
            Some(i) => (
                report.converged,
                crate::FitTermination::AtStabilityBoundary {
                    params: vec![i],
                    names: structure
                        .param_names()
                        .into_iter()
                        .skip(i)
                        .take(1)
                        .collect(),
                },
            ),
            None => (report.converged, report.termination.into()),
        },
    };
    Ok(Fit {
        criterion: criterion.name().to_string(),
        names: structure.param_names(),
        params: report.params,
        covariance,
        std_errors,
        cost: report.cost,
        cost_kind: CostKind::SumOfSquares,
        iterations: report.iterations,
        termination,
        converged,
        residuals,
        noise_std,
        residual_flatness,
    })
}
