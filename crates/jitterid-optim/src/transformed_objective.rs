//! Any [`Objective`] in unconstrained coordinates: [`TransformedObjective`].

use crate::transform::Coordinates;
use crate::{Objective, SolverError, Transform};

/// An objective in unconstrained coordinates `φ`, `θ_j = T_j(φ_j)` (see [`Transform`]): the
/// cost of `θ(φ)`, and its gradient by the chain rule. The least-squares form, which keeps the
/// residuals, is [`Transformed`](crate::Transformed).
#[derive(Debug)]
pub struct TransformedObjective<'a, O: ?Sized> {
    inner: &'a O,
    coordinates: Coordinates,
}

impl<'a, O: Objective + ?Sized> TransformedObjective<'a, O> {
    /// Wraps `inner` with one transform per parameter.
    ///
    /// # Errors
    ///
    /// A wrong number of transforms, or invalid bounds.
    pub fn new(inner: &'a O, transforms: Vec<Transform>) -> Result<Self, SolverError> {
        let coordinates = Coordinates::new(inner.num_params(), transforms)?;
        Ok(TransformedObjective { inner, coordinates })
    }

    /// The transforms, one per parameter.
    pub fn transforms(&self) -> &[Transform] {
        self.coordinates.transforms()
    }

    /// `θ(φ)`.
    pub fn to_external(&self, phi: &[f64]) -> Vec<f64> {
        self.coordinates.external(phi)
    }

    /// `φ(θ)`.
    ///
    /// # Errors
    ///
    /// [`SolverError::OutsideConstraint`] for the first parameter that violates its
    /// constraint.
    pub fn to_internal(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        self.coordinates.internal(theta)
    }
}

impl<O: Objective + ?Sized> Objective for TransformedObjective<'_, O> {
    fn num_params(&self) -> usize {
        self.inner.num_params()
    }

    fn cost(&self, phi: &[f64]) -> f64 {
        let theta = self.to_external(phi);
        if theta.iter().any(|v| !v.is_finite()) {
            return f64::INFINITY;
        }
        self.inner.cost(&theta)
    }

    fn cost_gradient(&self, phi: &[f64]) -> (f64, Vec<f64>) {
        let theta = self.to_external(phi);
        if theta.iter().any(|v| !v.is_finite()) {
            return (f64::INFINITY, vec![f64::NAN; phi.len()]);
        }
        let (f, mut g) = self.inner.cost_gradient(&theta);
        for (gj, d) in g.iter_mut().zip(self.coordinates.derivatives(phi)) {
            *gj *= d;
        }
        (f, g)
    }
}
