//! A single sinusoid `s(t) = A sin(2πf0 t + φ)`, whose jittered moments are closed forms in the
//! jitter's characteristic function.

use crate::error::{finite, SignalError};
use crate::{Jacobian, SampleGrid, Signal, SpectralLine, Spectrum};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// A sinusoid `s(t) = A sin(2πf0 t + φ)` with parameters `θ = [A, f0, φ]`
/// (`"amplitude"`, `"frequency"` in Hz, `"phase"` in radians).
///
/// Its transform is two spectral lines, at `±f0` with coefficients `A e^{±iφ}/(±2i)`, and no
/// density. Under jitter, with `θ_k = 2πf0 t_k + φ` and `γ(f) = E[e^{-i2πfτ}]`,
///
/// * `m_k = E[s(t_k + τ)] = A · Im(e^{iθ_k} γ(-f0))`,
/// * `E[s(t_k + τ)²] = A²/2 · (1 − Re(e^{i2θ_k} γ(-2f0)))`,
///
/// which [`Signal::expected_values`] and [`Signal::expected_squares`] use instead of
/// quadrature.
///
/// Deserializes through [`Sinusoid::new`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "SinusoidFields")]
pub struct Sinusoid {
    amplitude: f64,
    frequency: f64,
    phase: f64,
}

impl Sinusoid {
    /// `A sin(2πf0 t + φ)`. All values finite and `f0 ≥ 0` (a negative frequency is the same
    /// signal as `(−A, −f0, −φ)`, so it is rejected rather than silently accepted).
    pub fn new(amplitude: f64, frequency: f64, phase: f64) -> Result<Self, SignalError> {
        finite("amplitude", amplitude)?;
        finite("frequency", frequency)?;
        if frequency < 0.0 {
            // Same convention as `Multisine`: there is no dedicated "must be ≥ 0" variant.
            return Err(SignalError::NotPositive {
                name: "frequency",
                value: frequency,
            });
        }
        finite("phase", phase)?;
        Ok(Self {
            amplitude,
            frequency,
            phase,
        })
    }

    /// Amplitude `A`.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// Frequency `f0` in Hz.
    pub fn frequency(&self) -> f64 {
        self.frequency
    }

    /// Phase `φ` in radians.
    pub fn phase(&self) -> f64 {
        self.phase
    }

    /// The argument `2πf0 t + φ` at time `t`.
    fn angle(&self, t: f64) -> f64 {
        TAU * self.frequency * t + self.phase
    }

    /// Coefficient of the line at `+f0`: `A e^{iφ}/(2i)`.
    fn positive_coefficient(&self) -> Complex64 {
        Complex64::cis(self.phase) * Complex64::new(0.0, -0.5 * self.amplitude)
    }
}

impl Signal for Sinusoid {
    fn param_names(&self) -> Vec<String> {
        ["amplitude", "frequency", "phase"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    fn params(&self) -> Vec<f64> {
        vec![self.amplitude, self.frequency, self.phase]
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        match params {
            &[a, f0, phi] => Self::new(a, f0, phi),
            _ => Err(SignalError::WrongParamCount {
                expected: 3,
                got: params.len(),
            }),
        }
    }

    fn value(&self, t: f64) -> f64 {
        self.amplitude * self.angle(t).sin()
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        let (sin, cos) = self.angle(t).sin_cos();
        let out = [sin, self.amplitude * cos * TAU * t, self.amplitude * cos];
        for (g, v) in grad.iter_mut().zip(out) {
            *g = v;
        }
    }

    fn rate(&self) -> f64 {
        TAU * self.frequency
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        // γ(-f0) = E[e^{i2πf0τ}].
        let g = jitter.cf(-self.frequency);
        grid.times()
            .map(|t| self.amplitude * (Complex64::cis(self.angle(t)) * g).im)
            .collect()
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let g = jitter.cf(-self.frequency);
        // q = E[τ e^{i2πf0τ}] for the f0-derivative: the rule resolves e^{i2πf0τ} (and the
        // polynomial factor τ) to near machine precision, with no differencing of γ.
        let rule = jitter.rule(&[], self.rate());
        let q: Complex64 = rule
            .nodes
            .iter()
            .zip(&rule.weights)
            .map(|(&tau, &w)| w * tau * Complex64::cis(TAU * self.frequency * tau))
            .sum();
        let mut cols: Jacobian = (0..3).map(|_| Vec::with_capacity(grid.len())).collect();
        for t in grid.times() {
            let e = Complex64::cis(self.angle(t));
            let z = e * g;
            cols[0].push(z.im);
            // ∂/∂f0 E[A sin(θ + 2πf0τ)] = 2πA Re(e^{iθ} E[(t + τ) e^{i2πf0τ}]).
            cols[1].push(TAU * self.amplitude * (e * (g * t + q)).re);
            cols[2].push(self.amplitude * z.re);
        }
        cols
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        // sin² x = (1 − cos 2x)/2, and E[cos(2θ + 4πf0τ)] = Re(e^{i2θ} γ(-2f0)).
        let g2 = jitter.cf(-2.0 * self.frequency);
        let half_power = 0.5 * self.amplitude * self.amplitude;
        grid.times()
            .map(|t| half_power * (1.0 - (Complex64::cis(2.0 * self.angle(t)) * g2).re))
            .collect()
    }
}

impl Spectrum for Sinusoid {
    fn density(&self, _f: f64) -> Complex64 {
        Complex64::new(0.0, 0.0)
    }

    fn density_gradient(&self, _f: f64, grad: &mut [Complex64]) {
        grad.fill(Complex64::new(0.0, 0.0));
    }

    fn lines(&self) -> Vec<SpectralLine> {
        let c = self.positive_coefficient();
        vec![
            SpectralLine {
                frequency: self.frequency,
                coefficient: c,
            },
            SpectralLine {
                frequency: -self.frequency,
                coefficient: c.conj(),
            },
        ]
    }

    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        let zero = Complex64::new(0.0, 0.0);
        // c = A e^{iφ}/(2i): ∂c/∂A = e^{iφ}/(2i), ∂c/∂φ = i c; the frequency moves the line only.
        let dc_da = Complex64::cis(self.phase) * Complex64::new(0.0, -0.5);
        let dc_dphi = Complex64::i() * self.positive_coefficient();
        vec![
            vec![(dc_da, 0.0), (zero, 1.0), (dc_dphi, 0.0)],
            vec![(dc_da.conj(), 0.0), (zero, -1.0), (dc_dphi.conj(), 0.0)],
        ]
    }
}

/// The serialized form of a [`Sinusoid`], validated on the way in.
#[derive(serde::Deserialize)]
struct SinusoidFields {
    amplitude: f64,
    frequency: f64,
    phase: f64,
}

impl TryFrom<SinusoidFields> for Sinusoid {
    type Error = SignalError;
    fn try_from(s: SinusoidFields) -> Result<Self, SignalError> {
        Self::new(s.amplitude, s.frequency, s.phase)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine() -> Sinusoid {
        Sinusoid::new(1.3, 0.27, 0.4).unwrap()
    }

    #[test]
    fn constructor_validates() {
        assert!(matches!(
            Sinusoid::new(1.0, -0.1, 0.0),
            Err(SignalError::NotPositive {
                name: "frequency",
                ..
            })
        ));
        assert!(matches!(
            Sinusoid::new(f64::NAN, 0.1, 0.0),
            Err(SignalError::NotFinite {
                name: "amplitude",
                ..
            })
        ));
        assert!(matches!(
            Sinusoid::new(1.0, 0.1, f64::INFINITY),
            Err(SignalError::NotFinite { name: "phase", .. })
        ));
        assert!(Sinusoid::new(-2.0, 0.0, 1.0).is_ok());
        assert_eq!(
            sine().with_params(&[1.0, 2.0]),
            Err(SignalError::WrongParamCount {
                expected: 3,
                got: 2
            })
        );
        let s = sine().with_params(&[2.0, 0.5, -1.0]).unwrap();
        assert_eq!(s.params(), vec![2.0, 0.5, -1.0]);
        assert_eq!(s.param_names(), vec!["amplitude", "frequency", "phase"]);
    }

    #[test]
    fn lines_reproduce_the_signal() {
        let s = sine();
        for &t in &[-3.1, 0.0, 0.7, 12.25] {
            let sum: Complex64 = s
                .lines()
                .iter()
                .map(|l| l.coefficient * Complex64::cis(TAU * l.frequency * t))
                .sum();
            assert!((sum.re - s.value(t)).abs() < 1e-14, "{t}");
            assert!(sum.im.abs() < 1e-14);
        }
        assert_eq!(s.density(0.3), Complex64::new(0.0, 0.0));
        assert!(s.breakpoints().is_empty());
    }

    #[test]
    fn gradients_match_central_differences() {
        let s = sine();
        let p = s.params();
        let h = 1e-6;
        let mut grad = [0.0; 3];
        let lg = s.lines_gradient();
        for j in 0..3 {
            let mut up = p.clone();
            let mut dn = p.clone();
            up[j] += h;
            dn[j] -= h;
            let (su, sd) = (s.with_params(&up).unwrap(), s.with_params(&dn).unwrap());
            for &t in &[-2.0, 0.3, 5.5] {
                s.value_gradient(t, &mut grad);
                let fd = (su.value(t) - sd.value(t)) / (2.0 * h);
                assert!((grad[j] - fd).abs() < 1e-8, "value θ{j} t={t}");
            }
            for (l, (lu, ld)) in su.lines().iter().zip(sd.lines()).enumerate() {
                let dc = (lu.coefficient - ld.coefficient) / (2.0 * h);
                let df = (lu.frequency - ld.frequency) / (2.0 * h);
                assert!((lg[l][j].0 - dc).norm() < 1e-8, "line {l} θ{j}");
                assert!((lg[l][j].1 - df).abs() < 1e-8, "line {l} θ{j}");
            }
        }
    }
}
