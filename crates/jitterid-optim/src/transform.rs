//! Parameter constraints by reparametrisation.

use super::problem::{checked_jacobian, first_non_finite, LeastSquares};
use super::{Solver, SolverError, SolverReport};
use faer::Mat;
use serde::{Deserialize, Serialize};
use std::fmt;

/// How an external (constrained) parameter `θ` is written in terms of an internal,
/// unconstrained `φ ∈ ℝ`. Deserialization rejects `Bounded` without finite `lo < hi`.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(try_from = "RawTransform")]
pub enum Transform {
    /// No constraint: `θ = φ`.
    #[default]
    Free,
    /// `θ > 0`: `θ = e^φ`.
    Positive,
    /// `θ < 0`: `θ = −e^φ`.
    Negative,
    /// `lo < θ < hi`: `θ = lo + (hi − lo) σ(φ)` with the logistic `σ(φ) = 1/(1 + e^{−φ})`.
    Bounded {
        /// Lower bound (finite).
        lo: f64,
        /// Upper bound (finite, `> lo`).
        hi: f64,
    },
}

/// [`Transform`] as read, before validation.
#[derive(Deserialize)]
enum RawTransform {
    Free,
    Positive,
    Negative,
    Bounded { lo: f64, hi: f64 },
}

impl TryFrom<RawTransform> for Transform {
    type Error = SolverError;

    fn try_from(raw: RawTransform) -> Result<Self, SolverError> {
        Ok(match raw {
            RawTransform::Free => Transform::Free,
            RawTransform::Positive => Transform::Positive,
            RawTransform::Negative => Transform::Negative,
            RawTransform::Bounded { lo, hi } => {
                let t = Transform::Bounded { lo, hi };
                if !t.is_valid() {
                    return Err(SolverError::InvalidBounds { index: 0, lo, hi });
                }
                t
            }
        })
    }
}

/// Logistic function, without overflow for either sign of `x`.
fn logistic(x: f64) -> f64 {
    if x >= 0.0 {
        1.0 / (1.0 + (-x).exp())
    } else {
        let e = x.exp();
        e / (1.0 + e)
    }
}

impl Transform {
    /// `θ(φ)`.
    pub fn to_external(self, phi: f64) -> f64 {
        match self {
            Transform::Free => phi,
            Transform::Positive => phi.exp(),
            Transform::Negative => -phi.exp(),
            // Measured from the nearer bound so that values close to either bound keep precision.
            Transform::Bounded { lo, hi } => {
                if phi >= 0.0 {
                    hi - (hi - lo) * logistic(-phi)
                } else {
                    lo + (hi - lo) * logistic(phi)
                }
            }
        }
    }

    /// `dθ/dφ`.
    pub fn derivative(self, phi: f64) -> f64 {
        match self {
            Transform::Free => 1.0,
            Transform::Positive => phi.exp(),
            Transform::Negative => -phi.exp(),
            // σ(1 − σ) = σ(φ)σ(−φ) avoids the cancellation in 1 − σ.
            Transform::Bounded { lo, hi } => (hi - lo) * logistic(phi) * logistic(-phi),
        }
    }

    /// `φ(θ)`, or `None` if `θ` violates the constraint (or is not finite).
    pub fn to_internal(self, theta: f64) -> Option<f64> {
        if !theta.is_finite() {
            return None;
        }
        match self {
            Transform::Free => Some(theta),
            Transform::Positive => (theta > 0.0).then(|| theta.ln()),
            Transform::Negative => (theta < 0.0).then(|| (-theta).ln()),
            Transform::Bounded { lo, hi } => {
                (lo < theta && theta < hi).then(|| ((theta - lo) / (hi - theta)).ln())
            }
        }
    }

    /// Whether the transform itself is valid (finite bounds with `lo < hi`).
    pub fn is_valid(self) -> bool {
        match self {
            Transform::Bounded { lo, hi } => lo.is_finite() && hi.is_finite() && lo < hi,
            _ => true,
        }
    }
}

impl fmt::Display for Transform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Transform::Free => f.write_str("free"),
            Transform::Positive => f.write_str("θ > 0"),
            Transform::Negative => f.write_str("θ < 0"),
            Transform::Bounded { lo, hi } => write!(f, "{lo} < θ < {hi}"),
        }
    }
}

/// One valid transform per parameter: the map between external `θ` and internal `φ` that
/// [`Transformed`] (a least-squares problem) and
/// [`TransformedObjective`](crate::TransformedObjective) (any objective) share.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Coordinates(Vec<Transform>);

impl Coordinates {
    /// `transforms` for a problem of `expected` parameters.
    ///
    /// # Errors
    ///
    /// [`SolverError::WrongTransformCount`] if the lengths differ,
    /// [`SolverError::InvalidBounds`] for a `Bounded` transform without finite `lo < hi`.
    pub(crate) fn new(expected: usize, transforms: Vec<Transform>) -> Result<Self, SolverError> {
        if transforms.len() != expected {
            return Err(SolverError::WrongTransformCount {
                expected,
                got: transforms.len(),
            });
        }
        for (index, t) in transforms.iter().enumerate() {
            if let Transform::Bounded { lo, hi } = *t {
                if !t.is_valid() {
                    return Err(SolverError::InvalidBounds { index, lo, hi });
                }
            }
        }
        Ok(Coordinates(transforms))
    }

    /// The transforms, one per parameter.
    pub(crate) fn transforms(&self) -> &[Transform] {
        &self.0
    }

    /// `θ(φ)`.
    pub(crate) fn external(&self, phi: &[f64]) -> Vec<f64> {
        phi.iter()
            .zip(&self.0)
            .map(|(&p, t)| t.to_external(p))
            .collect()
    }

    /// `φ(θ)`.
    ///
    /// # Errors
    ///
    /// [`SolverError::OutsideConstraint`] for the first parameter that violates its
    /// constraint.
    pub(crate) fn internal(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        theta
            .iter()
            .zip(&self.0)
            .enumerate()
            .map(|(index, (&value, &t))| {
                t.to_internal(value).ok_or(SolverError::OutsideConstraint {
                    index,
                    value,
                    constraint: t,
                })
            })
            .collect()
    }

    /// `dθⱼ/dφⱼ` for every parameter.
    pub(crate) fn derivatives(&self, phi: &[f64]) -> Vec<f64> {
        phi.iter()
            .zip(&self.0)
            .map(|(&p, t)| t.derivative(p))
            .collect()
    }
}

/// A problem in unconstrained internal coordinates `φ`: `r̃(φ) = r(θ(φ))`, with the chain rule
/// `∂r̃/∂φⱼ = ∂r/∂θⱼ · dθⱼ/dφⱼ` for the Jacobian.
///
/// Solvers minimise over `φ`; convert starts with [`to_internal`](Self::to_internal) (which
/// rejects starts outside the constraints) and results with
/// [`to_external`](Self::to_external), or use [`minimize`](Self::minimize) which does both.
///
/// A parameter near a bound has a small `dθ/dφ`, so steps there shrink; a minimum *on* a bound
/// is approached but never reached.
///
/// # Example
///
/// ```
/// use jitterid_optim::{
///     LeastSquares, LevenbergMarquardt, SolverError, Transform, Transformed,
/// };
///
/// /// Residuals `θ − 2`, minimum at 2.
/// struct Shift;
/// impl LeastSquares for Shift {
///     fn num_params(&self) -> usize { 1 }
///     fn num_residuals(&self) -> usize { 1 }
///     fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> { Ok(vec![p[0] - 2.0]) }
/// }
///
/// let constrained = Transformed::new(&Shift, vec![Transform::Positive])?;
/// let report = constrained.minimize(&LevenbergMarquardt::default(), &[0.5])?;
/// assert!((report.params[0] - 2.0).abs() < 1e-8); // external coordinates
/// assert!(matches!(
///     constrained.minimize(&LevenbergMarquardt::default(), &[-1.0]),
///     Err(SolverError::OutsideConstraint { index: 0, .. })
/// ));
/// # Ok::<(), SolverError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Transformed<P> {
    problem: P,
    coordinates: Coordinates,
}

impl<P: LeastSquares> Transformed<P> {
    /// Wraps `problem` with one transform per parameter.
    ///
    /// # Errors
    ///
    /// [`SolverError::WrongTransformCount`] if `transforms.len()` differs from the number of
    /// parameters, [`SolverError::InvalidBounds`] for a `Bounded` transform without finite
    /// `lo < hi`.
    pub fn new(problem: P, transforms: Vec<Transform>) -> Result<Self, SolverError> {
        let coordinates = Coordinates::new(problem.num_params(), transforms)?;
        Ok(Transformed {
            problem,
            coordinates,
        })
    }

    /// The wrapped problem (external coordinates).
    pub fn inner(&self) -> &P {
        &self.problem
    }

    /// The transforms, one per parameter.
    pub fn transforms(&self) -> &[Transform] {
        self.coordinates.transforms()
    }

    /// Internal coordinates `φ` of external parameters `θ`.
    ///
    /// # Errors
    ///
    /// [`SolverError::WrongStartLength`], [`SolverError::NonFiniteStart`], and
    /// [`SolverError::OutsideConstraint`] for the first parameter that violates its constraint.
    pub fn to_internal(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        self.check_len(theta)?;
        if let Some((index, value)) = first_non_finite(theta) {
            return Err(SolverError::NonFiniteStart { index, value });
        }
        self.coordinates.internal(theta)
    }

    /// External parameters `θ` of internal coordinates `φ`.
    ///
    /// # Errors
    ///
    /// [`SolverError::WrongStartLength`] if `phi` has the wrong length.
    pub fn to_external(&self, phi: &[f64]) -> Result<Vec<f64>, SolverError> {
        self.check_len(phi)?;
        Ok(self.external(phi))
    }

    /// Minimises with `solver` from the external start `theta0` and reports the result in
    /// external coordinates (the cost is the same in both).
    ///
    /// # Errors
    ///
    /// Those of [`to_internal`](Self::to_internal) for the start, and those of the solver.
    pub fn minimize<S: Solver<Self> + ?Sized>(
        &self,
        solver: &S,
        theta0: &[f64],
    ) -> Result<SolverReport, SolverError> {
        let phi0 = self.to_internal(theta0)?;
        let mut report = solver.minimize(self, &phi0)?;
        report.params = self.to_external(&report.params)?;
        Ok(report)
    }

    fn external(&self, phi: &[f64]) -> Vec<f64> {
        self.coordinates.external(phi)
    }

    fn check_len(&self, v: &[f64]) -> Result<(), SolverError> {
        let expected = self.coordinates.transforms().len();
        if v.len() != expected {
            return Err(SolverError::WrongStartLength {
                expected,
                got: v.len(),
            });
        }
        Ok(())
    }
}

impl<P: LeastSquares> LeastSquares for Transformed<P> {
    fn num_params(&self) -> usize {
        self.problem.num_params()
    }

    fn num_residuals(&self) -> usize {
        self.problem.num_residuals()
    }

    fn residuals(&self, phi: &[f64]) -> Result<Vec<f64>, SolverError> {
        self.check_len(phi)?;
        self.problem.residuals(&self.external(phi))
    }

    fn jacobian(&self, phi: &[f64]) -> Result<Mat<f64>, SolverError> {
        self.check_len(phi)?;
        let j = checked_jacobian(&self.problem, &self.external(phi))?;
        let d = self.coordinates.derivatives(phi);
        Ok(Mat::from_fn(j.nrows(), j.ncols(), |r, c| j[(r, c)] * d[c]))
    }
}
