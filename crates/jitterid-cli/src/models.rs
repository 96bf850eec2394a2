//! Run-time choice of signal and noise model: enums that delegate every trait method to the
//! chosen library type (including the fast exact overrides), so that one non-generic
//! [`ModelStructure`](jitterid::estimate::ModelStructure) serves every experiment. (The jitter
//! family and the solver are the library's run-time types,
//! [`AnyJitter`](jitterid::jitter::AnyJitter) and
//! [`AnySolver`](jitterid::estimate::solver::AnySolver).)

use jitterid::estimate::{ArmaNoise, EstimateError, NoiseModel};
use jitterid::jitter::JitterModel;
use jitterid::num_complex::Complex64;
use jitterid::signal::{
    Jacobian, LtiResponse, SampleGrid, Signal, SignalError, Sinusoid, SpectralLine, Spectrum,
    TransferFunction, Zpk,
};

/// A signal model chosen at run time.
#[derive(Debug, Clone, PartialEq)]
pub enum AnySignal {
    /// A zero-pole-gain system driven by a known input.
    Zpk(LtiResponse<Zpk>),
    /// A polynomial transfer function driven by a known input.
    Tf(LtiResponse<TransferFunction>),
    /// A sinusoid (no input).
    Sinusoid(Sinusoid),
}

macro_rules! each_signal {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            AnySignal::Zpk($s) => $e,
            AnySignal::Tf($s) => $e,
            AnySignal::Sinusoid($s) => $e,
        }
    };
}

impl Signal for AnySignal {
    fn param_names(&self) -> Vec<String> {
        each_signal!(self, s => s.param_names())
    }
    fn params(&self) -> Vec<f64> {
        each_signal!(self, s => s.params())
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        Ok(match self {
            AnySignal::Zpk(s) => AnySignal::Zpk(s.with_params(params)?),
            AnySignal::Tf(s) => AnySignal::Tf(s.with_params(params)?),
            AnySignal::Sinusoid(s) => AnySignal::Sinusoid(s.with_params(params)?),
        })
    }
    fn value(&self, t: f64) -> f64 {
        each_signal!(self, s => s.value(t))
    }
    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        each_signal!(self, s => s.value_gradient(t, grad))
    }
    fn breakpoints(&self) -> Vec<f64> {
        each_signal!(self, s => s.breakpoints())
    }
    fn rate(&self) -> f64 {
        each_signal!(self, s => s.rate())
    }
    fn num_params(&self) -> usize {
        each_signal!(self, s => s.num_params())
    }
    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        each_signal!(self, s => s.expected_values(grid, jitter))
    }
    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        each_signal!(self, s => s.expected_values_gradient(grid, jitter))
    }
    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        each_signal!(self, s => s.expected_squares(grid, jitter))
    }
}

impl Spectrum for AnySignal {
    fn density(&self, f: f64) -> Complex64 {
        each_signal!(self, s => s.density(f))
    }
    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        each_signal!(self, s => s.density_gradient(f, grad))
    }
    fn lines(&self) -> Vec<SpectralLine> {
        each_signal!(self, s => s.lines())
    }
    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        each_signal!(self, s => s.lines_gradient())
    }
}

impl AnySignal {
    /// `G(i2πf)` for the rational systems, `None` for a sinusoid.
    pub fn frequency_response(&self, f: f64) -> Option<Complex64> {
        use jitterid::signal::RationalModel;
        match self {
            AnySignal::Zpk(s) => Some(s.model().frequency_response(f)),
            AnySignal::Tf(s) => Some(s.model().frequency_response(f)),
            AnySignal::Sinusoid(_) => None,
        }
    }
}

/// A measurement-noise shape chosen at run time.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyNoise {
    /// White noise.
    White,
    /// ARMA-filtered white noise.
    Arma(ArmaNoise),
}

impl NoiseModel for AnyNoise {
    fn param_names(&self) -> Vec<String> {
        match self {
            AnyNoise::White => Vec::new(),
            AnyNoise::Arma(a) => a.param_names(),
        }
    }
    fn params(&self) -> Vec<f64> {
        match self {
            AnyNoise::White => Vec::new(),
            AnyNoise::Arma(a) => a.params(),
        }
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, EstimateError> {
        match self {
            AnyNoise::White => {
                if params.is_empty() {
                    Ok(AnyNoise::White)
                } else {
                    Err(EstimateError::WrongParamCount {
                        expected: 0,
                        got: params.len(),
                    })
                }
            }
            AnyNoise::Arma(a) => Ok(AnyNoise::Arma(a.with_params(params)?)),
        }
    }
    fn shape(&self, f: f64, interval: f64) -> f64 {
        match self {
            AnyNoise::White => 1.0,
            AnyNoise::Arma(a) => a.shape(f, interval),
        }
    }
    fn is_white(&self) -> bool {
        matches!(self, AnyNoise::White)
    }
}
