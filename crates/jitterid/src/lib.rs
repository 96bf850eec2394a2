//! **jitterid**: system identification when the sampling instants themselves are noisy.
//!
//! A sensor asked to sample at `t_k = t0 + kT` measures at `t_k + τ_k`, with `τ_k` random and
//! unknown. Treating this as amplitude noise biases ordinary identification at high
//! frequencies. jitterid models the jitter: the first moment of the data's DTFT is the
//! continuous-time model convolved with the Dirichlet (leakage/alias) window and damped by the
//! jitter's characteristic function `γ(f)`:
//!
//! ```text
//! μ_Y(f; θ) = E[Y(f)] = ∫ S_c(ψ; θ) γ(−ψ; θ) Γ_N(f − ψ) dψ = Σ_k E[s(t_k + τ)] e^{−i2πf kT}
//! ```
//!
//! This facade re-exports the workspace's crates:
//!
//! * [`jitter`]: the [`JitterModel`](jitter::JitterModel) trait and its families.
//! * [`signal`]: the [`Signal`](signal::Signal) trait, transfer functions, inputs, the exact
//!   jittered simulator.
//! * [`window`]: DTFT, FFT, the Dirichlet kernel and the first moment `μ_Y` two ways.
//! * [`estimate`]: criteria, solvers and model structures (`jitterid-estimate`), with the
//!   likelihoods (`jitterid-likelihood`) and the solvers (`jitterid-optim`) beside them.
//!
//! Conventions (Hz, no `1/2π`, the corrected uniform-sum characteristic function) are those of
//! the crate docs of [`jitter`] and [`window`].
//!
//! # Example
//!
//! The paper's Table 2 system, its first moment under jitter, by the fast exact route:
//!
//! ```
//! use jitterid::prelude::*;
//! use rand::SeedableRng;
//!
//! let g = Zpk::new(0.2, vec![Root::Real(-0.5)], vec![Root::Pair { re: -0.25, im: 0.3 }])?;
//! let mut rng = rand::rngs::StdRng::seed_from_u64(1);
//! let u = RandomBinary::paper().generate(0.0, 200.0, &mut rng)?;
//! let signal = LtiResponse::new(g, u);
//! let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt())?;
//! let grid = SampleGrid::new(0.0, 1.0, 200)?;
//! let m = signal.expected_values(&grid, &jitter); // m_k = E[s(t_k + τ)]
//! assert_eq!(m.len(), 200);
//! let data = simulate(&signal, &jitter, &grid, 0.01, &mut rng)?;
//! assert_eq!(data.y.len(), 200);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

/// Estimation: criteria, solvers and model structures, with the likelihood layer as [`ml`](estimate::ml)
/// and the optimisation layer as [`solver`](estimate::solver). One path for the workspace's
/// estimation crates (`jitterid-estimate`, `jitterid-likelihood`, `jitterid-optim`,
/// `jitterid-registry`), as the front ends have always used it.
pub mod estimate {
    pub use jitterid_estimate::*;
    /// The likelihood layer (`jitterid-likelihood`).
    pub use jitterid_likelihood as ml;
    pub use jitterid_likelihood::{
        selection, validation, AnyCriterion, AnyStructure, CriterionEntry, CriterionRegistry,
        ExactMl, Likelihood, QuasiMl,
    };
    /// The optimisation layer (`jitterid-optim`).
    pub use jitterid_optim as solver;
}
pub use jitterid_jitter as jitter;
/// The wall-clock budget and cancel flag that every long loop checks.
pub use jitterid_numeric::budget;
/// The documented limits on the sizes a caller can ask for, checked where each enters.
pub use jitterid_numeric::limits;
pub use jitterid_signal as signal;
pub use jitterid_window as window;
pub use num_complex;
pub use rand;

/// The commonly used types and traits.
pub mod prelude {
    pub use crate::jitter::registry::{JitterRegistry, ParamSpec};
    pub use crate::jitter::{
        AnyJitter, ExponentialDelay, Gaussian, JitterError, JitterModel, Laplace, Mixture,
        NoJitter, Periodic, Shifted, Sum, TwoPoint, UniformSum,
    };
    pub use crate::signal::{
        simulate, Input, LtiResponse, Multisine, PiecewiseConstant, RandomBinary, RationalModel,
        Root, SampleGrid, Signal, Simulation, Sinusoid, Spectrum, TransferFunction, Zpk,
    };
    pub use num_complex::Complex64;
}

// The README's library example is compiled and run with the doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;

// The extension guide's examples (a jitter family, a signal, a criterion) are compiled and run
// with the doctests, so that the guide cannot drift from the traits.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/extending.md")]
struct ExtendingGuide;
