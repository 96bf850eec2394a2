//! The validated experiment: what every command reads, with nothing left to check.

use crate::models::AnyNoise;
use jitterid::estimate::Frequencies;
use jitterid::jitter::AnyJitter;
use jitterid::signal::{Input, RandomBinary, SampleGrid, Sinusoid, TransferFunction, Zpk};
use std::path::PathBuf;

/// How the input is obtained.
#[derive(Debug, Clone, PartialEq)]
pub enum InputSpec {
    /// No input (a sinusoid system).
    None,
    /// A random binary input, drawn per realisation from the seed.
    RandomBinary(RandomBinary),
    /// A known input.
    Known(Input),
}

/// The system kind with its parameters (the truth in `simulate`/`montecarlo`, the start in
/// `fit`).
#[derive(Debug, Clone, PartialEq)]
pub enum SystemKind {
    /// Zeros, poles, gain.
    Zpk(Zpk),
    /// Polynomial transfer function.
    Tf(TransferFunction),
    /// A sinusoid `A sin(2πft + φ)` (no input).
    Sinusoid(Sinusoid),
}

/// The `[system]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSpec {
    /// The model.
    pub kind: SystemKind,
    /// Whether its parameters are estimated.
    pub estimate: bool,
}

/// The `[jitter]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct JitterSpec {
    /// The family and parameters given (the truth in `simulate`/`montecarlo`).
    pub truth: AnyJitter,
    /// The model's family for fitting, started at the truth's standard deviation (equal to
    /// `truth` unless `fit_family` is given).
    pub model: AnyJitter,
    /// Whether the model's parameters are estimated.
    pub estimate: bool,
    /// For an estimated uniform-sum model: the range of `n` profiled over (inclusive).
    pub n_range: Option<(u32, u32)>,
    /// Whether the fitted family differs from the given one (its parameters have no truth).
    pub family_differs: bool,
}

/// The `[noise]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseSpec {
    /// Standard deviation of the white noise `e_k` (of `v_k` itself for white noise).
    pub std: f64,
    /// The noise shape `H`.
    pub shape: AnyNoise,
    /// Whether the noise level (and, with method `bj`, the shape) is estimated.
    pub estimate: bool,
}

/// Estimation method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Naive least squares (jitter ignored).
    Ls,
    /// Bias-compensated least squares.
    Bcls,
    /// The Box–Jenkins frequency-domain criterion (BCLS weighted by the noise shape).
    Bj,
    /// Maximum likelihood.
    Ml,
}

impl Method {
    /// The name used in files and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Ls => "ls",
            Method::Bcls => "bcls",
            Method::Bj => "bj",
            Method::Ml => "ml",
        }
    }

    /// Parses a method name.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "ls" => Method::Ls,
            "bcls" => Method::Bcls,
            "bj" => Method::Bj,
            "ml" => Method::Ml,
            _ => return None,
        })
    }
}

/// Solver kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolverKind {
    /// Levenberg–Marquardt.
    Lm,
    /// Gauss–Newton with line search.
    GaussNewton,
    /// Nelder–Mead.
    NelderMead,
}

/// The `[estimate]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimateSpec {
    /// The method.
    pub method: Method,
    /// The frequency set.
    pub frequencies: Frequencies,
    /// The solver.
    pub solver: SolverKind,
    /// Number of extra, perturbed starts.
    pub multistart: usize,
    /// Relative radius of the multistart perturbations.
    pub multistart_radius: f64,
    /// Relative size of the seeded start perturbation in Monte Carlo.
    pub perturb: f64,
    /// Iteration limit of the solver (its default if `None`).
    pub max_iterations: Option<u64>,
    /// Wall-clock budget of each fit in seconds (the solver's default if `None`); set from the
    /// command line.
    pub max_seconds: Option<f64>,
}

/// A validated experiment: every value is within the representable range, every model is
/// built, and (when read for estimation) `estimate.method` can fit what is marked as
/// estimated. Commands use it as it is; nothing in it is checked again.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// The file's name, for messages.
    pub file: String,
    /// The directory relative paths are resolved from.
    pub dir: PathBuf,
    /// An optional title.
    pub title: Option<String>,
    /// The sampling grid.
    pub grid: SampleGrid,
    /// The input.
    pub input: InputSpec,
    /// The system.
    pub system: SystemSpec,
    /// The jitter.
    pub jitter: JitterSpec,
    /// The measurement noise.
    pub noise: NoiseSpec,
    /// How to estimate.
    pub estimate: EstimateSpec,
}
