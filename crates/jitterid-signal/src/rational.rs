//! Proper continuous-time transfer functions `G(s) = N(s)/A(s)`: the `Rational` core with its
//! modal (partial-fraction) form and parameter derivatives where the poles are distinct and
//! strictly stable, the `RationalModel` trait, and the coefficient parameterisation
//! `TransferFunction`. The zero–pole–gain one is in `zpk.rs`, its roots in `root.rs`, repeated
//! poles in `confluent.rs`; the tests here check both parameterisations against each other.

use crate::coefficients::Coefficients;
use crate::confluent::Confluent;
use crate::error::{all_finite, tf_coefficients, SignalError};
use crate::poly;
use num_complex::Complex64;
use std::fmt;

/// Relative distance (to the larger of `|p|` and 1) below which two poles are taken as
/// repeated, and the response goes by the confluent route instead of the modal form: the
/// modal form's rounding error grows like `ε/gap` in `s` and `ε/gap²` in its gradient, which at
/// this gap are `2e-12` and `2e-8` of the response's scale.
const CONFLUENT_GAP: f64 = 1e-4;

/// Relative real part (to the larger of `|p|` and 1) up to which a pole right of the axis counts
/// as on it (marginally stable: an integrator, an undamped oscillator): the rounding of a root
/// on the axis by a root finder, a few `ε`. Beyond it a pole is unstable. Kept that narrow on
/// purpose: a search that pushes a pair towards the axis is stopped there, as before, instead
/// of going on along the axis (where a lightly damped pair costs the realisation `|p|/|Re p|`
/// quadrature nodes).
const MARGINAL: f64 = 1e-13;

/// A pole closer to the origin than this fraction of the smaller of 1 rad/s and the largest
/// pole modulus is taken as an integrator. The modal form's step response `G(0) + Σ (r_i/p_i)
/// e^{p_i t}` cancels terms of size `|r/p|` there (a root at 0 of a polynomial comes out of a
/// root finder as a few `ε`; a search may pass through `10⁻¹⁰`), losing `ε|r/p|` of the
/// response; the realisation has no such term.
const ORIGIN: f64 = 1e-6;

/// The modal form `G(s) = D + Σ_i r_i / (s − p_i)` over all poles (conjugate pairs appear as
/// two entries), with derivatives of `D`, `p_i`, `r_i` and `G(0)` with respect to each parameter.
///
/// It exists for models whose poles are distinct and strictly stable
/// ([`Rational::modal`]); the others (repeated poles, integrators) are evaluated through a
/// state-space realisation instead.
///
/// Derived from a [`Rational`] (serialized, not deserialized: read the rational model instead).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Modal {
    /// Direct feed-through `D = G(∞)`.
    pub direct: f64,
    /// Poles `p_i` (distinct, `Re p_i < 0`).
    pub poles: Vec<Complex64>,
    /// Residues `r_i`.
    pub residues: Vec<Complex64>,
    /// Static gain `G(0)`.
    pub dc_gain: f64,
    /// `∂p_i/∂θ_j` as `[i][j]`.
    pub d_poles: Vec<Vec<Complex64>>,
    /// `∂r_i/∂θ_j` as `[i][j]`.
    pub d_residues: Vec<Vec<Complex64>>,
    /// `∂G(0)/∂θ_j`.
    pub d_dc_gain: Vec<f64>,
}

/// `N(s)/A(s)` with `A` monic, the coefficient derivatives, and the modal form: the validated
/// core of every [`RationalModel`].
///
/// A parameterisation outside this crate builds one with [`Rational::new`] from its
/// coefficients and their derivatives with respect to its parameters, and returns it from
/// [`RationalModel::rational`]. Serializes as those coefficients; deserializes through
/// [`Rational::new`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "RationalFields", into = "RationalFields")]
pub struct Rational {
    num: Vec<f64>,
    den: Vec<f64>,
    /// Per parameter, the derivatives of `num`'s coefficients.
    pub(crate) d_num: Vec<Vec<f64>>,
    d_den: Vec<Vec<f64>>,
    poles: Vec<Complex64>,
    modal: Option<Modal>,
    /// Whether poles right of the imaginary axis are accepted.
    pub(crate) unstable: bool,
}

impl Rational {
    /// `N(s)/A(s)` from coefficients in decreasing powers, with `A` monic (leading
    /// coefficient exactly 1) and of degree at least 1, `N` of degree at most that of `A`;
    /// `d_num[j]`, `d_den[j]` are the derivatives of the coefficients with respect to parameter
    /// `j` (one pair per parameter, each no longer than its polynomial, right-aligned: a
    /// shorter row is padded with leading zeros; `A` stays monic, so a row of `d_den` as long
    /// as `A` has a leading 0). The poles are the roots of `A`: stable or on the imaginary
    /// axis (integrators, undamped modes), distinct or repeated.
    pub fn new(
        num: Vec<f64>,
        den: Vec<f64>,
        d_num: Vec<Vec<f64>>,
        d_den: Vec<Vec<f64>>,
    ) -> Result<Self, SignalError> {
        Self::build(num, den, d_num, d_den, false)
    }

    fn build(
        num: Vec<f64>,
        den: Vec<f64>,
        d_num: Vec<Vec<f64>>,
        d_den: Vec<Vec<f64>>,
        unstable: bool,
    ) -> Result<Self, SignalError> {
        tf_coefficients(&num, &den)?;
        if den[0] != 1.0 {
            return Err(SignalError::NotMonic { lead: den[0] });
        }
        let degree = num
            .iter()
            .position(|&c| c != 0.0)
            .map_or(0, |i| num.len() - 1 - i);
        if degree > den.len() - 1 {
            return Err(SignalError::Improper {
                zeros: degree,
                poles: den.len() - 1,
            });
        }
        if d_num.len() != d_den.len() {
            return Err(SignalError::WrongLength {
                name: "d_den",
                expected: d_num.len(),
                got: d_den.len(),
            });
        }
        for (d, len, name) in [(&d_num, num.len(), "d_num"), (&d_den, den.len(), "d_den")] {
            for row in d.iter() {
                all_finite(name, row)?;
                if row.len() > len {
                    return Err(SignalError::WrongLength {
                        name,
                        expected: len,
                        got: row.len(),
                    });
                }
            }
        }
        let num = poly::pad(&num[num.len() - 1 - degree..], den.len());
        let poles = poly::roots(&den).ok_or(SignalError::Roots { name: "den" })?;
        Self::with_poles(num, den, poles, d_num, d_den, unstable)
    }

    /// As [`new`](Self::new), but poles right of the imaginary axis are accepted too (a
    /// record is finite, so its response is; an estimate may then cross the axis).
    pub fn new_allowing_unstable(
        num: Vec<f64>,
        den: Vec<f64>,
        d_num: Vec<Vec<f64>>,
        d_den: Vec<Vec<f64>>,
    ) -> Result<Self, SignalError> {
        Self::build(num, den, d_num, d_den, true)
    }

    /// Builds and validates: `num` padded to `den`'s length, `den` monic, `poles` the roots of
    /// `den` (known exactly by the caller); `d_num[j]`, `d_den[j]` are the coefficient
    /// derivatives for parameter `j`.
    pub(crate) fn with_poles(
        num: Vec<f64>,
        den: Vec<f64>,
        poles: Vec<Complex64>,
        d_num: Vec<Vec<f64>>,
        d_den: Vec<Vec<f64>>,
        unstable: bool,
    ) -> Result<Self, SignalError> {
        for p in &poles {
            if (!unstable && p.re > MARGINAL * p.norm().max(1.0)) || !p.re.is_finite() {
                return Err(SignalError::Unstable { re: p.re, im: p.im });
            }
        }
        // The modal form only where it is accurate: poles left of the axis, none at the origin
        // (whose `r/p` would be a cancellation of huge terms), well separated.
        let largest = poles.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let modal_form = poles
            .iter()
            .all(|p| p.re < 0.0 && p.norm() > ORIGIN * largest.min(1.0))
            && poles.iter().enumerate().all(|(i, p)| {
                poles[i + 1..]
                    .iter()
                    .all(|q| (p - q).norm() > CONFLUENT_GAP * p.norm().max(q.norm()).max(1.0))
            });
        let n = den.len();
        let num = poly::pad(&num, n);
        let d_num: Vec<Vec<f64>> = d_num.iter().map(|d| poly::pad(d, n)).collect();
        let d_den: Vec<Vec<f64>> = d_den.iter().map(|d| poly::pad(d, n)).collect();
        if !modal_form {
            return Ok(Self {
                num,
                den,
                d_num,
                d_den,
                poles,
                modal: None,
                unstable,
            });
        }
        let dn = poly::derivative(&num);
        let np = d_num.len();
        let mut residues = Vec::with_capacity(poles.len());
        let mut d_poles = Vec::with_capacity(poles.len());
        let mut d_residues = Vec::with_capacity(poles.len());
        for (i, &p) in poles.iter().enumerate() {
            // `A'(p_i)` and `A''(p_i)` from the poles, `A = Π (s − p_l)`, not from the
            // coefficients: near a repeated pole the coefficients' `A'(p_i)` is not the one that
            // makes the residues sum back to `N/A` (a relative error of `ε/|p_i − p_l|` in each
            // residue, whose terms of size `1/|p_i − p_l|` then cancel to a wrong response).
            let a1 = poly::derivative_at_root(&poles, i);
            let others = || poles.iter().enumerate().filter(move |&(l, _)| l != i);
            // `A''(p_i) = 2 Σ_{l≠i} Π_{m≠i,l} (p_i − p_m)`, as products (exactly 2 for two poles).
            let a2: Complex64 = 2.0
                * others()
                    .map(|(l, _)| {
                        others()
                            .filter(|&(m, _)| m != l)
                            .map(|(_, &q)| p - q)
                            .product::<Complex64>()
                    })
                    .sum::<Complex64>();
            let np_ = poly::eval(&num, p);
            let r = np_ / a1;
            let n1 = poly::eval(&dn, p);
            let mut dp = Vec::with_capacity(np);
            let mut dr = Vec::with_capacity(np);
            for j in 0..np {
                // A(p(θ); θ) = 0  ⇒  ∂p = −(∂A)(p) / A'(p).
                let dpj = -poly::eval(&d_den[j], p) / a1;
                let d_a1 = a2 * dpj + poly::eval(&poly::derivative(&d_den[j]), p);
                let d_np = n1 * dpj + poly::eval(&d_num[j], p);
                dp.push(dpj);
                dr.push((d_np * a1 - np_ * d_a1) / (a1 * a1));
            }
            residues.push(r);
            d_poles.push(dp);
            d_residues.push(dr);
        }
        let a0 = den[n - 1];
        let b0 = num[n - 1];
        let dc_gain = b0 / a0;
        let d_dc_gain = (0..np)
            .map(|j| (d_num[j][n - 1] * a0 - b0 * d_den[j][n - 1]) / (a0 * a0))
            .collect();
        let modal = Modal {
            direct: num[0],
            poles: poles.clone(),
            residues,
            dc_gain,
            d_poles,
            d_residues,
            d_dc_gain,
        };
        let all_finite = modal.residues.iter().all(|r| r.is_finite()) && dc_gain.is_finite();
        if !all_finite {
            return Err(SignalError::Roots { name: "den" });
        }
        Ok(Self {
            num,
            den,
            d_num,
            d_den,
            poles,
            modal: Some(modal),
            unstable,
        })
    }

    /// `G(s)`.
    pub fn response(&self, s: Complex64) -> Complex64 {
        poly::eval(&self.num, s) / poly::eval(&self.den, s)
    }

    /// `∂G(s)/∂θ_j` into `grad`.
    pub fn response_gradient(&self, s: Complex64, grad: &mut [Complex64]) {
        let n = poly::eval(&self.num, s);
        let a = poly::eval(&self.den, s);
        for (g, (dn, da)) in grad.iter_mut().zip(self.d_num.iter().zip(&self.d_den)) {
            *g = (poly::eval(dn, s) * a - n * poly::eval(da, s)) / (a * a);
        }
    }

    /// The modal form, for distinct and strictly stable poles; `None` for a model with a
    /// repeated (or nearly repeated) pole or a pole on the imaginary axis, whose responses go
    /// through a state-space realisation.
    pub fn modal(&self) -> Option<&Modal> {
        self.modal.as_ref()
    }

    /// Whether poles right of the imaginary axis are accepted ([`Rational::new_allowing_unstable`],
    /// [`TransferFunction::new_allowing_unstable`], [`Zpk::new_allowing_unstable`](crate::Zpk::new_allowing_unstable)); kept by
    /// `with_params`.
    pub fn allows_unstable(&self) -> bool {
        self.unstable
    }

    /// The poles, the roots of the denominator (conjugate pairs as two entries).
    pub fn poles(&self) -> &[Complex64] {
        &self.poles
    }

    /// Whether a pole is taken as an integrator: closer to the origin than `1e-6` of the
    /// smaller of 1 rad/s and the largest pole modulus (the rule that keeps such a model off
    /// the modal form).
    pub fn has_pole_at_origin(&self) -> bool {
        let largest = self.poles.iter().map(|p| p.norm()).fold(0.0, f64::max);
        self.poles
            .iter()
            .any(|p| p.norm() <= ORIGIN * largest.min(1.0))
    }

    /// Whether the step response settles to the finite static gain `G(0)`: every pole
    /// strictly left of the imaginary axis and none taken as an integrator.
    pub fn settles(&self) -> bool {
        self.poles.iter().all(|p| p.re < 0.0) && !self.has_pole_at_origin()
    }

    /// The coefficients the confluent realisation reads.
    pub(crate) fn coefficients(&self) -> Coefficients<'_> {
        Coefficients {
            num: self.num(),
            den: self.den(),
            d_num: self.d_num(),
            d_den: self.d_den(),
            poles: self.poles(),
        }
    }

    /// `∂N/∂θ_j`, coefficients padded to the denominator's length.
    pub(crate) fn d_num(&self) -> &[Vec<f64>] {
        &self.d_num
    }

    /// `∂A/∂θ_j`, coefficients (with a leading 0: `A` stays monic).
    pub(crate) fn d_den(&self) -> &[Vec<f64>] {
        &self.d_den
    }

    /// The unit-step response `t ≥ 0` after the step from rest, and its gradient into `grad`
    /// (one entry per parameter).
    pub fn step_response(&self, t: f64, grad: &mut [f64]) -> f64 {
        let Some(m) = &self.modal else {
            return Confluent::new(&self.coefficients()).step_response(t, grad);
        };
        let mut value = Complex64::new(m.dc_gain, 0.0);
        for (j, g) in grad.iter_mut().enumerate() {
            *g = m.d_dc_gain.get(j).copied().unwrap_or(0.0);
        }
        for (i, (&pole, &r)) in m.poles.iter().zip(&m.residues).enumerate() {
            let e = (pole * t).exp();
            value += r / pole * e;
            for (j, g) in grad.iter_mut().enumerate() {
                let (Some(&dp), Some(&dr)) = (m.d_poles[i].get(j), m.d_residues[i].get(j)) else {
                    continue;
                };
                *g += ((dr / pole - r * dp / (pole * pole) + r / pole * t * dp) * e).re;
            }
        }
        value.re
    }

    /// The impulse response `t > 0` after the impulse (without the feed-through's `D δ(t)`).
    pub fn impulse_response(&self, t: f64) -> f64 {
        match &self.modal {
            Some(m) => {
                m.poles
                    .iter()
                    .zip(&m.residues)
                    .map(|(&p, &r)| r * (p * t).exp())
                    .sum::<Complex64>()
                    .re
            }
            None => Confluent::new(&self.coefficients()).impulse_response(t),
        }
    }

    /// Numerator coefficients (padded to the denominator's length).
    pub fn num(&self) -> &[f64] {
        &self.num
    }

    /// Monic denominator coefficients.
    pub fn den(&self) -> &[f64] {
        &self.den
    }

    /// Number of parameters the derivatives are taken for.
    pub fn num_params(&self) -> usize {
        self.d_num.len()
    }
}

/// The serialized form of a [`Rational`]: coefficients and their derivatives.
#[derive(serde::Serialize, serde::Deserialize)]
struct RationalFields {
    num: Vec<f64>,
    den: Vec<f64>,
    d_num: Vec<Vec<f64>>,
    d_den: Vec<Vec<f64>>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    unstable: bool,
}

impl TryFrom<RationalFields> for Rational {
    type Error = SignalError;
    fn try_from(r: RationalFields) -> Result<Self, SignalError> {
        if r.unstable {
            Self::new_allowing_unstable(r.num, r.den, r.d_num, r.d_den)
        } else {
            Self::new(r.num, r.den, r.d_num, r.d_den)
        }
    }
}

impl From<Rational> for RationalFields {
    fn from(r: Rational) -> Self {
        Self {
            num: r.num,
            den: r.den,
            d_num: r.d_num,
            d_den: r.d_den,
            unstable: r.unstable,
        }
    }
}

/// A proper continuous-time rational model with parameters `θ`.
///
/// Implementors build a [`Rational`] at construction ([`Rational::new`] validates properness
/// and stability: poles with real part `≤ 0`, repeated or not); everything else is provided.
pub trait RationalModel: fmt::Debug + Clone + Send + Sync {
    /// Names of the parameters.
    fn param_names(&self) -> Vec<String>;
    /// The parameters.
    fn params(&self) -> Vec<f64>;
    /// The same parameterisation with new parameters, validated.
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError>;
    /// The validated rational function with derivatives.
    fn rational(&self) -> &Rational;

    /// `G(s)` at complex `s` (rad/s).
    fn response(&self, s: Complex64) -> Complex64 {
        self.rational().response(s)
    }

    /// `G(i2πf)`, the frequency response at `f` Hz.
    fn frequency_response(&self, f: f64) -> Complex64 {
        self.response(Complex64::new(0.0, std::f64::consts::TAU * f))
    }

    /// The modal form, where the poles are distinct and strictly stable
    /// ([`Rational::modal`]).
    fn modal(&self) -> Option<&Modal> {
        self.rational().modal()
    }
}

/// `G(s) = (b_m s^m + … + b_0) / (s^n + a_{n-1} s^{n-1} + … + a_0)`, `m ≤ n`.
///
/// Parameters: the numerator coefficients (highest power first), then the denominator's
/// without its leading 1 (a denominator given with another leading coefficient is normalised).
///
/// Serializes as `{num, den}`; deserializes through [`TransferFunction::new`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "TfFields", into = "TfFields")]
pub struct TransferFunction {
    rational: Rational,
    num_len: usize,
    /// Poles held exactly at the origin: the denominator's last coefficients, 0 and not
    /// parameters.
    integrators: usize,
}

impl TransferFunction {
    /// `num` and `den` in decreasing powers. Rejects non-finite coefficients, a zero leading
    /// denominator coefficient, an improper model, unstable poles (repeated poles and poles on
    /// the imaginary axis are accepted).
    pub fn new(num: &[f64], den: &[f64]) -> Result<Self, SignalError> {
        let form = crate::forms::TfForm::new(num, den)?;
        Self::from_monic(form.num().to_vec(), form.den().to_vec(), false, 0)
    }

    /// As [`new`](Self::new), but poles right of the imaginary axis are accepted, here and in
    /// every `with_params` of the model (an estimate may cross the axis).
    pub fn new_allowing_unstable(num: &[f64], den: &[f64]) -> Result<Self, SignalError> {
        let form = crate::forms::TfForm::new(num, den)?;
        Self::from_monic(form.num().to_vec(), form.den().to_vec(), true, 0)
    }

    /// The same model with its last `n` poles at the origin structural: `den`'s last `n`
    /// coefficients are held at exactly 0 (not parameters), so that every `with_params` keeps
    /// `n` exact integrators. Refused ([`SignalError::Integrators`]) unless `den` ends in at
    /// least `n` zeros.
    pub fn with_integrators(&self, n: usize) -> Result<Self, SignalError> {
        let den = self.den();
        let at_origin = den.iter().rev().take_while(|&&c| c == 0.0).count();
        if n > at_origin {
            return Err(SignalError::Integrators {
                integrators: n,
                at_origin,
                poles: den.len() - 1,
            });
        }
        Self::from_monic(self.num().to_vec(), den.to_vec(), self.rational.unstable, n)
    }

    /// The number of poles held at the origin ([`with_integrators`](Self::with_integrators)).
    pub fn integrators(&self) -> usize {
        self.integrators
    }

    /// `den`'s last `integrators` coefficients are 0 (checked by the callers).
    fn from_monic(
        num: Vec<f64>,
        den: Vec<f64>,
        unstable: bool,
        integrators: usize,
    ) -> Result<Self, SignalError> {
        // The held poles exactly at 0, the others the roots of the rest of `den`.
        let poles = if integrators == 0 {
            poly::roots(&den)
        } else {
            crate::integrators::roots_with_origin(&den, integrators)
        }
        .ok_or(SignalError::Roots { name: "den" })?;
        let (nb, na) = (num.len(), den.len() - 1 - integrators);
        let mut d_num = Vec::with_capacity(nb + na);
        let mut d_den = Vec::with_capacity(nb + na);
        for j in 0..nb {
            let mut e = vec![0.0; nb];
            e[j] = 1.0;
            d_num.push(e);
            d_den.push(vec![0.0; den.len()]);
        }
        for j in 0..na {
            // Full length: the held coefficients of the integrators are the last ones.
            let mut e = vec![0.0; den.len()];
            e[j + 1] = 1.0;
            d_num.push(vec![0.0; nb]);
            d_den.push(e);
        }
        let num_len = num.len();
        Ok(Self {
            rational: Rational::with_poles(num, den, poles, d_num, d_den, unstable)?,
            num_len,
            integrators,
        })
    }

    /// Numerator coefficients, highest power first.
    pub fn num(&self) -> &[f64] {
        let n = self.rational.num.len();
        &self.rational.num[n - self.num_len..]
    }

    /// Monic denominator coefficients, highest power first.
    pub fn den(&self) -> &[f64] {
        &self.rational.den
    }
}

impl RationalModel for TransferFunction {
    fn param_names(&self) -> Vec<String> {
        let nb = self.num_len;
        let na = self.rational.den.len() - 1;
        // The held coefficients a_{n-1} … a_0 of the integrators are not parameters.
        (0..nb)
            .map(|i| format!("b{}", nb - 1 - i))
            .chain((0..na - self.integrators).map(|i| format!("a{}", na - 1 - i)))
            .collect()
    }

    fn params(&self) -> Vec<f64> {
        let mut p = self.num().to_vec();
        let den = &self.rational.den;
        p.extend_from_slice(&den[1..den.len() - self.integrators]);
        p
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        let na = self.rational.den.len() - 1 - self.integrators;
        if params.len() != self.num_len + na {
            return Err(SignalError::WrongParamCount {
                expected: self.num_len + na,
                got: params.len(),
            });
        }
        all_finite("tf parameter", params)?;
        let num = params[..self.num_len].to_vec();
        let mut den = vec![1.0];
        den.extend_from_slice(&params[self.num_len..]);
        den.extend(std::iter::repeat_n(0.0, self.integrators));
        Self::from_monic(num, den, self.rational.unstable, self.integrators)
    }

    fn rational(&self) -> &Rational {
        &self.rational
    }
}

/// The serialized form of a [`TransferFunction`].
#[derive(serde::Serialize, serde::Deserialize)]
struct TfFields {
    num: Vec<f64>,
    den: Vec<f64>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    unstable: bool,
    #[serde(default, skip_serializing_if = "crate::integrators::is_zero")]
    integrators: usize,
}

impl TryFrom<TfFields> for TransferFunction {
    type Error = SignalError;
    fn try_from(t: TfFields) -> Result<Self, SignalError> {
        let form = crate::forms::TfForm::new(&t.num, &t.den)?;
        let g = Self::from_monic(form.num().to_vec(), form.den().to_vec(), t.unstable, 0)?;
        if t.integrators == 0 {
            Ok(g)
        } else {
            g.with_integrators(t.integrators)
        }
    }
}

impl From<TransferFunction> for TfFields {
    fn from(t: TransferFunction) -> Self {
        Self {
            num: t.num().to_vec(),
            den: t.den().to_vec(),
            unstable: t.rational.unstable,
            integrators: t.integrators,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Root, Zpk};

    fn paper() -> Zpk {
        Zpk::new(
            0.2,
            vec![Root::Real(-0.5)],
            vec![Root::Pair { re: -0.25, im: 0.3 }],
        )
        .unwrap()
    }

    #[test]
    fn modal_form_reproduces_response() {
        let g = paper();
        let m = g.modal().unwrap();
        for s in [Complex64::new(0.0, 1.3), Complex64::new(-0.1, 0.2)] {
            let modal: Complex64 = m.direct
                + m.poles
                    .iter()
                    .zip(&m.residues)
                    .map(|(p, r)| r / (s - p))
                    .sum::<Complex64>();
            assert!((modal - g.response(s)).norm() < 1e-14);
        }
        assert!((m.dc_gain - 0.2 * 0.5 / (0.0625 + 0.09)).abs() < 1e-14);
    }

    #[test]
    fn modal_derivatives_match_finite_differences() {
        // Zpk and tf, each against central differences of with_params.
        check_fd(&paper());
        check_fd(&TransferFunction::new(&[0.3, 1.0, 0.2], &[1.0, 3.0, 2.5, 0.5]).unwrap());
    }

    fn check_fd<M: RationalModel>(g: &M) {
        let p0 = g.params();
        let m = g.modal().unwrap().clone();
        for j in 0..p0.len() {
            let h = 1e-6 * p0[j].abs().max(1.0);
            let mut pp = p0.clone();
            pp[j] += h;
            let mut pm = p0.clone();
            pm[j] -= h;
            let (mp, mm) = (
                g.with_params(&pp).unwrap().modal().unwrap().clone(),
                g.with_params(&pm).unwrap().modal().unwrap().clone(),
            );
            let fd_gain = (mp.dc_gain - mm.dc_gain) / (2.0 * h);
            assert!(
                (fd_gain - m.d_dc_gain[j]).abs() < 1e-7,
                "dc gain, param {j}"
            );
            for i in 0..m.poles.len() {
                // Match poles by proximity: root order may differ between solves.
                let find = |mm: &Modal| {
                    (0..mm.poles.len())
                        .min_by(|&a, &b| {
                            (mm.poles[a] - m.poles[i])
                                .norm()
                                .total_cmp(&(mm.poles[b] - m.poles[i]).norm())
                        })
                        .unwrap()
                };
                let (ip, im) = (find(&mp), find(&mm));
                let fd_p = (mp.poles[ip] - mm.poles[im]) / (2.0 * h);
                let fd_r = (mp.residues[ip] - mm.residues[im]) / (2.0 * h);
                assert!((fd_p - m.d_poles[i][j]).norm() < 1e-6, "pole {i} param {j}");
                assert!(
                    (fd_r - m.d_residues[i][j]).norm() < 1e-6,
                    "residue {i} param {j}"
                );
            }
        }
    }

    #[test]
    fn validation_names_the_problem() {
        assert!(matches!(
            Zpk::new(1.0, vec![], vec![Root::Real(0.1)]),
            Err(SignalError::Unstable { .. })
        ));
        assert!(matches!(
            Zpk::new(
                1.0,
                vec![Root::Real(1.0), Root::Real(2.0)],
                vec![Root::Real(-1.0)]
            ),
            Err(SignalError::Improper { .. })
        ));
        // A repeated pole and a pole at the origin are valid, without a modal form.
        for poles in [
            vec![Root::Real(-1.0), Root::Real(-1.0)],
            vec![Root::Real(0.0), Root::Real(-1.0)],
        ] {
            assert!(Zpk::new(1.0, vec![], poles).unwrap().modal().is_none());
        }
        assert!(matches!(
            Zpk::new(f64::NAN, vec![], vec![Root::Real(-1.0)]),
            Err(SignalError::NotFinite { name: "gain", .. })
        ));
        assert!(matches!(
            TransferFunction::new(&[1.0], &[0.0, 1.0]),
            Err(SignalError::ZeroLeading { .. })
        ));
        assert!(matches!(
            TransferFunction::new(&[1.0, 0.0, 0.0], &[1.0, 1.0]),
            Err(SignalError::Improper { .. })
        ));
    }

    #[test]
    fn tf_and_zpk_agree() {
        let z = paper();
        let t = TransferFunction::new(&[0.2, 0.1], &[1.0, 0.5, 0.1525]).unwrap();
        for f in [0.0, 0.1, 0.7] {
            assert!((z.frequency_response(f) - t.frequency_response(f)).norm() < 1e-14);
        }
        assert_eq!(t.param_names(), ["b1", "b0", "a1", "a0"]);
        assert_eq!(z.param_names(), ["gain", "zero0", "pole0.re", "pole0.im"]);
    }
}
