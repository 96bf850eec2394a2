//! The exact response of a rational model by the matrix exponential, for the models whose
//! partial-fraction form is not accurate: repeated or nearly coincident poles (a critically
//! damped loop, poles passing through coincidence during a search) and poles on the imaginary
//! axis (integrators `1/s`, `1/(s(s+1))`, undamped oscillators).
//!
//! `G = N/A` (monic `A` of degree `n`, `N = D·A + N'`) in controllable canonical form, with the
//! input level appended to the state: `z = (x, u)`, `ż = Ā z` between input steps,
//! `s = c̄ · z`, and each step adds `Δu` to the last component. Between steps
//! `z(t) = e^{Ā(t − t_j)} z(t_j)`, exactly, whatever the poles' multiplicities: the confluent
//! terms `t^l e^{pt}` are inside the exponential of the Jordan structure.
//!
//! The gradient follows from the sensitivity system `d(∂_i z)/dt = Ā ∂_i z + (∂_i Ā) z`, the
//! block lower-triangular matrix `S` acting on `(z, ∂_1 z, …, ∂_P z)`; the input steps do not
//! depend on `θ`, so they only enter `z`.

use crate::expm::expm;
use crate::rational::Rational;
use faer::Mat;
use std::sync::OnceLock;

/// The augmented state-space form of one rational model, with its states after each input
/// step tabulated on first use.
#[derive(Debug, Clone)]
pub(crate) struct Augmented {
    /// State dimension `n + 1`.
    dim: usize,
    /// `Ā`.
    a: Mat<f64>,
    /// `c̄ = (N'_{n−1} … N'_0, D)`.
    c: Vec<f64>,
    /// The sensitivity matrix `S`, `(P + 1)(n + 1)` square.
    sens: Mat<f64>,
    /// `∂c̄/∂θ_i`.
    dc: Vec<Vec<f64>>,
    /// `z` right after each step, row-major.
    states: OnceLock<Vec<f64>>,
    /// `(z, ∂z)` right after each step, row-major.
    sensitivities: OnceLock<Vec<f64>>,
}

/// A cache derived from the model: equal models give equal caches.
impl PartialEq for Augmented {
    fn eq(&self, other: &Self) -> bool {
        self.a == other.a && self.c == other.c && self.sens == other.sens && self.dc == other.dc
    }
}

/// `Ā` (or `∂Ā`) for a monic denominator `den` (or its derivative) of degree `n`: the first row
/// holds `−den[1..]`, ones below the diagonal, and the input enters `x_1` (a 1 in the last
/// column when `input`).
fn companion(den: &[f64], input: bool) -> Mat<f64> {
    let n = den.len() - 1;
    Mat::from_fn(n + 1, n + 1, |i, j| match (i, j) {
        (0, j) if j < n => -den[j + 1],
        (0, j) if j == n => f64::from(u8::from(input)),
        (i, j) if i < n && i == j + 1 && input => 1.0,
        _ => 0.0,
    })
}

/// `c̄` for numerator `num` (padded to `den`'s length) over `den`: the strictly proper part's
/// coefficients and the feed-through `D = num[0]` (`den` monic).
fn output_row(num: &[f64], den: &[f64], d_lead: f64) -> Vec<f64> {
    let mut c: Vec<f64> = num[1..]
        .iter()
        .zip(&den[1..])
        .map(|(b, a)| b - d_lead * a)
        .collect();
    c.push(d_lead);
    c
}

impl Augmented {
    /// The augmented form of `r`.
    pub(crate) fn new(r: &Rational) -> Self {
        let (num, den) = (r.num(), r.den());
        let n = den.len() - 1;
        let dim = n + 1;
        let a = companion(den, true);
        let c = output_row(num, den, num[0]);
        let np = r.num_params();
        let mut dc = Vec::with_capacity(np);
        let big = (np + 1) * dim;
        let mut sens = Mat::zeros(big, big);
        for blk in 0..=np {
            for i in 0..dim {
                for j in 0..dim {
                    sens[(blk * dim + i, blk * dim + j)] = a[(i, j)];
                }
            }
        }
        for (p, (dn, dd)) in r.num_gradient().iter().zip(r.den_gradient()).enumerate() {
            // ∂c̄ = (∂N' , ∂D) with N' = N − D·A: ∂N' = ∂N − ∂D·A − D·∂A.
            let d_lead = dn[0];
            let mut row: Vec<f64> = (1..=n)
                .map(|k| dn[k] - d_lead * den[k] - num[0] * dd[k])
                .collect();
            row.push(d_lead);
            dc.push(row);
            let da = companion(dd, false);
            for i in 0..dim {
                for j in 0..dim {
                    sens[((p + 1) * dim + i, j)] = da[(i, j)];
                }
            }
        }
        Self {
            dim,
            a,
            c,
            sens,
            dc,
            states: OnceLock::new(),
            sensitivities: OnceLock::new(),
        }
    }

    /// The states right after each step of `steps`, propagated by `e^{M δ}` (`M` of width
    /// `width`, input level in component `dim − 1`).
    fn after_steps(m: &Mat<f64>, dim: usize, steps: &[(f64, f64)]) -> Vec<f64> {
        let width = m.nrows();
        let mut z = vec![0.0; width];
        let mut out = Vec::with_capacity(steps.len() * width);
        let mut prev = f64::NAN;
        for &(tj, du) in steps {
            if prev.is_finite() {
                z = propagate(m, tj - prev, &z);
            }
            z[dim - 1] += du;
            prev = tj;
            out.extend_from_slice(&z);
        }
        out
    }

    /// `s(t)` for the input with `steps` (the system at rest before the first).
    pub(crate) fn value(&self, steps: &[(f64, f64)], t: f64) -> f64 {
        let j = steps.partition_point(|s| s.0 <= t);
        if j == 0 {
            return 0.0;
        }
        let states = self
            .states
            .get_or_init(|| Self::after_steps(&self.a, self.dim, steps));
        let z0 = &states[(j - 1) * self.dim..j * self.dim];
        let z = propagate(&self.a, t - steps[j - 1].0, z0);
        dot(&self.c, &z)
    }

    /// `s(t)` and `∂s(t)/∂θ_i` into `grad`.
    pub(crate) fn value_and_gradient(&self, steps: &[(f64, f64)], t: f64, grad: &mut [f64]) -> f64 {
        grad.iter_mut().for_each(|g| *g = 0.0);
        let j = steps.partition_point(|s| s.0 <= t);
        if j == 0 {
            return 0.0;
        }
        let width = self.sens.nrows();
        let states = self
            .sensitivities
            .get_or_init(|| Self::after_steps(&self.sens, self.dim, steps));
        let w0 = &states[(j - 1) * width..j * width];
        let w = propagate(&self.sens, t - steps[j - 1].0, w0);
        let z = &w[..self.dim];
        for (i, (g, dc)) in grad.iter_mut().zip(&self.dc).enumerate() {
            let dz = &w[(i + 1) * self.dim..(i + 2) * self.dim];
            *g = dot(dc, z) + dot(&self.c, dz);
        }
        dot(&self.c, z)
    }
}

/// `e^{M δ} z`; not-a-number when the exponential overflows (a marginally stable mode over an
/// astronomically long time), which the estimators reject as a non-finite model.
fn propagate(m: &Mat<f64>, delta: f64, z: &[f64]) -> Vec<f64> {
    let n = m.nrows();
    match expm(m, delta) {
        Some(e) => (0..n)
            .map(|i| (0..n).map(|j| e[(i, j)] * z[j]).sum())
            .collect(),
        None => vec![f64::NAN; n],
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
