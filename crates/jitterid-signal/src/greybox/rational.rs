//! The modal route of a grey-box model: its transfer function `C adj(sI − A) B / det(sI − A) + D`
//! with the coefficients' exact derivatives with respect to `θ`, as a [`RationalModel`] whose
//! parameters are the physical ones, so that [`LtiResponse`](crate::LtiResponse)'s modal form
//! (the transfer-function route's, and as fast) gives the response, its gradient and the
//! jittered moments wherever the poles are distinct.
//!
//! The coefficients come from the Faddeev–LeVerrier recursion (`M_1 = I`,
//! `M_k = A M_{k−1} + c_{n−k+1} I`, `c_{n−k} = −tr(A M_k)/k`), run once on the matrices and
//! once per parameter on dual numbers seeded with the matrices' derivatives
//! (`A + A_j ε`, …): the directional derivative of the recursion, exact to rounding.

use super::{StateMatrices, StateSpaceModel};
use crate::{Rational, RationalModel, SignalError};
use jitterid_numeric::dual::{Dual, Real};

/// `(num, den)` of `C adj(sI − A) B / det(sI − A) + D`, highest power first, both of length
/// `n + 1`, `den` monic (not reduced: a non-minimal model keeps its cancelling pairs).
pub(super) fn transfer<R: Real>(m: &StateMatrices<R>) -> (Vec<R>, Vec<R>) {
    let n = m.a.len();
    let zero = R::constant(0.0);
    let mat_mul = |x: &[Vec<R>], y: &[Vec<R>]| -> Vec<Vec<R>> {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| (0..n).fold(zero, |s, l| s + x[i][l] * y[l][j]))
                    .collect()
            })
            .collect()
    };
    let mut den = vec![R::constant(1.0)];
    let mut strictly_proper = vec![zero];
    let mut mk = vec![vec![zero; n]; n];
    for k in 1..=n {
        let lead = den[k - 1];
        mk = mat_mul(&m.a, &mk);
        for (i, row) in mk.iter_mut().enumerate() {
            row[i] = row[i] + lead;
        }
        let am = mat_mul(&m.a, &mk);
        let trace = (0..n).fold(zero, |s, i| s + am[i][i]);
        den.push(-trace / R::constant(k as f64));
        let mb = mk
            .iter()
            .map(|row| row.iter().zip(&m.b).fold(zero, |s, (x, b)| s + *x * *b));
        strictly_proper.push(m.c.iter().zip(mb).fold(zero, |s, (c, x)| s + *c * x));
    }
    let num = den
        .iter()
        .zip(&strictly_proper)
        .map(|(a, b)| m.d * *a + *b)
        .collect();
    (num, den)
}

/// The matrices with their derivative along one parameter as dual numbers.
fn seeded(m: &StateMatrices<f64>, d: &StateMatrices<f64>) -> StateMatrices<Dual> {
    let dual = |value: f64, derivative: f64| Dual { value, derivative };
    StateMatrices {
        a: m.a
            .iter()
            .zip(&d.a)
            .map(|(r, dr)| r.iter().zip(dr).map(|(x, dx)| dual(*x, *dx)).collect())
            .collect(),
        b: m.b.iter().zip(&d.b).map(|(x, dx)| dual(*x, *dx)).collect(),
        c: m.c.iter().zip(&d.c).map(|(x, dx)| dual(*x, *dx)).collect(),
        d: dual(m.d, d.d),
    }
}

/// A grey-box model's transfer function, parameterised by its physical parameters: the
/// [`RationalModel`] an [`LtiResponse`](crate::LtiResponse) drives, which an input delay
/// ([`Delayed`](crate::Delayed)) and a free response
/// ([`WithInitialState`](crate::WithInitialState)) are built on
/// ([`GreyBox::transfer_response`](super::GreyBox::transfer_response)).
#[derive(Debug, Clone)]
pub struct GreyTf<M> {
    model: M,
    theta: Vec<f64>,
    rational: Rational,
}

impl<M: StateSpaceModel> GreyTf<M> {
    /// The transfer function at `theta`, from the matrices there and their derivatives.
    ///
    /// # Errors
    ///
    /// Those of [`Rational::new`]: a pole right of the axis, coefficients it cannot root.
    pub(crate) fn new(
        model: M,
        theta: Vec<f64>,
        mats: &StateMatrices<f64>,
        derivs: &[StateMatrices<f64>],
    ) -> Result<Self, SignalError> {
        let (num, den) = transfer(mats);
        let (d_num, d_den) = derivs
            .iter()
            .map(|d| {
                let (n, a) = transfer(&seeded(mats, d));
                (
                    n.iter().map(|x| x.derivative).collect(),
                    a.iter().map(|x| x.derivative).collect(),
                )
            })
            .unzip();
        let rational = Rational::new(num, den, d_num, d_den)?;
        Ok(Self {
            model,
            theta,
            rational,
        })
    }
}

impl<M> GreyTf<M> {
    /// The model whose transfer function this is.
    pub fn model(&self) -> &M {
        &self.model
    }
}

impl<M: StateSpaceModel> RationalModel for GreyTf<M> {
    fn param_names(&self) -> Vec<String> {
        self.model.param_names()
    }

    fn params(&self) -> Vec<f64> {
        self.theta.clone()
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        if params.len() != self.theta.len() {
            return Err(SignalError::WrongParamCount {
                expected: self.theta.len(),
                got: params.len(),
            });
        }
        self.model.check(params)?;
        let (mats, derivs) = super::validated(&self.model, params)?;
        Self::new(self.model.clone(), params.to_vec(), &mats, &derivs)
    }

    fn rational(&self) -> &Rational {
        &self.rational
    }
}
