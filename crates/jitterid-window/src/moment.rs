//! The first moment of the data's windowed DTFT, `μ_Y(f; θ) = E[Σ_k w_k y_k e^{-i2πfkT}]`,
//! computed two independent ways.
//!
//! With `y_k = s(t_k + τ_k) + v_k`, `t_k = t0 + kT`, zero-mean noise and iid jitter:
//!
//! * **Time domain (route b, production)**, [`first_moment`]:
//!   `μ_Y(f) = Σ_k w_k m_k e^{-i2πfkT}` with `m_k = E[s(t_k + τ)]` from
//!   [`Signal::expected_values`], transformed by [`transform`](crate::transform) (FFT on the
//!   DFT grid). Exact up to the accuracy of `m_k`.
//! * **Frequency domain (route a, reference)**, [`first_moment_integral`]: the literal
//!   eq. (14b) with the window kernel `K` in place of `Γ_N` (no `1/2π`, `f` in Hz),
//!   `μ_Y(f) = ∫ S_c(ψ) γ(-ψ) e^{i2πψ t0} K(f-ψ) dψ + Σ_l c_l γ(-f_l) e^{i2πf_l t0} K(f-f_l)`,
//!   using only [`Signal::density`], [`Signal::lines`] and [`JitterModel::cf`]. See
//!   [`first_moment_integral`] for how the infinite range and the oscillation are handled.
//!
//! The factor `e^{i2πψ t0}`: `s(t) = ∫ S_c(ψ) e^{i2πψt} dψ`, so
//! `E[s(t0 + kT + τ)] = ∫ S_c(ψ) e^{i2πψ t0} e^{i2πψkT} γ(-ψ) dψ` (as `E[e^{i2πψτ}] = γ(-ψ)`),
//! and `Σ_k w_k e^{-i2πfkT} e^{i2πψkT} = K(f-ψ)`. The DTFT's phase is referred to `kT`, the
//! samples sit at `t0 + kT`, and the difference is this factor.

mod integral;

pub use integral::{first_moment_integral, IntegralMoment, IntegralOptions};

use crate::dtft::transform_unchecked;
use crate::{FrequencySet, Window};
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};
use num_complex::Complex64;

/// `μ_Y(f) = Σ_k w_k m_k e^{-i2πfkT}` at every frequency of the set, with
/// `m_k = E[s(t_k + τ)]` from [`Signal::expected_values`] (route b, the production route).
///
/// Infallible: a grid and a frequency set are valid by construction. A signal that breaks its
/// contract (`expected_values` of the wrong length, or non-finite) yields NaN outputs.
pub fn first_moment<S, W>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    window: &W,
    freqs: &FrequencySet,
) -> Vec<Complex64>
where
    S: Signal + ?Sized,
    W: Window + ?Sized,
{
    let m = signal.expected_values(grid, jitter);
    transform_unchecked(grid, window, &m, freqs)
}
