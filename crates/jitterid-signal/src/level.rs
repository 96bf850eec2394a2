//! An input level: a system identified around an operating point of its input, `G (u − u₀)`.

use crate::delay::Delayed;
use crate::initial::ModalSignal;
use crate::lti::LtiResponse;
use crate::rational::RationalModel;
use crate::signal::{Jacobian, Signal};
use crate::spectrum::{SpectralLine, Spectrum};
use crate::{Input, SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;

/// The name of the level's parameter (when it is estimated).
pub const LEVEL_PARAM: &str = "level";

/// A response driven by an input, which can be driven by another input with the same system:
/// what an [`InputLevel`] needs to move the input's level.
pub trait DrivenSignal: Signal + Sized {
    /// The input that drives it.
    fn input(&self) -> &Input;

    /// The same system (parameters, delay) driven by `input`.
    ///
    /// # Errors
    ///
    /// Those of the response's constructor for `input` (a delay needs steps).
    fn driven_by(&self, input: Input) -> Result<Self, SignalError>;
}

impl<M: RationalModel + Clone> DrivenSignal for LtiResponse<M> {
    fn input(&self) -> &Input {
        LtiResponse::input(self)
    }

    fn driven_by(&self, input: Input) -> Result<Self, SignalError> {
        Ok(LtiResponse::new(self.model().clone(), input))
    }
}

impl<M: RationalModel + Clone> DrivenSignal for Delayed<M> {
    fn input(&self) -> &Input {
        self.response().input()
    }

    fn driven_by(&self, input: Input) -> Result<Self, SignalError> {
        Delayed::new(
            LtiResponse::new(self.response().model().clone(), input),
            self.delay(),
        )
    }
}

/// `G (u − u₀ 1)`: the response to the input's deviation from its level `u₀` (the operating
/// point of the input), where `1` is one over the input's span: a piecewise input is at `u₀`
/// before its first step and after its last (the plant was at rest at the operating point),
/// a tone input has `u₀` subtracted at all times.
///
/// The model is linear in the input, so the response is the system driven by the shifted
/// input `u − u₀ 1`: a response of the same kind, whose jittered moments (`m_k` and
/// `E[s(t_k + τ)²]`) are its own exact ones, unchanged in cost. The level's derivative is
/// `−G 1`, the response to the unit input over the same span (`−E[(G1)(t_k + τ)]` for the
/// first moment), also exact.
///
/// Where the response to `1` settles to the constant `G(0)` (every pole strictly stable), an
/// estimated `u₀` moves the output as a constant `−G(0) u₀` once the input's first step has
/// decayed: it is then confounded with an estimated output offset ([`settles`](Self::settles)
/// tells; the experiment reader refuses the pair). With an integrator the level is a ramp and
/// stands on its own.
///
/// Parameters: those of the response, then `level` when [`estimated`](Self::estimated); a
/// known level is part of the model but not a parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct InputLevel<S> {
    /// The system driven by `u − u₀ 1`.
    shifted: S,
    /// The system driven by `1` over the input's span.
    unit: S,
    /// The input as applied, `u`.
    input: Input,
    level: f64,
    estimated: bool,
}

impl<S: DrivenSignal + ModalSignal> InputLevel<S> {
    /// `signal` (the system driven by `u`) around the input level `level`, a parameter when
    /// `estimated`.
    ///
    /// # Errors
    ///
    /// [`SignalError::NotFinite`] for a NaN or infinite level; [`SignalError::OutOfRange`]
    /// (`level`) for a tone input to a system with a pole at the origin, whose response to a
    /// constant has no steady state; the response's own errors for the shifted input (a tone
    /// input with the most tones already).
    pub fn new(signal: S, level: f64, estimated: bool) -> Result<Self, SignalError> {
        crate::error::finite(LEVEL_PARAM, level)?;
        let input = signal.input().clone();
        if matches!(input, Input::Tones(_)) && signal.rational().has_pole_at_origin() {
            return Err(SignalError::OutOfRange {
                name: LEVEL_PARAM,
                value: level,
                expected: "absent for a tone input to a system with an integrator (its steady-state response to a constant level is unbounded)",
            });
        }
        let unit = signal.driven_by(input.unit_span()?)?;
        let shifted = signal.driven_by(input.deviation(level)?)?;
        Ok(Self {
            shifted,
            unit,
            input,
            level,
            estimated,
        })
    }
}

impl<S: DrivenSignal> InputLevel<S> {
    /// The response to the deviation `u − u₀ 1` (its keys are the system's).
    pub fn response(&self) -> &S {
        &self.shifted
    }

    /// The input as applied, `u`.
    pub fn input(&self) -> &Input {
        &self.input
    }

    /// The level `u₀`.
    pub fn level(&self) -> f64 {
        self.level
    }

    /// Whether `u₀` is a parameter (after the response's).
    pub fn estimated(&self) -> bool {
        self.estimated
    }

    /// The level's column `−E[(G1)(t_k + τ)]`, when it is a parameter.
    fn with_level_column(
        &self,
        mut cols: Jacobian,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> Jacobian {
        if self.estimated {
            let mut unit = self.unit.expected_values(grid, jitter);
            unit.iter_mut().for_each(|v| *v = -*v);
            cols.push(unit);
        }
        cols
    }
}

impl<S: DrivenSignal + ModalSignal> InputLevel<S> {
    /// Whether the response to the unit input settles to the constant `G(0)`: every pole
    /// strictly left of the imaginary axis (no integrator, no undamped mode). An estimated
    /// level is then confounded with an estimated output offset.
    pub fn settles(&self) -> bool {
        self.shifted.rational().settles()
    }
}

impl<S: DrivenSignal + ModalSignal + Clone> Signal for InputLevel<S> {
    fn param_names(&self) -> Vec<String> {
        let mut names = self.shifted.param_names();
        if self.estimated {
            names.push(LEVEL_PARAM.into());
        }
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p = self.shifted.params();
        if self.estimated {
            p.push(self.level);
        }
        p
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        let (inner, own) =
            crate::error::split_trailing(params, self.shifted.num_params(), self.estimated)?;
        let level = match own {
            Some(level) => crate::error::finite(LEVEL_PARAM, level)?,
            None => self.level,
        };
        let system = self.shifted.with_params(inner)?;
        // The unit input does not move with the level: only the shifted input is rebuilt.
        Ok(Self {
            unit: system.driven_by(self.unit.input().clone())?,
            shifted: system.driven_by(self.input.deviation(level)?)?,
            input: self.input.clone(),
            level,
            estimated: self.estimated,
        })
    }

    fn value(&self, t: f64) -> f64 {
        self.shifted.value(t)
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        let n = self.shifted.num_params();
        self.shifted.value_gradient(t, &mut grad[..n]);
        if self.estimated {
            grad[n] = -self.unit.value(t);
        }
    }

    fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        let n = self.shifted.num_params();
        let v = self.shifted.value_and_gradient(t, &mut grad[..n]);
        if self.estimated {
            grad[n] = -self.unit.value(t);
        }
        v
    }

    fn breakpoints(&self) -> Vec<f64> {
        // The unit input's edges are the input's first and last: already among these.
        self.shifted.breakpoints()
    }

    fn rate(&self) -> f64 {
        self.shifted.rate()
    }

    fn num_params(&self) -> usize {
        self.shifted.num_params() + usize::from(self.estimated)
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        self.shifted.expected_values(grid, jitter)
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let cols = self.shifted.expected_values_gradient(grid, jitter);
        self.with_level_column(cols, grid, jitter)
    }

    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        let (m, cols) = self.shifted.expected_values_and_gradient(grid, jitter);
        (m, self.with_level_column(cols, grid, jitter))
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        self.shifted.expected_squares(grid, jitter)
    }
}

impl<S: DrivenSignal + ModalSignal + Spectrum + Clone> Spectrum for InputLevel<S> {
    fn density(&self, f: f64) -> Complex64 {
        self.shifted.density(f)
    }

    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        let n = self.shifted.num_params();
        self.shifted.density_gradient(f, &mut grad[..n]);
        if self.estimated {
            grad[n] = -self.unit.density(f);
        }
    }

    fn lines(&self) -> Vec<SpectralLine> {
        self.shifted.lines()
    }

    /// The response's rows, with the level's column: `−` the unit response's lines, which are
    /// the shifted response's last ones (the level is the shifted input's last tone).
    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        let zero = (Complex64::new(0.0, 0.0), 0.0);
        let n = self.num_params();
        let lines = self.shifted.lines().len();
        let mut rows = self.shifted.lines_gradient();
        rows.resize(lines, Vec::new());
        rows.iter_mut().for_each(|row| row.resize(n, zero));
        if self.estimated {
            let unit = self.unit.lines();
            let first = lines - unit.len().min(lines);
            for (row, line) in rows[first..].iter_mut().zip(&unit) {
                row[n - 1] = (-line.coefficient, 0.0);
            }
        }
        rows
    }
}

impl<S: DrivenSignal + ModalSignal + Clone> ModalSignal for InputLevel<S> {
    fn rational(&self) -> &crate::rational::Rational {
        self.shifted.rational()
    }
}
