//! Test-local signals with closed-form spectra, and a compensated reference DTFT.
#![allow(dead_code)]

use jitterid_signal::{Signal, SignalError, SpectralLine, Spectrum};
use num_complex::Complex64;
use std::f64::consts::{PI, TAU};

/// `s(t) = e^{-α(t - start)}` for `start ≤ t < start + len`, zero elsewhere (jumps at both ends).
/// `S_c(f) = e^{-i2πf start} (1 − e^{-(α+i2πf)len}) / (α + i2πf)`.
#[derive(Debug, Clone, PartialEq)]
pub struct ExpPulse {
    pub alpha: f64,
    pub start: f64,
    pub len: f64,
}

impl ExpPulse {
    fn z(&self, f: f64) -> Complex64 {
        Complex64::new(self.alpha, TAU * f)
    }
}

impl Signal for ExpPulse {
    fn param_names(&self) -> Vec<String> {
        vec!["alpha".into()]
    }
    fn params(&self) -> Vec<f64> {
        vec![self.alpha]
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        match params {
            [a] if a.is_finite() && *a > 0.0 => Ok(Self {
                alpha: *a,
                ..self.clone()
            }),
            [a] => Err(SignalError::NotPositive {
                name: "alpha",
                value: *a,
            }),
            _ => Err(SignalError::WrongParamCount {
                expected: 1,
                got: params.len(),
            }),
        }
    }
    fn value(&self, t: f64) -> f64 {
        let x = t - self.start;
        if (0.0..self.len).contains(&x) {
            (-self.alpha * x).exp()
        } else {
            0.0
        }
    }
    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        let x = t - self.start;
        grad[0] = if (0.0..self.len).contains(&x) {
            -x * (-self.alpha * x).exp()
        } else {
            0.0
        };
    }
    fn breakpoints(&self) -> Vec<f64> {
        vec![self.start, self.start + self.len]
    }
    fn rate(&self) -> f64 {
        self.alpha
    }
}

impl Spectrum for ExpPulse {
    fn density(&self, f: f64) -> Complex64 {
        let z = self.z(f);
        let shift = Complex64::from_polar(1.0, -TAU * f * self.start);
        shift * (1.0 - (-z * self.len).exp()) / z
    }
    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        let z = self.z(f);
        let e = (-z * self.len).exp();
        let shift = Complex64::from_polar(1.0, -TAU * f * self.start);
        grad[0] = shift * (self.len * e * z - (1.0 - e)) / (z * z);
    }
}

/// A Gaussian pulse `s(t) = A exp(-(t − c)²/(2w²))`: smooth, with
/// `S_c(f) = A w √(2π) e^{-2π²w²f²} e^{-i2πfc}`.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussPulse {
    pub amplitude: f64,
    pub centre: f64,
    pub width: f64,
}

impl Signal for GaussPulse {
    fn param_names(&self) -> Vec<String> {
        vec!["amplitude".into()]
    }
    fn params(&self) -> Vec<f64> {
        vec![self.amplitude]
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        match params {
            [a] => Ok(Self {
                amplitude: *a,
                ..self.clone()
            }),
            _ => Err(SignalError::WrongParamCount {
                expected: 1,
                got: params.len(),
            }),
        }
    }
    fn value(&self, t: f64) -> f64 {
        let x = (t - self.centre) / self.width;
        self.amplitude * (-0.5 * x * x).exp()
    }
    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        let x = (t - self.centre) / self.width;
        grad[0] = (-0.5 * x * x).exp();
    }
    fn rate(&self) -> f64 {
        3.0 / self.width
    }
}

impl Spectrum for GaussPulse {
    fn density(&self, f: f64) -> Complex64 {
        let w = self.width;
        let mag = self.amplitude * w * (2.0 * PI).sqrt() * (-2.0 * PI * PI * w * w * f * f).exp();
        Complex64::from_polar(mag, -TAU * f * self.centre)
    }
    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        grad[0] = self.density(f) / self.amplitude;
    }
}

/// A sum of cosines `Σ A_j cos(2πf_j t + φ_j)`: spectral lines only.
#[derive(Debug, Clone, PartialEq)]
pub struct Tones {
    /// `(A_j, f_j, φ_j)`.
    pub tones: Vec<(f64, f64, f64)>,
}

impl Signal for Tones {
    fn param_names(&self) -> Vec<String> {
        Vec::new()
    }
    fn params(&self) -> Vec<f64> {
        Vec::new()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        if params.is_empty() {
            Ok(self.clone())
        } else {
            Err(SignalError::WrongParamCount {
                expected: 0,
                got: params.len(),
            })
        }
    }
    fn value(&self, t: f64) -> f64 {
        self.tones
            .iter()
            .map(|&(a, f, p)| a * (TAU * f * t + p).cos())
            .sum()
    }
    fn value_gradient(&self, _t: f64, _grad: &mut [f64]) {}
    fn rate(&self) -> f64 {
        self.tones
            .iter()
            .fold(0.0, |r, &(_, f, _)| r.max(TAU * f.abs()))
    }
}

impl Spectrum for Tones {
    fn density(&self, _f: f64) -> Complex64 {
        Complex64::new(0.0, 0.0)
    }
    fn density_gradient(&self, _f: f64, _grad: &mut [Complex64]) {}
    fn lines(&self) -> Vec<SpectralLine> {
        self.tones
            .iter()
            .flat_map(|&(a, f, p)| {
                let c = Complex64::from_polar(0.5 * a, p);
                [
                    SpectralLine {
                        frequency: f,
                        coefficient: c,
                    },
                    SpectralLine {
                        frequency: -f,
                        coefficient: c.conj(),
                    },
                ]
            })
            .collect()
    }
}

/// The sum of two signals (parameters are not exposed).
#[derive(Debug, Clone, PartialEq)]
pub struct Sum<A, B>(pub A, pub B);

impl<A: Signal + Clone, B: Signal + Clone> Signal for Sum<A, B> {
    fn param_names(&self) -> Vec<String> {
        Vec::new()
    }
    fn params(&self) -> Vec<f64> {
        Vec::new()
    }
    fn with_params(&self, _params: &[f64]) -> Result<Self, SignalError> {
        Ok(self.clone())
    }
    fn value(&self, t: f64) -> f64 {
        self.0.value(t) + self.1.value(t)
    }
    fn value_gradient(&self, _t: f64, _grad: &mut [f64]) {}
    fn breakpoints(&self) -> Vec<f64> {
        let mut b = self.0.breakpoints();
        b.extend(self.1.breakpoints());
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }
    fn rate(&self) -> f64 {
        self.0.rate().max(self.1.rate())
    }
}

impl<A: Spectrum + Clone, B: Spectrum + Clone> Spectrum for Sum<A, B> {
    fn density(&self, f: f64) -> Complex64 {
        self.0.density(f) + self.1.density(f)
    }
    fn density_gradient(&self, _f: f64, _grad: &mut [Complex64]) {}
    fn lines(&self) -> Vec<SpectralLine> {
        let mut l = self.0.lines();
        l.extend(self.1.lines());
        l
    }
}

/// `(a·b) mod 1` in `[-0.5, 0.5]`, from an exact product (independent of the crate's code).
fn frac_of_product(a: f64, b: f64) -> f64 {
    let p = a * b;
    let e = a.mul_add(b, -p);
    let r = (p - p.round()) + e;
    r - r.round()
}

/// Kahan–Babuška compensated `Σ_k v_k e^{-i2πf kT}`, each phase reduced exactly and evaluated
/// with its own `sin_cos` (no recurrence): the reference for the DTFT tests.
pub fn reference_dtft(values: &[f64], f: f64, interval: f64) -> Complex64 {
    // f·T exactly as hi + lo, hi reduced.
    let p = f * interval;
    let lo = f.mul_add(interval, -p);
    let hi = p - p.round();
    let (mut re, mut im, mut cre, mut cim) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    let add = |s: &mut f64, c: &mut f64, x: f64| {
        let t = *s + x;
        if s.abs() >= x.abs() {
            *c += (*s - t) + x;
        } else {
            *c += (x - t) + *s;
        }
        *s = t;
    };
    for (k, &v) in values.iter().enumerate() {
        let kf = k as f64;
        let phase = frac_of_product(kf, hi) + kf * lo;
        let phase = phase - phase.round();
        let (s, c) = (TAU * phase).sin_cos();
        add(&mut re, &mut cre, v * c);
        add(&mut im, &mut cim, -v * s);
    }
    Complex64::new(re + cre, im + cim)
}
