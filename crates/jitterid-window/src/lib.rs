//! Frequency transforms for **jitterid**: the DTFT and FFT of a record, data windows and their
//! kernels (the Dirichlet kernel `Γ_N`), and the first moment `μ_Y(f; θ)` of the data's DTFT
//! under sampling jitter.
//!
//! # Conventions
//!
//! These follow the conventions of `docs/method.md`:
//!
//! * Time in seconds, frequency in **Hz**; there is no `1/(2π)` anywhere (the paper's factor in
//!   eqs. (11), (13), (14b) belongs to an angular-frequency convention).
//! * Samples are requested at `t_k = t0 + kT`, `k = 0..N-1` ([`SampleGrid`]) and taken at
//!   `t_k + τ_k`: `y_k = s(t_k + τ_k) + v_k`.
//! * DTFT with the phase referred to `kT` (to the record's first instant `t0`):
//!   `Y(f) = Σ_k w_k y_k e^{-i2πf kT}`, periodic in `f` with period `1/T`; the plain DTFT has
//!   `w_k = 1` ([`DirichletWindow`]).
//! * Dirichlet kernel `Γ_N(ν) = Σ_k e^{-i2πνkT} = e^{-iπν(N-1)T} sin(πνNT)/sin(πνT)`, exactly
//!   `N` at `ν = m/T` ([`dirichlet`]). A window's kernel is `K(ν) = Σ_k w_k e^{-i2πνkT}`.
//! * Jitter characteristic function `γ(f) = E[e^{-i2πfτ}]` ([`JitterModel::cf`]).
//! * First moment, two ways (they agree; tests hold them equal):
//!   - time domain: `μ_Y(f) = Σ_k w_k m_k e^{-i2πfkT}`, `m_k = E[s(t_k + τ)]`
//!     ([`first_moment`], the production route);
//!   - frequency domain, the paper's eq. (14b):
//!     `μ_Y(f) = ∫ S_c(ψ) γ(-ψ) e^{i2πψ t0} K(f-ψ) dψ` (+ the signal's spectral lines)
//!     ([`first_moment_integral`], the reference route). The factor `e^{i2πψ t0}` is there
//!     because the phase is referred to `kT` while the samples sit at `t0 + kT`.
//! * Parseval on the full DFT grid `f_j = j/(NT)`, `j = 0..N-1`:
//!   `Σ_j |Y(f_j)|² = N Σ_k y_k²` (rectangular window).
//!
//! # Tutorial
//!
//! A record of `N = 8` samples with `T = 0.5 s`, starting at `t0 = 2 s`:
//!
//! ```
//! use jitterid_signal::SampleGrid;
//! use jitterid_window::{dtft, transform, DirichletWindow, FrequencySet, HannWindow, Window};
//!
//! let grid = SampleGrid::new(2.0, 0.5, 8).unwrap();
//! let y = [0.0, 1.0, 0.5, -0.25, 0.0, 0.75, 1.0, 0.5];
//!
//! // The paper's default frequencies: the DFT grid j/(NT), 0 ≤ j ≤ N/2 (0, 0.25, …, 1 Hz).
//! let freqs = FrequencySet::dft(&grid);
//! assert_eq!(freqs.len(), 5);
//!
//! // The windowed DTFT at those frequencies (an FFT when it pays off).
//! let yf = transform(&grid, &DirichletWindow, &y, &freqs).unwrap();
//! // The same numbers by the direct DTFT, which accepts any frequency.
//! let direct = dtft(&grid, &y, None, freqs.frequencies()).unwrap();
//! for (a, b) in yf.iter().zip(&direct) {
//!     assert!((a - b).norm() < 1e-12);
//! }
//!
//! // The kernel of the rectangular window is the Dirichlet kernel: N at ν = m/T.
//! let k = DirichletWindow.kernel(&grid, 2.0); // 2 Hz = 1/T
//! assert!((k.re - 8.0).abs() < 1e-12 && k.im.abs() < 1e-12);
//! // A Hann taper has its own kernel; the criterion with a Hann window uses it throughout.
//! let weights = HannWindow.weights(8);
//! assert_eq!(weights[0], 0.0);
//! ```
//!
//! The first moment of a model, under jitter, two ways (route (a) reports an error bound):
//!
//! ```
//! use jitterid_jitter::Gaussian;
//! use jitterid_signal::{SampleGrid, Sinusoid};
//! use jitterid_window::{
//!     first_moment, first_moment_integral, DirichletWindow, FrequencySet, IntegralOptions,
//! };
//!
//! let grid = SampleGrid::new(0.3, 1.0, 64).unwrap();
//! let signal = Sinusoid::new(1.0, 0.11, 0.4).unwrap();
//! let jitter = Gaussian::new(0.05).unwrap();
//! let freqs = FrequencySet::dft(&grid);
//!
//! let b = first_moment(&signal, &jitter, &grid, &DirichletWindow, &freqs);
//! let a = first_moment_integral(
//!     &signal, &jitter, &grid, &DirichletWindow, &freqs, &IntegralOptions::default(),
//! )
//! .unwrap();
//! for ((x, y), bound) in a.values.iter().zip(&b).zip(&a.error_bounds) {
//!     assert!((x - y).norm() <= bound + 1e-12);
//! }
//! ```
//!
//! # Modules
//!
//! * [`Window`], [`DirichletWindow`], [`HannWindow`], [`dirichlet`]: tapers and kernels.
//! * [`FrequencySet`]: validated frequency sets that remember the DFT grid.
//! * [`dtft()`], [`fft_grid`], [`transform`]: transforms of a record.
//! * [`moment`]: the first moment `μ_Y`, both routes.
//! * [`WindowError`]: everything that can go wrong.
//! * [`testing`]: the contract every [`Window`] must meet, as a check to run in tests.
#![warn(missing_docs)]

mod direct;
mod dtft;
mod error;
mod frequencies;
pub mod moment;
pub mod testing;
mod window;

pub use dtft::{dtft, fft_grid, fft_in_place, transform};
pub use error::WindowError;
pub use frequencies::FrequencySet;
pub use moment::{first_moment, first_moment_integral, IntegralMoment, IntegralOptions};
pub use num_complex::{self, Complex64};
pub use window::{dirichlet, DirichletWindow, HannWindow, Window};

#[doc(no_inline)]
pub use jitterid_jitter::JitterModel;
#[doc(no_inline)]
pub use jitterid_signal::{SampleGrid, Signal, Spectrum};
