//! Transfer-function coefficients `N(s)/A(s)`.

use super::{StateSpace, ZpkForm};
use crate::error::{tf_coefficients, SignalError};
use crate::poly;
use crate::RationalModel;
use num_complex::Complex64;

/// `G(s) = (b_m s^m + … + b_0) / (s^n + a_{n−1} s^{n−1} + … + a_0)`, `m ≤ n`, `n ≥ 1`:
/// coefficients in decreasing powers, the denominator monic, the numerator without leading
/// zeros (the zero function is `num = [0]`).
///
/// Serializes as `{"num": [...], "den": [...]}`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TfForm {
    num: Vec<f64>,
    den: Vec<f64>,
}

impl TfForm {
    /// From coefficients in decreasing powers; both are divided by `den`'s leading coefficient
    /// and the numerator's leading zeros are dropped. Rejects non-finite coefficients, a zero
    /// leading denominator coefficient, a denominator of degree 0 and an improper model.
    pub fn new(num: &[f64], den: &[f64]) -> Result<Self, SignalError> {
        tf_coefficients(num, den)?;
        let lead = den[0];
        if lead == 0.0 {
            return Err(SignalError::ZeroLeading { name: "den" });
        }
        let first = num.iter().position(|&c| c != 0.0).unwrap_or(num.len() - 1);
        let num: Vec<f64> = num[first..].iter().map(|c| c / lead).collect();
        if num.len() > den.len() {
            return Err(SignalError::Improper {
                zeros: num.len() - 1,
                poles: den.len() - 1,
            });
        }
        let den = den.iter().map(|c| c / lead).collect();
        Ok(Self { num, den })
    }

    /// The coefficients of a fitted rational model.
    pub fn of<M: RationalModel>(model: &M) -> Self {
        let r = model.rational();
        let first = r
            .num()
            .iter()
            .position(|&c| c != 0.0)
            .unwrap_or(r.num().len() - 1);
        Self {
            num: r.num()[first..].to_vec(),
            den: r.den().to_vec(),
        }
    }

    /// Numerator coefficients, highest power first.
    pub fn num(&self) -> &[f64] {
        &self.num
    }

    /// Monic denominator coefficients, highest power first.
    pub fn den(&self) -> &[f64] {
        &self.den
    }

    /// The number of poles `n`.
    pub fn order(&self) -> usize {
        self.den.len() - 1
    }

    /// `G(s)` at complex `s` (rad/s).
    pub fn response(&self, s: Complex64) -> Complex64 {
        poly::eval(&self.num, s) / poly::eval(&self.den, s)
    }

    /// Zeros, poles and gain: the roots of the numerator and the denominator (eigenvalues of
    /// their companion matrices, polished), the gain the numerator's leading coefficient.
    pub fn to_zpk(&self) -> Result<ZpkForm, SignalError> {
        let gain = self.num[0];
        let zeros = if gain == 0.0 {
            Vec::new()
        } else {
            poly::roots(&self.num).ok_or(SignalError::Roots { name: "num" })?
        };
        let poles = poly::roots(&self.den).ok_or(SignalError::Roots { name: "den" })?;
        ZpkForm::new(gain, zeros, poles)
    }

    /// The controllable canonical realisation: `A` the companion matrix with first row
    /// `[−a_{n−1}, …, −a_0]` and ones below the diagonal, `B = e_1`, `D = b_n` (the
    /// feed-through) and `C` the coefficients of the strictly proper remainder
    /// `N(s) − D·A(s)`. Repeated poles and poles at the origin need no special case.
    pub fn to_state_space(&self) -> StateSpace {
        let n = self.order();
        let num = poly::pad(&self.num, n + 1);
        let d = num[0];
        let c: Vec<f64> = (1..=n).map(|i| num[i] - d * self.den[i]).collect();
        let a: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| match i {
                        0 => -self.den[j + 1],
                        _ if i == j + 1 => 1.0,
                        _ => 0.0,
                    })
                    .collect()
            })
            .collect();
        let mut b = vec![0.0; n];
        b[0] = 1.0;
        StateSpace::from_parts(a, b, c, d)
    }
}
