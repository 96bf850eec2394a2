//! Continuous-time signal models for **jitterid**.
//!
//! A [`Signal`] is a model `s(t; θ)` that can be evaluated exactly at any time, with its
//! gradient, and whose Fourier transform `S_c(f) = ∫ s(t) e^{-i2πft} dt` is known in closed form
//! as a density plus spectral lines. What identification needs from it under jitter is the
//! first moment of the samples, `m_k = E[s(t_k + τ)]` ([`Signal::expected_values`]), and for
//! the second moment `E[s(t_k + τ)²]`.
//!
//! # Conventions
//!
//! * Time in seconds, frequency in Hz; the Laplace variable `s` is in rad/s as usual, so a
//!   transfer function's frequency response is `G(i2πf)`.
//! * Requested instants `t_k = t0 + kT` ([`SampleGrid`]).
//! * Responses are exact: an LTI system driven by a piecewise-constant input is evaluated in
//!   modal (partial-fraction) form, `s(t) = Σ_j Δu_j [G(0) + Σ_i (r_i/p_i) e^{p_i (t − t_j)}]`
//!   over the input's steps; no time stepping. Where the modal form fails (repeated or nearly
//!   repeated poles, integrators and other poles on the imaginary axis) a state-space
//!   realisation of `1/A²` gives the response and its gradient through matrix exponentials;
//!   [`Rational::modal`] tells which route a model takes. Unstable poles are refused unless
//!   asked for ([`TransferFunction::new_allowing_unstable`], [`Zpk::new_allowing_unstable`]).
//!
//! # Models
//!
//! * [`TransferFunction`] (polynomial coefficients) and [`Zpk`] (zeros, poles, gain; real roots
//!   and complex pairs), both [`RationalModel`]s, driven by an [`Input`] in [`LtiResponse`].
//! * [`Delayed`]: an LTI response to its input delayed by a dead time `D` (a parameter).
//! * [`WithInitialState`]: a response plus the free response from an unknown state at the
//!   record's start.
//! * [`Offset`]: a signal plus a constant output offset `y₀` (an operating point), known or
//!   the parameter `offset`.
//! * [`Sinusoid`]: `A sin(2πf0 t + φ)` with parameters `(A, f0, φ)`, spectral lines only.
//! * [`PulseResponse`]: a discrete-time pulse response `g(t) = Σ h_l δ(t − lT_s)` driven by a
//!   piecewise-constant input.
//! * Inputs: [`PiecewiseConstant`] (and [`RandomBinary`], the paper's input, and zero-order
//!   hold), [`Multisine`].
//!
//! * [`greybox`]: a grey-box state-space model `ẋ = A(θ)x + B(θ)u, y = C(θ)x + D(θ)u` of named
//!   physical parameters (a Rust type implementing [`greybox::StateSpaceModel`], or matrices
//!   written as expressions, [`greybox::ExprModel`]), its sensitivities by the augmented
//!   matrix exponential.
//! * [`forms`]: plain transfer-function, zero-pole-gain and state-space forms of a model, with
//!   conversions and readable display, for export.
//!
//! The exact jittered simulator [`simulate`] draws `y_k = s(t_k + τ_k) + v_k`.
#![warn(missing_docs)]

mod any;
mod coefficients;
mod confluent;
mod delay;
mod error;
mod expm;
pub mod forms;
pub mod greybox;
mod grid;
mod initial;
mod input;
mod integrators;
mod level;
mod lti;
mod offset;
pub mod poly;
mod pulse;
mod rational;
mod reach;
pub mod registry;
mod root;
mod signal;
mod simulate;
mod sinusoid;
mod spectrum;
pub mod superposition;
pub mod testing;
mod zpk;

pub use any::AnySignal;
pub use delay::Delayed;
pub use error::SignalError;
pub use grid::SampleGrid;
pub use initial::{ModalSignal, WithInitialState, INITIAL_PREFIX};
pub use input::{Input, Multisine, PiecewiseConstant, RandomBinary, Tone, MAX_SWITCHES};
pub use level::{DrivenSignal, InputLevel, LEVEL_PARAM};
pub use lti::{LtiResponse, ModalState};
pub use offset::{Offset, OFFSET_PARAM};
pub use pulse::PulseResponse;
pub use rational::{Modal, Rational, RationalModel, TransferFunction};
pub use root::Root;
pub use signal::{local_breaks, Jacobian, Signal};
pub use simulate::{simulate, Simulation};
pub use sinusoid::Sinusoid;
pub use spectrum::{SpectralLine, Spectrum};
pub use superposition::{Channel, Superposition};
pub use zpk::Zpk;
