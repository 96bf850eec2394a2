//! Zeros, poles and gain `k Π(s − z_i) / Π(s − p_i)`.

use super::TfForm;
use crate::error::{finite, SignalError};
use num_complex::Complex64;

/// Relative tolerance for a root's complex-conjugate partner.
const CONJUGATE_TOL: f64 = 1e-9;

/// `G(s) = k Π(s − z_i) / Π(s − p_i)` with complex roots in conjugate pairs (so that the
/// coefficients are real), at least one pole and no more zeros than poles. Roots are kept in
/// the order given; repeated roots are listed once per multiplicity.
///
/// Serializes as `{"gain": k, "zeros": [[re, im], …], "poles": [[re, im], …]}`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ZpkForm {
    gain: f64,
    zeros: Vec<Complex64>,
    poles: Vec<Complex64>,
}

impl ZpkForm {
    /// Validates finite values, at least one pole, no more zeros than poles, and that every
    /// non-real root has its conjugate in the same list (to a relative `1e-9`).
    pub fn new(
        gain: f64,
        zeros: Vec<Complex64>,
        poles: Vec<Complex64>,
    ) -> Result<Self, SignalError> {
        finite("gain", gain)?;
        if poles.is_empty() {
            return Err(SignalError::TooFew {
                name: "poles",
                min: 1,
                value: 0,
            });
        }
        if zeros.len() > poles.len() {
            return Err(SignalError::Improper {
                zeros: zeros.len(),
                poles: poles.len(),
            });
        }
        jitterid_numeric::limits::check(jitterid_numeric::limits::Limit::Poles, poles.len())?;
        conjugate_closed("zero", &zeros)?;
        conjugate_closed("pole", &poles)?;
        Ok(Self { gain, zeros, poles })
    }

    /// The gain `k` (the numerator's leading coefficient over the denominator's).
    pub fn gain(&self) -> f64 {
        self.gain
    }

    /// The zeros.
    pub fn zeros(&self) -> &[Complex64] {
        &self.zeros
    }

    /// The poles.
    pub fn poles(&self) -> &[Complex64] {
        &self.poles
    }

    /// `G(s)` at complex `s` (rad/s).
    pub fn response(&self, s: Complex64) -> Complex64 {
        let num: Complex64 = self.zeros.iter().map(|z| s - z).product();
        let den: Complex64 = self.poles.iter().map(|p| s - p).product();
        self.gain * num / den
    }

    /// The coefficients, by expanding the products (the imaginary parts, zero up to rounding
    /// for conjugate-closed roots, are dropped). Fails only when a coefficient overflows.
    pub fn to_tf(&self) -> Result<TfForm, SignalError> {
        let num: Vec<f64> = expand(&self.zeros).iter().map(|c| self.gain * c).collect();
        TfForm::new(&num, &expand(&self.poles))
    }
}

/// The real coefficients of `Π(s − r_i)`, highest power first.
fn expand(roots: &[Complex64]) -> Vec<f64> {
    let mut p = vec![Complex64::new(1.0, 0.0)];
    for r in roots {
        let mut next = vec![Complex64::new(0.0, 0.0); p.len() + 1];
        for (i, c) in p.iter().enumerate() {
            next[i] += c;
            next[i + 1] -= c * r;
        }
        p = next;
    }
    p.iter().map(|c| c.re).collect()
}

fn conjugate_closed(name: &'static str, roots: &[Complex64]) -> Result<(), SignalError> {
    for r in roots {
        finite(name, r.re)?;
        finite(name, r.im)?;
    }
    let mut used = vec![false; roots.len()];
    for (i, r) in roots.iter().enumerate() {
        if r.im == 0.0 || used[i] {
            continue;
        }
        let tol = CONJUGATE_TOL * r.norm().max(1.0);
        let partner =
            (0..roots.len()).find(|&j| j != i && !used[j] && (roots[j] - r.conj()).norm() <= tol);
        match partner {
            Some(j) => {
                used[i] = true;
                used[j] = true;
            }
            None => {
                return Err(SignalError::Unpaired {
                    name,
                    re: r.re,
                    im: r.im,
                })
            }
        }
    }
    Ok(())
}
