//! An input delay (dead time) as a parameter of the LTI response.

use crate::lti::LtiResponse;
use crate::rational::{Modal, RationalModel};
use crate::signal::{Jacobian, Signal};
use crate::spectrum::Spectrum;
use crate::{Input, SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The response of a rational model to its input delayed by `D` seconds (dead time):
/// `s_D(t) = s(t − D)` where `s` is the [`LtiResponse`] to the undelayed input. The system
/// is at rest before the input's first step, so delaying the input delays the whole
/// response, and the jittered moments are those of `s` on the grid moved earlier by `D`:
/// exact, at the cost of the undelayed response.
///
/// Parameters: the model's, then `delay` (s). `∂m_k/∂D = −E[ṡ(t_k − D + τ)]`
/// ([`LtiResponse::expected_rates`]): the input's steps move with `D`.
///
/// `D` is any finite number here (a search may step below zero); front ends ask `D ≥ 0` of
/// what a user writes. Needs a piecewise-constant input (a tone's delay is a phase).
#[derive(Debug, Clone, PartialEq)]
pub struct Delayed<M> {
    inner: LtiResponse<M>,
    delay: f64,
}

impl<M: RationalModel> Delayed<M> {
    /// `response` with its input delayed by `delay` seconds.
    ///
    /// # Errors
    ///
    /// [`SignalError::NotFinite`] for a NaN or infinite delay,
    /// [`SignalError::NeedsSteps`] for a tone input.
    pub fn new(response: LtiResponse<M>, delay: f64) -> Result<Self, SignalError> {
        crate::error::finite("delay", delay)?;
        if let Input::Tones(_) = response.input() {
            return Err(SignalError::NeedsSteps { what: "a delay" });
        }
        Ok(Self {
            inner: response,
            delay,
        })
    }

    /// The undelayed response.
    pub fn response(&self) -> &LtiResponse<M> {
        &self.inner
    }

    /// The delay `D` (s).
    pub fn delay(&self) -> f64 {
        self.delay
    }

    /// The model's modal form, where it has one (its poles do not depend on `delay`).
    pub fn modal(&self) -> Option<&Modal> {
        self.inner.model().modal()
    }

    fn rates_column(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let rates = self
            .inner
            .expected_rates(&grid.earlier(self.delay), jitter)
            .unwrap_or_default();
        rates.into_iter().map(|r| -r).collect()
    }
}

impl<M: RationalModel> Signal for Delayed<M> {
    fn param_names(&self) -> Vec<String> {
        let mut names = self.inner.param_names();
        names.push("delay".into());
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p = self.inner.params();
        p.push(self.delay);
        p
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        let (inner, delay) = crate::error::split_trailing(params, self.inner.num_params(), true)?;
        Self::new(self.inner.with_params(inner)?, delay.unwrap_or(self.delay))
    }

    fn value(&self, t: f64) -> f64 {
        self.inner.value(t - self.delay)
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        let n = grad.len() - 1;
        self.inner.value_gradient(t - self.delay, &mut grad[..n]);
        grad[n] = -self.inner.rate_at(t - self.delay).unwrap_or(0.0);
    }

    fn breakpoints(&self) -> Vec<f64> {
        let mut b = self.inner.breakpoints();
        b.iter_mut().for_each(|t| *t += self.delay);
        b
    }

    fn rate(&self) -> f64 {
        self.inner.rate()
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        self.inner
            .expected_values(&grid.earlier(self.delay), jitter)
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let mut cols = self
            .inner
            .expected_values_gradient(&grid.earlier(self.delay), jitter);
        cols.push(self.rates_column(grid, jitter));
        cols
    }

    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        let (values, mut cols) = self
            .inner
            .expected_values_and_gradient(&grid.earlier(self.delay), jitter);
        cols.push(self.rates_column(grid, jitter));
        (values, cols)
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        self.inner
            .expected_squares(&grid.earlier(self.delay), jitter)
    }
}

impl<M: RationalModel> Spectrum for Delayed<M> {
    fn density(&self, f: f64) -> Complex64 {
        self.inner.density(f) * shift(f, self.delay)
    }

    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        let n = grad.len() - 1;
        self.inner.density_gradient(f, &mut grad[..n]);
        let e = shift(f, self.delay);
        grad[..n].iter_mut().for_each(|g| *g *= e);
        grad[n] = Complex64::new(0.0, -TAU * f) * self.density(f);
    }
}

/// `e^{−i2πfD}`, the transform of a delay by `D`.
fn shift(f: f64, delay: f64) -> Complex64 {
    Complex64::from_polar(1.0, -TAU * f * delay)
}
