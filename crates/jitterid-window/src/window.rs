//! Data windows (tapers) and their kernels.
//!
//! A window multiplies the samples before the transform: `Y_w(f) = Σ_k w_k y_k e^{-i2πfkT}`.
//! Its *kernel* is the transform of the weights, `K(ν) = Σ_k w_k e^{-i2πνkT}`, which replaces
//! the Dirichlet kernel `Γ_N` in the first moment (eq. 14b):
//! `μ_Y(f) = ∫ S_c(ψ) γ(-ψ) e^{i2πψ t0} K(f-ψ) dψ`.

use crate::direct::dtft_at;
use jitterid_numeric::phase::{cis_neg_half_cycles, sin_pi_times, Cycles};
use jitterid_signal::SampleGrid;
use num_complex::Complex64;
use std::f64::consts::PI;
use std::fmt::Debug;

/// A data window: the taper `w_k`, `k = 0..n-1`, applied to a record of `n` samples.
///
/// Only [`weight`](Self::weight) is required. The generic [`kernel`](Self::kernel) costs
/// `O(N)` per call; a window with a closed form overrides it.
pub trait Window: Debug + Send + Sync {
    /// The taper value `w_k` for sample `k` of a record of `n` samples. Returns `0.0` for
    /// `k ≥ n`.
    fn weight(&self, k: usize, n: usize) -> f64;

    /// All `n` taper values `w_0, …, w_{n-1}`.
    fn weights(&self, n: usize) -> Vec<f64> {
        (0..n).map(|k| self.weight(k, n)).collect()
    }

    /// The kernel `K(ν) = Σ_{k=0}^{N-1} w_k e^{-i2πνkT}` for the record `grid` (only `N` and
    /// `T` matter), at `ν` in Hz. Periodic in `ν` with period `1/T`. Evaluated with the
    /// stable DTFT of the weights ([`dtft`](crate::dtft())): `O(N)`. A non-finite `ν` gives
    /// NaN.
    fn kernel(&self, grid: &SampleGrid, nu: f64) -> Complex64 {
        let w = self.weights(grid.len());
        dtft_at(&w, Cycles::new(nu, grid.interval()))
    }

    /// Whether every weight is 1 (the rectangular window, whose kernel is the Dirichlet
    /// kernel `Γ_N`). Transforms skip the multiplication when it is.
    fn is_rectangular(&self) -> bool {
        false
    }
}

/// A shared window is the window it shares: run-time choices (a window held as
/// `Arc<dyn Window>` in fit options) work wherever a window type does.
impl<W: Window + ?Sized> Window for std::sync::Arc<W> {
    fn weight(&self, k: usize, n: usize) -> f64 {
        (**self).weight(k, n)
    }
    fn weights(&self, n: usize) -> Vec<f64> {
        (**self).weights(n)
    }
    fn kernel(&self, grid: &SampleGrid, nu: f64) -> Complex64 {
        (**self).kernel(grid, nu)
    }
    fn is_rectangular(&self) -> bool {
        (**self).is_rectangular()
    }
}

/// The rectangular window `w_k = 1`: the plain DTFT, with the Dirichlet kernel
/// `Γ_N(ν) = e^{-iπν(N-1)T} sin(πνNT)/sin(πνT)` as its kernel. This is the paper's choice.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DirichletWindow;

impl Window for DirichletWindow {
    fn weight(&self, k: usize, n: usize) -> f64 {
        if k < n {
            1.0
        } else {
            0.0
        }
    }

    /// The closed form of `Γ_N(ν)`, `O(1)`: exactly `N` at `ν = m/T` and accurate near it
    /// (see [`dirichlet`]).
    fn kernel(&self, grid: &SampleGrid, nu: f64) -> Complex64 {
        dirichlet(grid, nu)
    }

    fn is_rectangular(&self) -> bool {
        true
    }
}

/// The periodic ("DFT-even") Hann window `w_k = 0.5 − 0.5 cos(2πk/N)`, `k = 0..N-1`.
///
/// This is the periodic variant, not the symmetric one (`cos(2πk/(N-1))`): its weights are
/// `0.5 − 0.25 e^{i2πk/N} − 0.25 e^{-i2πk/N}`, so its kernel is the closed form
/// `K(ν) = 0.5 Γ_N(ν) − 0.25 Γ_N(ν − 1/(NT)) − 0.25 Γ_N(ν + 1/(NT))`, and on the DFT grid
/// it is exactly the three-tap smoothing of the rectangular DFT. `w_0 = 0`; for `N = 1`
/// the only weight is 0.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct HannWindow;

impl Window for HannWindow {
    fn weight(&self, k: usize, n: usize) -> f64 {
        if k >= n {
            return 0.0;
        }
        // Reduce k/n to [0, 1) exactly before the cosine; 1 - cos = 2 sin² avoids cancellation
        // near k = 0.
        let s = (PI * (k as f64 / n as f64)).sin();
        s * s
    }

    /// Closed form from three shifted Dirichlet kernels, `O(1)`.
    fn kernel(&self, grid: &SampleGrid, nu: f64) -> Complex64 {
        let n = grid.len();
        let x = Cycles::new(nu, grid.interval());
        let d = 1.0 / n as f64;
        0.5 * dirichlet_cycles(n, x)
            - 0.25 * dirichlet_cycles(n, x.shifted(-d))
            - 0.25 * dirichlet_cycles(n, x.shifted(d))
    }
}

/// The Dirichlet kernel `Γ_N(ν) = Σ_{k=0}^{N-1} e^{-i2πνkT} = e^{-iπν(N-1)T} sin(πνNT)/sin(πνT)`
/// in closed form, `O(1)`.
///
/// `νT` is first reduced modulo 1 exactly (to `r ∈ [-1/2, 1/2]`, using the identity
/// `Γ_N(ν) = e^{-iπ(N-1)r} sin(πNr)/sin(πr)`), so the result is exactly `N` at `ν = m/T` and
/// accurate for any `ν`; near the integers (`|πNr| < 1e-3`) the ratio of sines is replaced by
/// its series `N[1 − (N²−1)(πr)²/6 + (3N⁴−10N²+7)(πr)⁴/360]`, so there is no `0/0`. A
/// non-finite `ν` gives NaN.
pub fn dirichlet(grid: &SampleGrid, nu: f64) -> Complex64 {
    dirichlet_cycles(grid.len(), Cycles::new(nu, grid.interval()))
}

/// `Γ_N` at `x` cycles per sample.
pub(crate) fn dirichlet_cycles(n: usize, x: Cycles) -> Complex64 {
    if !x.is_finite() {
        return Complex64::new(f64::NAN, f64::NAN);
    }
    let nf = n as f64;
    let r = x.value();
    let pr = PI * r;
    let ratio = if (pr * nf).abs() < 1e-3 {
        let p2 = pr * pr;
        let n2 = nf * nf;
        nf * (1.0 - (n2 - 1.0) * p2 / 6.0 + (3.0 * n2 * n2 - 10.0 * n2 + 7.0) * p2 * p2 / 360.0)
    } else {
        sin_pi_times(x, nf) / pr.sin()
    };
    ratio * cis_neg_half_cycles(x.times_mod2(nf - 1.0))
}
