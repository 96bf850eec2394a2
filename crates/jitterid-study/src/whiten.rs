//! Residuals whitened by a fitted noise model's spectrum, for the correlation tests of
//! `validate`.
//!
//! With an ARMA noise model the residuals `y_k − m_k` are coloured by design: their spectrum is
//! `σ_e² (|H(f)|² + ρ)`, the ARMA shape plus the jitter's white floor `ρ = λ̄/σ_e²`
//! (`docs/experiments.md`, "Coloured noise and the jitter's floor"). Testing them for
//! whiteness would test the noise model's colour, not the fit; so the tests see the residuals
//! divided, bin by bin of the full DFT, by the square root of that spectrum (a zero-phase
//! whitening filter, circular over the record). The correlation tests are normalised, so the
//! level `σ_e²` does not matter.

use jitterid::window::{fft_in_place, Complex64};

/// `raw` whitened by the spectrum shape `shape(f)` (`f` in Hz, `0 ≤ f ≤ 1/(2T)`), or `None`
/// when the shape is not finite and positive at some bin.
pub fn whitened(raw: &[f64], interval: f64, shape: impl Fn(f64) -> f64) -> Option<Vec<f64>> {
    let n = raw.len();
    let mut x: Vec<Complex64> = raw.iter().map(|&v| Complex64::new(v, 0.0)).collect();
    fft_in_place(&mut x);
    for (j, bin) in x.iter_mut().enumerate() {
        // Bin j and bin N − j are the same |f| of a real sequence.
        let f = j.min(n - j) as f64 / (n as f64 * interval);
        let s = shape(f);
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        *bin = (*bin / s.sqrt()).conj();
    }
    // The inverse DFT as the conjugate of the forward DFT of the conjugate.
    fft_in_place(&mut x);
    Some(x.iter().map(|z| z.re / n as f64).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat shape changes nothing but the scale.
    #[test]
    fn a_flat_shape_only_scales() {
        let raw = [1.0, -2.0, 0.5, 3.0, -1.5];
        let w = whitened(&raw, 1.0, |_| 4.0).unwrap();
        for (a, b) in raw.iter().zip(&w) {
            assert!((a / 2.0 - b).abs() < 1e-12, "{a} {b}");
        }
    }

    /// Lag-1 autocorrelation.
    fn lag1(x: &[f64]) -> f64 {
        let m = x.iter().sum::<f64>() / x.len() as f64;
        let c0: f64 = x.iter().map(|v| (v - m) * (v - m)).sum();
        let c1: f64 = x.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum();
        c1 / c0
    }

    /// AR(1) noise `v_k = e_k + a v_{k−1}`, shape `1/|1 − a e^{−i2πfT}|²`: its lag-1
    /// autocorrelation is `a = 0.7`; whitened by that shape it is 0 within sampling error
    /// (standard error `1/√N = 0.016` for `N = 4096`; the bound is 4 standard errors).
    #[test]
    fn an_ar1_shape_whitens_ar1_noise() {
        let (a, n) = (0.7, 4096);
        // Uniform white driving noise from a fixed xorshift generator.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut v = Vec::with_capacity(n);
        let mut last = 0.0;
        for _ in 0..n {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let e = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            last = e + a * last;
            v.push(last);
        }
        let shape = |f: f64| {
            let z = Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * f);
            1.0 / (Complex64::new(1.0, 0.0) - a * z).norm_sqr()
        };
        let w = whitened(&v, 1.0, shape).unwrap();
        let bound = 4.0 / (n as f64).sqrt();
        assert!((lag1(&v) - a).abs() < bound, "raw lag 1: {}", lag1(&v));
        assert!(lag1(&w).abs() < bound, "whitened lag 1: {}", lag1(&w));
    }

    #[test]
    fn a_vanishing_shape_is_refused() {
        assert!(whitened(&[1.0, 2.0, 3.0], 1.0, |f| f).is_none());
    }
}
