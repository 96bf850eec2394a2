//! Joint fits: several records of one system — each with its own input, `T` and `N` — fitted
//! with one criterion summed over the records (as a system-identification toolbox's `merge`).
//!
//! Each record keeps its own [`FrequencyData`] and its own structure (the same model driven by
//! that record's input); the parameters are shared. A record's DTFT residuals grow as `√N`
//! (`E|D(f)|² = Σ_k λ_k`), so each record's residuals are scaled by `1/√N_i`: the summed cost
//! then weighs every sample alike, as one long record would, whatever the records' lengths.
//! The normal equations are the scaled sums of the records' (Levenberg–Marquardt sees one
//! problem), and the covariance the sandwich of the summed bread and meat: the records are
//! independent, so their information adds.

use crate::covariance::{sandwich_of, sandwich_parts};
use crate::criterion::Criterion;
use crate::fit::{FitProblem, MomentOptions};
use crate::frequency_data::FrequencyData;
use crate::measured::{InputLayout, MeasuredRecord};
use crate::noise::NoiseModel;
use crate::options::FitOptions;
use crate::result::{CostKind, Fit};
use crate::solver::{LeastSquares, NormalEquations, Solver, SolverError};
use crate::structure::ModelStructure;
use crate::EstimateError;
use faer::Mat;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;
use jitterid_window::Window;

/// `c · m`.
fn scaled(m: &Mat<f64>, c: f64) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| c * m[(i, j)])
}

/// The records' problems as one least-squares problem in the shared parameters.
#[derive(Debug)]
pub struct JointProblem<'a, S, J, N, C: ?Sized, W> {
    parts: Vec<FitProblem<'a, S, J, N, C, W>>,
    /// `1/N_i`: the factor on each record's cost.
    scales: Vec<f64>,
}

impl<S, J, N, C, W> JointProblem<'_, S, J, N, C, W> {
    /// The records' problems, in order.
    pub fn parts(&self) -> &[FitProblem<'_, S, J, N, C, W>] {
        &self.parts
    }
}

impl<S, J, N, C, W> LeastSquares for JointProblem<'_, S, J, N, C, W>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    fn num_params(&self) -> usize {
        self.parts[0].num_params()
    }

    fn num_residuals(&self) -> usize {
        self.parts.iter().map(LeastSquares::num_residuals).sum()
    }

    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        let mut r = Vec::with_capacity(self.num_residuals());
        for (part, c) in self.parts.iter().zip(&self.scales) {
            let root = c.sqrt();
            r.extend(part.residuals(theta)?.into_iter().map(|x| x * root));
        }
        Ok(r)
    }

    fn jacobian(&self, theta: &[f64]) -> Result<Mat<f64>, SolverError> {
        let blocks = self
            .parts
            .iter()
            .map(|p| p.jacobian(theta))
            .collect::<Result<Vec<_>, _>>()?;
        let rows: usize = blocks.iter().map(|b| b.nrows()).sum();
        let mut j = Mat::zeros(rows, self.num_params());
        let mut at = 0;
        for (b, scale) in blocks.iter().zip(&self.scales) {
            let root = scale.sqrt();
            for i in 0..b.nrows() {
                for c in 0..b.ncols() {
                    j[(at + i, c)] = root * b[(i, c)];
                }
            }
            at += b.nrows();
        }
        Ok(j)
    }

    fn normal_equations(
        &self,
        theta: &[f64],
        residuals: &[f64],
    ) -> Result<NormalEquations, SolverError> {
        if residuals.len() != self.num_residuals() {
            return Err(SolverError::ResidualLength {
                expected: self.num_residuals(),
                got: residuals.len(),
            });
        }
        let p = self.num_params();
        let mut sum = NormalEquations {
            gram: Mat::zeros(p, p),
            gradient: vec![0.0; p],
        };
        let mut at = 0;
        for (part, &c) in self.parts.iter().zip(&self.scales) {
            let m = part.num_residuals();
            // The record's own residuals are the scaled ones over √c.
            let root = c.sqrt();
            let own: Vec<f64> = residuals[at..at + m].iter().map(|r| r / root).collect();
            let ne = part.normal_equations(theta, &own)?;
            at += m;
            sum.gram = &sum.gram + &scaled(&ne.gram, c);
            for (s, g) in sum.gradient.iter_mut().zip(&ne.gradient) {
                *s += c * g;
            }
        }
        Ok(sum)
    }
}

/// Checks that records fitted jointly belong to one system: at least one record, one structure
/// per record with the same free parameters, and the same input layout in every record.
///
/// # Errors
///
/// [`EstimateError::JointRecords`] naming the record that differs and how.
pub fn check_joint<S, J, N>(
    structures: &[ModelStructure<S, J, N>],
    records: &[MeasuredRecord],
) -> Result<(), EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let bad = |record: &str, message: String| EstimateError::JointRecords {
        record: record.to_string(),
        message,
    };
    let Some(first) = records.first() else {
        return Err(bad("", "a joint fit needs at least one record".into()));
    };
    if structures.len() != records.len() {
        return Err(bad(
            "",
            format!(
                "{} structures for {} records: one structure per record",
                structures.len(),
                records.len()
            ),
        ));
    }
    let names = structures[0].param_names();
    let layout: InputLayout = first.input_layout();
    for (s, r) in structures.iter().zip(records).skip(1) {
        if r.input_layout() != layout {
            return Err(bad(
                r.name(),
                format!(
                    "has {}, the first record ({}) {}: records of different systems",
                    r.input_layout(),
                    first.name(),
                    layout
                ),
            ));
        }
        if s.param_names() != names {
            return Err(bad(
                r.name(),
                format!(
                    "its model has the parameters {:?}, the first record's {:?}",
                    s.param_names(),
                    names
                ),
            ));
        }
    }
    Ok(())
}

/// Estimates the shared free parameters of several records of one system: `structures[i]` is
/// the model driven by `records[i]`'s input (for example the signal rebuilt with
/// [`AnySignal::with_input`](jitterid_signal::AnySignal::with_input)), all with the same free
/// parameters, started from the first structure's. The criterion is summed over the records,
/// each on its own frequency set (`options.frequencies` resolved per record).
///
/// The returned [`Fit`] has the joint covariance (sandwich of the summed bread and meat), the
/// residuals of all records in order, and the noise level pooled over the records (root mean
/// of the records' variances).
///
/// # Errors
///
/// Those of [`check_joint`]; those of [`fit`](crate::fit) for each record's set-up.
pub fn estimate_joint<S, J, N, C>(
    structures: &[ModelStructure<S, J, N>],
    records: &[MeasuredRecord],
    criterion: &C,
    options: &FitOptions,
) -> Result<Fit, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
{
    joint(structures, records, criterion, &options.moment())
}

fn joint<S, J, N, C, V, W>(
    structures: &[ModelStructure<S, J, N>],
    records: &[MeasuredRecord],
    criterion: &C,
    options: &MomentOptions<V, W>,
) -> Result<Fit, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    V: for<'a> Solver<JointProblem<'a, S, J, N, C, W>>,
    W: Window + Clone,
{
    check_joint(structures, records)?;
    let p = structures[0].num_params();
    if p == 0 {
        return Err(EstimateError::NothingToEstimate);
    }
    if structures[0].estimate_jitter && !criterion.models_jitter() {
        return Err(EstimateError::JitterNotModelled {
            criterion: criterion.name(),
        });
    }
    let data = records
        .iter()
        .map(|r| {
            let freqs = options.frequencies.resolve(r.record())?;
            criterion.validate(&freqs)?;
            FrequencyData::new(r.record().clone(), options.window.clone(), freqs)
        })
        .collect::<Result<Vec<_>, EstimateError>>()?;
    let problem = JointProblem {
        parts: structures
            .iter()
            .zip(&data)
            .map(|(structure, data)| FitProblem::new(structure, criterion, data))
            .collect(),
        scales: records.iter().map(|r| 1.0 / r.y().len() as f64).collect(),
    };
    if problem.num_residuals() < p {
        return Err(EstimateError::TooFewData {
            what: "residuals",
            available: problem.num_residuals(),
            params: p,
        });
    }
    let start = structures[0].params();
    let r0 = problem.residuals(&start)?;
    if let Some((index, &value)) = r0.iter().enumerate().find(|(_, r)| !r.is_finite()) {
        return Err(EstimateError::NonFiniteAtStart { index, value });
    }
    let report = options.solver.minimize(&problem, &start)?;
    let fitted = structures
        .iter()
        .map(|s| s.with_params(&report.params))
        .collect::<Result<Vec<_>, _>>()?;
    let mut residuals = Vec::new();
    for (d, s) in data.iter().zip(&fitted) {
        residuals.extend(d.residuals(criterion, s));
    }
    let (covariance, noise_std) = if options.covariance {
        let mut gram = Mat::zeros(p, p);
        let mut meat = Mat::zeros(p, p);
        let mut noise_var = 0.0;
        for ((d, s), &c) in data.iter().zip(&fitted).zip(&problem.scales) {
            let (g, m, v) = sandwich_parts(d, s, criterion, None);
            // r scaled by √c: JᵀJ by c, Jᵀ Σ_r J by c² (J on both sides and Σ_r).
            gram = &gram + &scaled(&g, c);
            meat = &meat + &scaled(&m, c * c);
            noise_var += v / data.len() as f64;
        }
        sandwich_of(&gram, &meat, &[], noise_var)
    } else {
        (None, fitted[0].noise_std.unwrap_or(f64::NAN))
    };
    let std_errors = covariance
        .as_ref()
        .map(|c: &Vec<Vec<f64>>| (0..p).map(|i| c[i][i].max(0.0).sqrt()).collect());
    Ok(Fit {
        criterion: criterion.name().to_string(),
        names: structures[0].param_names(),
        params: report.params,
        covariance,
        std_errors,
        cost: report.cost,
        cost_kind: CostKind::SumOfSquares,
        iterations: report.iterations,
        termination: report.termination.into(),
        converged: report.converged,
        residuals,
        noise_std,
        residual_flatness: None,
    })
}
