//! A single-input single-output state-space realisation `ẋ = Ax + Bu`, `y = Cx + Du`.

use super::TfForm;
use crate::error::{all_finite, finite, SignalError};
use num_complex::Complex64;

/// `ẋ = A x + B u`, `y = C x + D u` with `n ≥ 1` states, one input and one output.
///
/// Serializes as matrices, `{"a": n×n, "b": n×1, "c": 1×n, "d": 1×1}` (rows of arrays), the
/// shapes other tools expect.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    a: Vec<Vec<f64>>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: f64,
}

impl StateSpace {
    /// Validates a square `A` of size `n ≥ 1`, `B` and `C` of length `n`, all finite.
    pub fn new(a: Vec<Vec<f64>>, b: Vec<f64>, c: Vec<f64>, d: f64) -> Result<Self, SignalError> {
        let n = a.len();
        if n == 0 {
            return Err(SignalError::TooFew {
                name: "a",
                min: 1,
                value: 0,
            });
        }
        for row in &a {
            if row.len() != n {
                return Err(SignalError::WrongLength {
                    name: "a",
                    expected: n,
                    got: row.len(),
                });
            }
            all_finite("a", row)?;
        }
        for (name, v) in [("b", &b), ("c", &c)] {
            if v.len() != n {
                return Err(SignalError::WrongLength {
                    name,
                    expected: n,
                    got: v.len(),
                });
            }
            all_finite(name, v)?;
        }
        finite("d", d)?;
        Ok(Self { a, b, c, d })
    }

    /// Built by a conversion that guarantees the shapes.
    pub(crate) fn from_parts(a: Vec<Vec<f64>>, b: Vec<f64>, c: Vec<f64>, d: f64) -> Self {
        Self { a, b, c, d }
    }

    /// `A`, by rows.
    pub fn a(&self) -> &[Vec<f64>] {
        &self.a
    }

    /// `B`.
    pub fn b(&self) -> &[f64] {
        &self.b
    }

    /// `C`.
    pub fn c(&self) -> &[f64] {
        &self.c
    }

    /// `D`.
    pub fn d(&self) -> f64 {
        self.d
    }

    /// The number of states.
    pub fn order(&self) -> usize {
        self.a.len()
    }

    /// `G(s) = C (sI − A)⁻¹ B + D` at complex `s` (rad/s), by Gaussian elimination with
    /// partial pivoting (infinite where `sI − A` is singular).
    pub fn response(&self, s: Complex64) -> Complex64 {
        let n = self.order();
        let mut m: Vec<Vec<Complex64>> = (0..n)
            .map(|i| {
                let mut row: Vec<Complex64> = (0..n)
                    .map(|j| {
                        Complex64::new(-self.a[i][j], 0.0) + if i == j { s } else { 0.0.into() }
                    })
                    .collect();
                row.push(self.b[i].into());
                row
            })
            .collect();
        for k in 0..n {
            let Some(p) = (k..n).max_by(|&i, &j| m[i][k].norm().total_cmp(&m[j][k].norm())) else {
                break;
            };
            m.swap(k, p);
            let pivot = m[k][k];
            if pivot.norm() == 0.0 {
                return Complex64::new(f64::INFINITY, 0.0);
            }
            let (upper, lower) = m.split_at_mut(k + 1);
            let pivot_row = &upper[k];
            for row in lower {
                let f = row[k] / pivot;
                for (x, v) in row[k..].iter_mut().zip(&pivot_row[k..]) {
                    *x -= f * v;
                }
            }
        }
        let mut x = vec![Complex64::new(0.0, 0.0); n];
        for i in (0..n).rev() {
            let tail: Complex64 = (i + 1..n).map(|j| m[i][j] * x[j]).sum();
            x[i] = (m[i][n] - tail) / m[i][i];
        }
        x.iter()
            .zip(&self.c)
            .map(|(xi, ci)| xi * ci)
            .sum::<Complex64>()
            + self.d
    }

    /// The transfer function `C adj(sI − A) B / det(sI − A) + D` by the Faddeev–LeVerrier
    /// recursion: `M_1 = I`, `M_k = A M_{k−1} + c_{n−k+1} I`, `c_{n−k} = −tr(A M_k)/k`, so
    /// that `det(sI − A) = Σ c_k s^k` and `adj(sI − A) = Σ_k M_k s^{n−k}`. An exact,
    /// division-free route (but for `1/k`) that needs no eigenvalues; the result is not
    /// reduced (pole–zero cancellations stay, as for any non-minimal realisation). Fails only
    /// when a coefficient overflows.
    pub fn to_tf(&self) -> Result<TfForm, SignalError> {
        let n = self.order();
        let identity = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
        let mut den = vec![1.0];
        let mut strictly_proper = vec![0.0];
        let mut m: Vec<Vec<f64>> = vec![vec![0.0; n]; n];
        for k in 1..=n {
            let lead = den[k - 1];
            let am = mat_mul(&self.a, &m);
            m = (0..n)
                .map(|i| (0..n).map(|j| am[i][j] + lead * identity(i, j)).collect())
                .collect();
            let a_m = mat_mul(&self.a, &m);
            let trace: f64 = (0..n).map(|i| a_m[i][i]).sum();
            den.push(-trace / k as f64);
            let mb: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| m[i][j] * self.b[j]).sum())
                .collect();
            strictly_proper.push(self.c.iter().zip(&mb).map(|(c, x)| c * x).sum());
        }
        let num: Vec<f64> = den
            .iter()
            .zip(&strictly_proper)
            .map(|(a, b)| self.d * a + b)
            .collect();
        TfForm::new(&num, &den)
    }
}

fn mat_mul(x: &[Vec<f64>], y: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = x.len();
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| (0..n).map(|l| x[i][l] * y[l][j]).sum())
                .collect()
        })
        .collect()
}

/// The serialized matrices.
#[derive(serde::Serialize)]
struct Matrices<'a> {
    a: &'a [Vec<f64>],
    b: Vec<[f64; 1]>,
    c: [&'a [f64]; 1],
    d: [[f64; 1]; 1],
}

impl serde::Serialize for StateSpace {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Matrices {
            a: &self.a,
            b: self.b.iter().map(|&x| [x]).collect(),
            c: [&self.c],
            d: [[self.d]],
        }
        .serialize(s)
    }
}
