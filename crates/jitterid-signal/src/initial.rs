//! The free response from an unknown state at the record's start, added to an LTI response.

use crate::confluent::{dot, Confluent, FreeRows};
use crate::delay::Delayed;
use crate::expm::mat_vec;
use crate::lti::LtiResponse;
use crate::rational::{Modal, Rational, RationalModel};
use crate::signal::{local_breaks, Jacobian, Signal};
use crate::{SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;

/// A signal whose output is a rational model's response: its denominator gives the modes a
/// free response is made of.
pub trait ModalSignal: Signal {
    /// The model (its derivatives are with respect to this signal's leading parameters).
    fn rational(&self) -> &Rational;

    /// The model's modal form, where it has one ([`Rational::modal`]).
    fn modal(&self) -> Option<&Modal> {
        self.rational().modal()
    }
}

impl<M: RationalModel> ModalSignal for LtiResponse<M> {
    fn rational(&self) -> &Rational {
        self.model().rational()
    }
}

impl<M: RationalModel> ModalSignal for Delayed<M> {
    fn rational(&self) -> &Rational {
        self.response().model().rational()
    }
}

/// `s(t) + f(t)`: a response `s` plus the free response `f` of its system from an unknown
/// state at the origin `t0` (the record's first requested instant).
///
/// For a model with denominator `A(s)` of degree `n`, every free response from a state at
/// `t0` has the Laplace transform `q(s)/A(s)` (time origin `t0`) with `q` a real polynomial of
/// degree `< n`; its coefficients `q_0 … q_{n−1}` are the parameters `initial.0 …
/// initial.{n−1}`, after the response's own. In modal form
/// `f(t) = Σ_i c_i e^{p_i (t − t0)}` with `c_i = q(p_i)/A'(p_i)`, which stays continuous
/// when a complex pair of a search becomes two real poles (the number of parameters does not
/// change). An input that ran before `t0` leaves exactly such a free response after `t0`.
///
/// The free response is taken as the analytic `Σ c_i e^{p_i(t − t0)}` at every `t`, also a
/// little before `t0`, where jitter may move the first samples. Its jittered mean is then
/// exact: `E[e^{p(t_k + τ − t0)}] = e^{p(t_k − t0)} M_τ(p)` with the jitter's moment-generating
/// function `M_τ` (the jitter's quadrature rule where `M_τ(p)` diverges), and its gradient
/// uses `E[τ e^{pτ}]`. The second moment adds `E[2 s f + f²]` by the jitter's rule cut at the
/// response's breakpoints, for the samples where `f` is not negligible against `E[s²]`.
#[derive(Debug, Clone, PartialEq)]
pub struct WithInitialState<S> {
    inner: S,
    origin: f64,
    initial: Vec<f64>,
}

/// Prefix of the names of the free response's coefficients: `initial.0 … initial.{n−1}`.
pub const INITIAL_PREFIX: &str = "initial.";

/// One representative mode (a real pole or the upper member of a pair) and what its
/// coefficient `c = q(p)/A'(p)` depends on.
struct Mode {
    p: Complex64,
    /// 2 for a pair (the conjugate adds the conjugate term), 1 for a real pole.
    w: f64,
    c: Complex64,
    /// `∂p/∂θ_j` for the response's parameters.
    dp: Vec<Complex64>,
    /// `∂c/∂θ_j` for the response's parameters.
    dc: Vec<Complex64>,
    /// `∂c/∂q_j = p^j / A'(p)`.
    basis: Vec<Complex64>,
}

impl<S: ModalSignal> WithInitialState<S> {
    /// `response` plus the free response with coefficients `initial` (`q_0 … q_{n−1}`, `n`
    /// the number of poles) from the origin `origin`.
    ///
    /// # Errors
    ///
    /// [`SignalError::NotFinite`] for a NaN or infinite origin or coefficient,
    /// [`SignalError::WrongLength`] when `initial` does not have one value per pole.
    pub fn new(response: S, origin: f64, initial: Vec<f64>) -> Result<Self, SignalError> {
        crate::error::finite("origin", origin)?;
        crate::error::all_finite("initial", &initial)?;
        let n = response.rational().poles().len();
        if initial.len() != n {
            return Err(SignalError::WrongLength {
                name: "initial",
                expected: n,
                got: initial.len(),
            });
        }
        Ok(Self {
            inner: response,
            origin,
            initial,
        })
    }

    /// `response` from rest at `origin` (every `q_j = 0`), as a start for estimation.
    pub fn at_rest(response: S, origin: f64) -> Result<Self, SignalError> {
        let n = response.rational().poles().len();
        Self::new(response, origin, vec![0.0; n])
    }

    /// The response without the free part.
    pub fn response(&self) -> &S {
        &self.inner
    }

    /// The origin `t0` of the free response (s).
    pub fn origin(&self) -> f64 {
        self.origin
    }

    /// The coefficients `q_0 … q_{n−1}`.
    pub fn initial(&self) -> &[f64] {
        &self.initial
    }

    /// The free response alone, `f(t)`.
    pub fn free_value(&self, t: f64) -> f64 {
        self.free().value(t - self.origin)
    }

    /// The free response's form: modes, or readouts of the model's realisation where it has
    /// no modal form.
    fn free(&self) -> Free {
        match self.inner.modal() {
            Some(_) => Free::Modes(self.modes()),
            None => {
                let cf = Confluent::new(&self.inner.rational().coefficients());
                let rows = cf.free_rows(&self.inner.rational().coefficients(), &self.initial);
                Free::Confluent(Box::new((cf, rows)))
            }
        }
    }

    /// The modes (empty for a model without a modal form).
    fn modes(&self) -> Vec<Mode> {
        let Some(m) = self.inner.modal() else {
            return Vec::new();
        };
        let ni = self.inner.num_params();
        let poles = &m.poles;
        let mut out = Vec::new();
        for (i, &p) in poles.iter().enumerate() {
            let w = match p.im.partial_cmp(&0.0) {
                Some(std::cmp::Ordering::Greater) => 2.0,
                Some(std::cmp::Ordering::Equal) => 1.0,
                _ => continue,
            };
            let r = crate::poly::derivative_at_root(poles, i).inv();
            // q(p) and q'(p) by Horner, highest power first.
            let (mut q, mut dq) = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
            for &qj in self.initial.iter().rev() {
                dq = dq * p + q;
                q = q * p + qj;
            }
            let c = q * r;
            let d_pole = |l: usize, j: usize| m.d_poles[l].get(j).copied().unwrap_or_default();
            let dp: Vec<Complex64> = (0..ni).map(|j| d_pole(i, j)).collect();
            let dc = (0..ni)
                .map(|j| {
                    // ∂(1/A'(p_i)) = −(1/A'(p_i)) Σ_{l≠i} (∂p_i − ∂p_l)/(p_i − p_l).
                    let spread: Complex64 = (0..poles.len())
                        .filter(|&l| l != i)
                        .map(|l| (dp[j] - d_pole(l, j)) / (p - poles[l]))
                        .sum();
                    dq * dp[j] * r - c * spread
                })
                .collect();
            let mut basis = Vec::with_capacity(self.initial.len());
            let mut pj = r;
            for _ in 0..self.initial.len() {
                basis.push(pj);
                pj *= p;
            }
            out.push(Mode {
                p,
                w,
                c,
                dp,
                dc,
                basis,
            });
        }
        out
    }

    /// Adds the free response's jittered mean to `values` and its gradient to `cols`.
    ///
    /// Per mode, every entry is `Re(α e^{pΔ_k} + β Δ_k e^{pΔ_k})` with coefficients `α`, `β`
    /// that do not depend on the sample: the modes `e^{pΔ_k}` are computed once per mode (by
    /// [`modes_on_grid`]) and each column is then one pass of real multiply-adds.
    fn add_free(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
        values: Option<&mut [f64]>,
        cols: Option<&mut Jacobian>,
    ) {
        let modes = match self.free() {
            Free::Modes(modes) => modes,
            Free::Confluent(c) => {
                return self.add_free_confluent(&c.0, &c.1, grid, jitter, values, cols)
            }
        };
        let ni = self.inner.num_params();
        let deltas: Vec<f64> = grid.times().map(|t| t - self.origin).collect();
        let mut e = vec![Complex64::new(0.0, 0.0); deltas.len()];
        let mut values = values;
        let mut cols = cols;
        for m in &modes {
            let (m0, m1) = jitter_factors(jitter, m.p);
            modes_on_grid(m.p, grid.interval(), &deltas, &mut e);
            let zero = Complex64::new(0.0, 0.0);
            if let Some(v) = values.as_deref_mut() {
                add_re(v, m.w * m.c * m0, zero, &e, &deltas);
            }
            if let Some(cols) = cols.as_deref_mut() {
                let (inner, free) = cols.split_at_mut(ni);
                for ((col, dc), dp) in inner.iter_mut().zip(&m.dc).zip(&m.dp) {
                    // ∂/∂θ of c e^{pΔ} M(p) = (∂c M + c M' ∂p) e^{pΔ} + c M ∂p Δ e^{pΔ}.
                    let alpha = m.w * (dc * m0 + m.c * m1 * dp);
                    let beta = m.w * m.c * m0 * dp;
                    add_re(col, alpha, beta, &e, &deltas);
                }
                for (col, b) in free.iter_mut().zip(&m.basis) {
                    add_re(col, m.w * b * m0, zero, &e, &deltas);
                }
            }
        }
    }
}

impl<S: ModalSignal> WithInitialState<S> {
    /// [`add_free`](Self::add_free) for a model without a modal form: every entry is a
    /// readout of `w_k = E[e^{M(t_k + τ − t0)}] e_1 = e^{M(t_k − t0)} E[e^{Mτ}] e_1`, carried
    /// along the grid by `e^{MT}`.
    fn add_free_confluent(
        &self,
        cf: &Confluent,
        rows: &FreeRows,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
        mut values: Option<&mut [f64]>,
        mut cols: Option<&mut Jacobian>,
    ) {
        let ni = self.inner.num_params();
        let mean = cf.expected_from(jitter, &cf.impulse_state(0.0));
        let carry = cf.carry(grid.interval());
        let mut w = vec![0.0; mean.len()];
        let mut next = w.clone();
        for (k, t) in grid.times().enumerate() {
            if k % RESTART == 0 {
                // Restarted from a direct exponential, as the modes are.
                mat_vec(&cf.carry(t - self.origin), &mean, &mut w);
            } else {
                mat_vec(&carry, &w, &mut next);
                std::mem::swap(&mut w, &mut next);
            }
            if let Some(v) = values.as_deref_mut() {
                v[k] += dot(&rows.value, &w);
            }
            if let Some(cols) = cols.as_deref_mut() {
                let (inner, free) = cols.split_at_mut(ni);
                for (col, row) in inner.iter_mut().zip(&rows.grads) {
                    col[k] += dot(row, &w);
                }
                for (col, row) in free.iter_mut().zip(&rows.basis) {
                    col[k] += dot(row, &w);
                }
            }
        }
    }
}

/// The free response: its modes, or the readouts of the model's realisation.
enum Free {
    Modes(Vec<Mode>),
    Confluent(Box<(Confluent, FreeRows)>),
}

impl Free {
    /// `f` at `delta = t − t0`.
    fn value(&self, delta: f64) -> f64 {
        match self {
            Free::Modes(modes) => free_of(modes, delta),
            Free::Confluent(c) => dot(&c.1.value, &c.0.impulse_state(delta)),
        }
    }
}

/// Samples between direct evaluations of `e^{pΔ_k}` in [`modes_on_grid`]: the recursion's
/// relative rounding error grows by a few units per step, so the restarts keep it within
/// about `RESTART` units of the direct evaluation (itself accurate only to `ε|pΔ_k|`).
const RESTART: usize = 16;

/// `e[k] = e^{p Δ_k}` for the equally spaced `Δ_k` (spacing `interval`), by the recursion
/// `e^{p(Δ + T)} = e^{pΔ} e^{pT}`, restarted from a direct evaluation every [`RESTART`]
/// samples: one complex exponential per `RESTART` samples instead of one per sample.
fn modes_on_grid(p: Complex64, interval: f64, deltas: &[f64], e: &mut [Complex64]) {
    let step = (p * interval).exp();
    let mut prev = Complex64::new(0.0, 0.0);
    for (k, (e, &delta)) in e.iter_mut().zip(deltas).enumerate() {
        *e = if k % RESTART == 0 {
            (p * delta).exp()
        } else {
            prev * step
        };
        prev = *e;
    }
}

/// `out[k] += Re(α e_k + β Δ_k e_k)`.
fn add_re(out: &mut [f64], alpha: Complex64, beta: Complex64, e: &[Complex64], deltas: &[f64]) {
    for ((o, e), &d) in out.iter_mut().zip(e).zip(deltas) {
        *o += (alpha.re + d * beta.re) * e.re - (alpha.im + d * beta.im) * e.im;
    }
}

/// `Σ_i c_i e^{p_i Δ}` over all modes.
fn free_of(modes: &[Mode], delta: f64) -> f64 {
    modes
        .iter()
        .map(|m| m.w * (m.c * (m.p * delta).exp()).re)
        .sum()
}

/// `M_τ(p) = E[e^{pτ}]` (the moment-generating function, or the jitter's rule where it
/// diverges) and `E[τ e^{pτ}]` (the rule), from one complex exponential per node.
fn jitter_factors(jitter: &dyn JitterModel, p: Complex64) -> (Complex64, Complex64) {
    let rule = jitter.rule(&[], p.norm());
    // Σ w_i h(τ_i) in the rule's order, as `QuadratureRule::expect` sums it.
    let (mut m0, mut m1) = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
    for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
        let e = (p * tau).exp();
        m0 += w * e;
        m1 += w * (tau * e);
    }
    (jitter.mgf(p).unwrap_or(m0), m1)
}

impl<S: ModalSignal + Clone> Signal for WithInitialState<S> {
    fn param_names(&self) -> Vec<String> {
        let mut names = self.inner.param_names();
        names.extend((0..self.initial.len()).map(|j| format!("{INITIAL_PREFIX}{j}")));
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p = self.inner.params();
        p.extend_from_slice(&self.initial);
        p
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        let ni = self.inner.num_params();
        let n = ni + self.initial.len();
        if params.len() != n {
            return Err(SignalError::WrongParamCount {
                expected: n,
                got: params.len(),
            });
        }
        Self::new(
            self.inner.with_params(&params[..ni])?,
            self.origin,
            params[ni..].to_vec(),
        )
    }

    fn value(&self, t: f64) -> f64 {
        self.inner.value(t) + self.free_value(t)
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        let ni = self.inner.num_params();
        self.inner.value_gradient(t, &mut grad[..ni]);
        grad[ni..].iter_mut().for_each(|g| *g = 0.0);
        let delta = t - self.origin;
        if let Free::Confluent(c) = self.free() {
            let (cf, rows) = &*c;
            let z = cf.impulse_state(delta);
            let (inner, free) = grad.split_at_mut(ni);
            for (g, row) in inner.iter_mut().zip(&rows.grads) {
                *g += dot(row, &z);
            }
            for (g, row) in free.iter_mut().zip(&rows.basis) {
                *g += dot(row, &z);
            }
            return;
        }
        for m in self.modes() {
            let e = (m.p * delta).exp();
            let (inner, free) = grad.split_at_mut(ni);
            for ((g, dc), dp) in inner.iter_mut().zip(&m.dc).zip(&m.dp) {
                *g += m.w * ((dc + m.c * delta * dp) * e).re;
            }
            for (g, b) in free.iter_mut().zip(&m.basis) {
                *g += m.w * (b * e).re;
            }
        }
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.inner.breakpoints()
    }

    fn rate(&self) -> f64 {
        self.inner.rate()
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let mut v = self.inner.expected_values(grid, jitter);
        self.add_free(grid, jitter, Some(&mut v), None);
        v
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let mut cols = self.inner.expected_values_gradient(grid, jitter);
        cols.extend((0..self.initial.len()).map(|_| vec![0.0; grid.len()]));
        self.add_free(grid, jitter, None, Some(&mut cols));
        cols
    }

    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        let (mut v, mut cols) = self.inner.expected_values_and_gradient(grid, jitter);
        cols.extend((0..self.initial.len()).map(|_| vec![0.0; grid.len()]));
        self.add_free(grid, jitter, Some(&mut v), Some(&mut cols));
        (v, cols)
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let mut sq = self.inner.expected_squares(grid, jitter);
        let free = self.free();
        let modes = match &free {
            Free::Modes(modes) => modes.as_slice(),
            Free::Confluent(_) => &[],
        };
        let breaks = self.inner.breakpoints();
        let (lo, hi) = jitter.reach();
        let mut smooth = None;
        let mut cut;
        for (k, t) in grid.times().enumerate() {
            // |f| ≤ bound on the sample's reach (every mode decays), so by Cauchy–Schwarz
            // |E[2sf + f²]| ≤ 2·bound·√E[s²] + bound²: below rounding of E[s²], skip it.
            let bound: f64 = modes
                .iter()
                .map(|m| m.w * m.c.norm() * (m.p.re * (t + lo - self.origin)).exp())
                .sum();
            let extra_bound = 2.0 * bound * sq[k].max(0.0).sqrt() + bound * bound;
            let modal = matches!(free, Free::Modes(_));
            if modal && (extra_bound <= 1e-17 * sq[k] || bound == 0.0) {
                continue;
            }
            let local = local_breaks(&breaks, t, lo, hi);
            // Most samples have no breakpoint in reach: their rule is the same one, built once.
            let rule = if local.is_empty() {
                &*smooth.get_or_insert_with(|| jitter.rule(&[], 2.0 * self.rate()))
            } else {
                cut = jitter.rule(&local, 2.0 * self.rate());
                &cut
            };
            sq[k] += rule.expect(|tau| {
                let f = free.value(t + tau - self.origin);
                f * (2.0 * self.inner.value(t + tau) + f)
            });
        }
        sq
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::binary;
    use crate::{Root, Zpk};
    use jitterid_jitter::{Gaussian, Laplace, UniformSum};

    /// The free part's mean and gradient sample by sample, one complex exponential each,
    /// straight from `c e^{pΔ} M(p)` and its derivative.
    fn per_sample(
        s: &WithInitialState<LtiResponse<Zpk>>,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        let modes = s.modes();
        let ni = s.inner.num_params();
        let mut v = vec![0.0; grid.len()];
        let mut cols = vec![vec![0.0; grid.len()]; ni + s.initial.len()];
        for m in &modes {
            let (m0, m1) = jitter_factors(jitter, m.p);
            for (k, t) in grid.times().enumerate() {
                let delta = t - s.origin;
                let e = (m.p * delta).exp();
                v[k] += m.w * (m.c * e * m0).re;
                let slope = m.c * e * (delta * m0 + m1);
                for ((col, dc), dp) in cols.iter_mut().zip(&m.dc).zip(&m.dp) {
                    col[k] += m.w * (dc * e * m0 + slope * dp).re;
                }
                for (j, b) in m.basis.iter().enumerate() {
                    cols[ni + j][k] += m.w * (b * e * m0).re;
                }
            }
        }
        (v, cols)
    }

    /// `e^{pΔ_k}` by the restarted recursion agrees with one exponential per sample entry by
    /// entry (not only against the largest): to the recursion's rounding (a few units per
    /// step since the last restart) plus that of the argument `pΔ_k` itself, which costs the
    /// direct route `ε|pΔ_k|` relative.
    #[test]
    fn modes_on_grid_equal_exponentials_entry_by_entry() {
        let deltas: Vec<f64> = (0..5000).map(|k| 0.5 * k as f64).collect();
        for p in [
            Complex64::new(-0.001, 2.0),
            Complex64::new(-0.002, 0.0),
            Complex64::new(-0.3, 0.7),
        ] {
            let mut e = vec![Complex64::new(0.0, 0.0); deltas.len()];
            modes_on_grid(p, 0.5, &deltas, &mut e);
            for (k, (got, &d)) in e.iter().zip(&deltas).enumerate() {
                let want = (p * d).exp();
                if want.norm() < 1e-280 {
                    // Near the subnormals relative accuracy is lost by any route.
                    break;
                }
                // Up to RESTART − 1 steps, each a rounding of the product and of e^{pT}.
                let tol = (4.0 * RESTART as f64 + 2.0 * (p * d).norm()) * f64::EPSILON;
                let tol = tol * want.norm();
                assert!(
                    (got - want).norm() <= tol,
                    "p = {p}, k = {k}: {got} vs {want}"
                );
            }
        }
    }

    /// The recursion over the grid agrees with one exponential per sample to rounding (about
    /// `RESTART` units of the largest entry of a column), on a long record with a pair and a
    /// real pole, whatever the family's route to `M(p)` (closed form or rule). Columns of
    /// parameters that do not move the poles are zero by both routes.
    #[test]
    fn free_part_by_recursion_equals_per_sample_route() {
        let g = Zpk::new(
            0.8,
            vec![Root::Real(-0.5)],
            vec![Root::Pair { re: -0.03, im: 0.7 }, Root::Real(-0.09)],
        )
        .unwrap();
        let u = binary(3, 4.0, 0.0, 400.0).unwrap();
        let s = WithInitialState::new(LtiResponse::new(g, u), -0.4, vec![0.4, -0.7, 1.1]).unwrap();
        let grid = SampleGrid::new(0.25, 0.5, 777).unwrap();
        let jitters: Vec<Box<dyn JitterModel>> = vec![
            Box::new(UniformSum::new(2, 0.2).unwrap()),
            Box::new(Gaussian::new(0.17).unwrap()),
            Box::new(Laplace::new(0.1).unwrap()),
        ];
        for j in &jitters {
            let (v_ref, cols_ref) = per_sample(&s, &grid, j.as_ref());
            let mut v = vec![0.0; grid.len()];
            let mut cols = vec![vec![0.0; grid.len()]; cols_ref.len()];
            s.add_free(&grid, j.as_ref(), Some(&mut v), Some(&mut cols));
            for (got, want) in std::iter::once(&v)
                .chain(&cols)
                .zip(std::iter::once(&v_ref).chain(&cols_ref))
            {
                let scale = want.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                // The gain and the zeros do not move the poles: their columns are zero.
                for (k, (a, b)) in got.iter().zip(want).enumerate() {
                    assert!(
                        (a - b).abs() <= 1e-14 * scale,
                        "{}: sample {k}: {a} vs {b} (scale {scale})",
                        j.name()
                    );
                }
            }
        }
    }
}
