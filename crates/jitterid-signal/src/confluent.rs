//! The exact response of a rational model whose modal form breaks down: repeated or nearly
//! repeated poles (`1/(s+1)²`, a pair of a search passing through the real axis), poles at the
//! origin (`1/s`, `1/(s(s+1))`) and other poles on or right of the imaginary axis.
//!
//! # Route
//!
//! The modal form writes the step response as `G(0) + Σ_i (r_i/p_i) e^{p_i t}`; at a repeated
//! pole the residues are infinite and terms `t^j e^{pt}` appear, and at a pole at the origin
//! `G(0)` is. A state-space realisation has neither problem: every response is `c·e^{Mt}z`.
//!
//! One realisation serves the response and its gradient. With `G = N/A` (`A` monic of degree
//! `n`), `∂G/∂θ_j = (N'_j A − N A'_j)/A²` and `G = N A/A²`: every one is a numerator over the
//! same `A²`. So the controllable companion form of `A²` (order `2n`), driven by the input level
//! `u` (a state of its own, constant between steps, so that a step is a jump of that state),
//! gives `s(t)` and every `∂s/∂θ_j` as readouts `c·z(t)` of one state `z`: the parameter
//! sensitivities of a linear system are themselves outputs of a linear system.
//!
//! The state is scaled (`x̃_i = ρ^{i−1} x_i`, `ρ` the largest pole modulus) so that the
//! companion matrix's entries are of the order of `ρ` instead of `ρ^{2n}`.
//!
//! # Jittered moments
//!
//! Everything is linear in the state. The state `z_k` at `t_k + lo` (`lo` the start of the
//! jitter's reach) from the steps before it is carried from sample to sample by `e^{MT}`;
//! beyond that instant, `E[e^{M(τ−lo)}]` is one matrix per evaluation (the jitter's quadrature
//! rule), and a step inside the reach at `c = t_j − t_k` adds `Δu_j E[e^{M(τ−c)} e_u 1{τ ≥ c}]`
//! (the jitter's rule from `c`). The second moment evaluates `s` at the rule's nodes, cut at the
//! steps inside the reach. The quadrature is exact for these integrands up to rounding (each is
//! analytic between the cuts), as for every signal without a closed form.

use crate::coefficients::Coefficients;
use crate::expm::{expm, mat_vec, vec_mat};
use crate::poly;
use crate::signal::Jacobian;
use crate::SampleGrid;
use jitterid_jitter::rule::QuadratureRule;
use jitterid_jitter::JitterModel;
use jitterid_numeric::budget;
use num_complex::Complex64;

/// A rational model and its parameter derivatives as readouts of one linear system.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Confluent {
    /// State dimension `2n + 1` (the last state is the input level).
    dim: usize,
    /// The generator `M`, row-major.
    generator: Vec<f64>,
    /// Readout of `s`.
    value: Vec<f64>,
    /// Readouts of `∂s/∂θ_j`.
    grads: Vec<Vec<f64>>,
    /// Readout of `ṡ` between steps (`value·M`).
    rate: Vec<f64>,
    /// `ρ`: the largest pole modulus (1 when every pole is at the origin), the rate that sets
    /// the quadrature's resolution.
    scale: f64,
    /// Whether the generator is the scaled companion form of a rational model (whose product
    /// with a vector has a structured `O(d)` route); a general linear readout system is not.
    companion: bool,
    /// Refinement zones of a mode started at 0 ([`crate::reach`]'s): `(x_end, rate)`, beyond
    /// the last end every mode has decayed below `e^{−50}`.
    zones: Vec<(f64, f64)>,
    /// `h` with `‖Mh‖₁ ≤ 1/2`, and `e^{M h 2^i}`: `e^{Mx}v` is a short Taylor series on
    /// `x mod h` then one product per binary digit of `⌊x/h⌋`.
    block: f64,
    powers: Vec<Vec<f64>>,
    /// `M^k e_u / k!` for `k ≤ TAYLOR`: the step's state as a polynomial in `x` on a block.
    step_taylor: Vec<Vec<f64>>,
}

/// Terms of the Taylor series on one block (`‖Mx‖₁ ≤ 1/2`: error below `1e-18`).
const TAYLOR: usize = 16;

/// Binary digits of `⌊x/h⌋` covered by [`Confluent::exp_apply`]'s table (beyond, the full
/// exponential).
const POWERS: usize = 63;

impl Confluent {
    /// The realisation of `r` and its derivatives.
    pub(crate) fn new(r: &Coefficients<'_>) -> Self {
        let den = r.den;
        let n = den.len() - 1;
        let a2 = poly::mul(den, den);
        let m = 2 * n;
        let dim = m + 1;
        let rho = r.poles.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let scale = if rho > 0.0 && rho.is_finite() {
            rho
        } else {
            1.0
        };
        // ρ^{1−i} for i = 1..=m.
        let shrink: Vec<f64> = (1..=m).map(|i| scale.powi(1 - i as i32)).collect();
        let mut generator = vec![0.0; dim * dim];
        for i in 1..=m {
            generator[i - 1] = -a2[i] * shrink[i - 1];
        }
        generator[m] = 1.0;
        for i in 1..m {
            generator[i * dim + i - 1] = scale;
        }
        let readout = |p: &[f64]| readout(&a2, scale, p);
        let num = r.num;
        let value = readout(&poly::mul(num, den));
        let grads = r
            .d_num
            .iter()
            .zip(r.d_den)
            .map(|(dn, da)| {
                let a = poly::pad(&poly::mul(dn, den), dim);
                let b = poly::pad(&poly::mul(num, da), dim);
                let p: Vec<f64> = a.iter().zip(&b).map(|(a, b)| a - b).collect();
                readout(&p)
            })
            .collect();
        Self::assemble(generator, value, grads, scale, r.poles, true)
    }

    /// A general linear readout system: the generator `M` (`dim × dim`, row-major, whose last
    /// state is the input level: its last row is zero), the readout of `s` and one of each
    /// `∂s/∂θ_j`, and the eigenvalues of `M` but the input level's zero (with their
    /// multiplicity, or at least every distinct one), which set the quadrature's refinement.
    /// The grey-box state-space model's sensitivities are such a system (the state and its
    /// parameter derivatives driven by the level).
    pub(crate) fn linear(
        generator: Vec<f64>,
        value: Vec<f64>,
        grads: Vec<Vec<f64>>,
        poles: &[Complex64],
    ) -> Self {
        let rho = poles.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let scale = if rho > 0.0 && rho.is_finite() {
            rho
        } else {
            1.0
        };
        Self::assemble(generator, value, grads, scale, poles, false)
    }

    /// The tables shared by every generator: the rate readout, the block length and its
    /// powers, the step's Taylor terms and the refinement zones.
    fn assemble(
        generator: Vec<f64>,
        value: Vec<f64>,
        grads: Vec<Vec<f64>>,
        scale: f64,
        poles: &[Complex64],
        companion: bool,
    ) -> Self {
        let dim = value.len();
        let mut rate = vec![0.0; dim];
        vec_mat(&value, &generator, &mut rate);
        let norm = (0..dim)
            .map(|j| (0..dim).map(|i| generator[i * dim + j].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let block = 0.5 / norm.max(f64::MIN_POSITIVE);
        let mut powers = vec![expm(&generator, dim, block)];
        for i in 1..POWERS {
            let mut sq = vec![0.0; dim * dim];
            crate::expm::mat_mul(&powers[i - 1], &powers[i - 1], dim, &mut sq);
            powers.push(sq);
        }
        let mut step_taylor = Vec::with_capacity(TAYLOR + 1);
        let mut v = vec![0.0; dim];
        v[dim - 1] = 1.0;
        for k in 0..=TAYLOR {
            if k > 0 {
                let mut next = vec![0.0; dim];
                mat_vec(&generator, &v, &mut next);
                v = next.iter().map(|x| x / k as f64).collect();
            }
            step_taylor.push(v.clone());
        }
        let zones = crate::reach::zones(poles, 1.0);
        Self {
            dim,
            generator,
            value,
            grads,
            rate,
            scale,
            companion,
            zones,
            block,
            powers,
            step_taylor,
        }
    }

    /// The state dimension (the sensitivity blocks a grey-box realisation needs, in tests).
    #[cfg(test)]
    pub(crate) fn dim(&self) -> usize {
        self.dim
    }

    /// `e^{Mx} v` for `x ≥ 0`: the Taylor series on `x mod h` (`taylor`, when given, holds
    /// `M^k v/k!`; otherwise Horner's rule on `v`) and a product with `e^{M h 2^i}` for each
    /// binary digit `i` of `⌊x/h⌋`; the full exponential for `x < 0` or beyond the table.
    fn exp_apply(&self, x: f64, v: &[f64], taylor: Option<&[Vec<f64>]>) -> Vec<f64> {
        let d = self.dim;
        let blocks = (x / self.block).floor();
        if !(x >= 0.0 && blocks < 2f64.powi(POWERS as i32)) {
            let mut out = vec![0.0; d];
            mat_vec(&self.exp(x), v, &mut out);
            return out;
        }
        let r = x - blocks * self.block;
        let mut tmp = vec![0.0; d];
        let mut out = match taylor {
            Some(t) => {
                // Σ r^k (M^k v/k!) by Horner in r.
                let mut acc = t[TAYLOR].clone();
                for term in t[..TAYLOR].iter().rev() {
                    for (a, c) in acc.iter_mut().zip(term) {
                        *a = *a * r + c;
                    }
                }
                acc
            }
            None => {
                // v + (rM)(v + (rM/2)(v + …)).
                let mut acc = v.to_vec();
                for k in (1..=TAYLOR).rev() {
                    self.generator_apply(&acc, &mut tmp);
                    let f = r / k as f64;
                    for ((a, t), vi) in acc.iter_mut().zip(&tmp).zip(v) {
                        *a = vi + f * t;
                    }
                }
                acc
            }
        };
        let mut digits = blocks as u64;
        for power in &self.powers {
            if digits == 0 {
                break;
            }
            if digits & 1 == 1 {
                mat_vec(power, &out, &mut tmp);
                std::mem::swap(&mut out, &mut tmp);
            }
            digits >>= 1;
        }
        out
    }

    /// `M v` into `out`; for the companion form by its structure: a full first row, the scaled
    /// shift `ρ v_{i−1}` below it and a zero last row (the input level is constant), `O(d)`
    /// instead of `O(d²)`. The first row's sum runs in the dense product's order and the other
    /// rows add only exact zeros to their one term there, so the result is the same to the bit.
    fn generator_apply(&self, v: &[f64], out: &mut [f64]) {
        let d = self.dim;
        if d < 2 || !self.companion {
            mat_vec(&self.generator, v, out);
            return;
        }
        out[0] = self.generator[..d].iter().zip(v).map(|(a, x)| a * x).sum();
        for i in 1..d - 1 {
            out[i] = self.scale * v[i - 1];
        }
        out[d - 1] = 0.0;
    }

    /// The refinement rate at `x` after the origins `origins` (`0` where every mode started
    /// there has decayed).
    fn rate_after(&self, origins: &[f64], x: f64, factor: f64) -> f64 {
        origins
            .iter()
            .filter(|&&o| o <= x)
            .map(|&o| {
                self.zones
                    .iter()
                    .find(|z| x - o < z.0)
                    .map_or(0.0, |z| factor * z.1)
            })
            .fold(0.0, f64::max)
    }

    /// The jitter's rule on `τ ≥ from` for a sum of this realisation's modes started at
    /// `origins` (cut there too), or of products of two of them (`factor` 2): refined as the
    /// modes alive at each place need, as [`crate::reach`] does, so that a fast decaying pole
    /// costs nodes only near its origin.
    fn rule_after(
        &self,
        jitter: &dyn JitterModel,
        from: f64,
        origins: &[f64],
        factor: f64,
    ) -> QuadratureRule {
        let mut rule = QuadratureRule::default();
        for (a, b) in jitter.pieces() {
            let a = a.max(from);
            if !(b > a) {
                continue;
            }
            let mut cuts = vec![a, b];
            for &o in origins {
                cuts.push(o);
                cuts.extend(self.zones.iter().map(|z| o + z.0));
            }
            cuts.retain(|c| (a..=b).contains(c));
            cuts.sort_by(f64::total_cmp);
            cuts.dedup();
            for w in cuts.windows(2) {
                let rate = self.rate_after(origins, 0.5 * (w[0] + w[1]), factor);
                rule.push_interval(w[0], w[1], rate, |t| jitter.pdf(t));
            }
        }
        for atom in jitter.atoms() {
            if atom.position >= from {
                rule.nodes.push(atom.position);
                rule.weights.push(atom.mass);
            }
        }
        rule
    }

    /// Readouts of the free response with Laplace transform `q(s)/A(s)` (coefficients
    /// `q_0 … q_{n−1}`, lowest power first), from the [`impulse_state`](Self::impulse_state):
    /// the response, its derivative with respect to each of `r`'s parameters
    /// (`−q A'_j/A²`), and with respect to each `q_i` (`s^i A/A²`).
    pub(crate) fn free_rows(&self, r: &Coefficients<'_>, q: &[f64]) -> FreeRows {
        // The companion realisation of `r` (the only one a free response is read from).
        let den = r.den;
        let den2 = poly::mul(den, den);
        let q_desc: Vec<f64> = q.iter().rev().copied().collect();
        let value = readout(&den2, self.scale, &poly::mul(&q_desc, den));
        let grads = r
            .d_den
            .iter()
            .map(|da| {
                let p: Vec<f64> = poly::mul(&q_desc, da).iter().map(|c| -c).collect();
                readout(&den2, self.scale, &p)
            })
            .collect();
        let basis = (0..q.len())
            .map(|i| {
                let mut si = vec![1.0];
                si.extend(std::iter::repeat_n(0.0, i));
                readout(&den2, self.scale, &poly::mul(&si, den))
            })
            .collect();
        FreeRows {
            value,
            grads,
            basis,
        }
    }

    /// The state `x` after a unit impulse at 0 from rest: `e^{Mx} e_1` (defined for `x < 0`
    /// too, as the analytic continuation of the free response).
    pub(crate) fn impulse_state(&self, x: f64) -> Vec<f64> {
        let e = self.exp(x);
        (0..self.dim).map(|i| e[i * self.dim]).collect()
    }

    /// `e^{MT}`, to carry states along a grid.
    pub(crate) fn carry(&self, interval: f64) -> Vec<f64> {
        self.exp(interval)
    }

    /// `E[e^{Mτ}] v` over the jitter.
    pub(crate) fn expected_from(&self, jitter: &dyn JitterModel, v: &[f64]) -> Vec<f64> {
        let rule = jitter.rule(&[], self.scale);
        let mut out = vec![0.0; self.dim];
        let mut ev = vec![0.0; self.dim];
        for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
            mat_vec(&self.exp(tau), v, &mut ev);
            for (o, e) in out.iter_mut().zip(&ev) {
                *o += w * e;
            }
        }
        out
    }

    /// `e^{Mx}`.
    fn exp(&self, x: f64) -> Vec<f64> {
        expm(&self.generator, self.dim, x)
    }

    /// The state `x ≥ 0` after a unit step from rest: the last column of `e^{Mx}`.
    fn step_state(&self, x: f64) -> Vec<f64> {
        let mut e_u = vec![0.0; self.dim];
        e_u[self.dim - 1] = 1.0;
        self.exp_apply(x, &e_u, Some(&self.step_taylor))
    }

    /// The unit-step response `x ≥ 0` after the step and its gradient.
    pub(crate) fn step_response(&self, x: f64, grad: &mut [f64]) -> f64 {
        let z = self.step_state(x);
        for (g, row) in grad.iter_mut().zip(&self.grads) {
            *g = dot(row, &z);
        }
        dot(&self.value, &z)
    }

    /// The impulse response `x > 0` after the impulse (the step response's rate).
    pub(crate) fn impulse_response(&self, x: f64) -> f64 {
        dot(&self.rate, &self.step_state(x))
    }

    /// The state right after each step `(t_j, Δu_j)`, row-major.
    pub(crate) fn prefix(&self, steps: &[(f64, f64)]) -> Vec<f64> {
        let d = self.dim;
        let mut out = Vec::with_capacity(steps.len() * d);
        let mut z = vec![0.0; d];
        let mut prev = f64::NEG_INFINITY;
        for &(tj, du) in steps {
            if prev.is_finite() {
                z = self.exp_apply(tj - prev, &z, None);
            }
            z[d - 1] += du;
            prev = tj;
            out.extend_from_slice(&z);
        }
        out
    }

    /// `s(t)` (and `∂s/∂θ_j` into `grad` when given) from the [`prefix`](Self::prefix) states.
    pub(crate) fn value_at(
        &self,
        steps: &[(f64, f64)],
        prefix: &[f64],
        t: f64,
        grad: Option<&mut [f64]>,
    ) -> f64 {
        let j = steps.partition_point(|s| s.0 <= t);
        if j == 0 {
            if let Some(g) = grad {
                g.iter_mut().for_each(|g| *g = 0.0);
            }
            return 0.0;
        }
        let d = self.dim;
        let z = self.exp_apply(t - steps[j - 1].0, &prefix[(j - 1) * d..j * d], None);
        if let Some(g) = grad {
            for (g, row) in g.iter_mut().zip(&self.grads) {
                *g = dot(row, &z);
            }
        }
        dot(&self.value, &z)
    }

    /// `ṡ(t)` between steps from the [`prefix`](Self::prefix) states.
    pub(crate) fn rate_at(&self, steps: &[(f64, f64)], prefix: &[f64], t: f64) -> f64 {
        let j = steps.partition_point(|s| s.0 <= t);
        if j == 0 {
            return 0.0;
        }
        let d = self.dim;
        let z = self.exp_apply(t - steps[j - 1].0, &prefix[(j - 1) * d..j * d], None);
        dot(&self.rate, &z)
    }

    /// Visits every sample `k` with the state `z_k` at `t_k + lo` due to the steps at or
    /// before that instant and the steps inside the reach `(t_k + lo, t_k + hi]`, carrying the
    /// state by `e^{MT}`: `O(N + J)` matrix-vector products and one exponential per step.
    fn walk(
        &self,
        steps: &[(f64, f64)],
        grid: &SampleGrid,
        lo: f64,
        hi: f64,
        mut visit: impl FnMut(usize, f64, &[f64], &[(f64, f64)]),
    ) {
        let d = self.dim;
        let carry = self.exp(grid.interval());
        let mut z = vec![0.0; d];
        let mut next = vec![0.0; d];
        let (mut next_past, mut reach_end) = (0usize, 0usize);
        for k in 0..grid.len() {
            let t = grid.time(k);
            if k > 0 {
                mat_vec(&carry, &z, &mut next);
                std::mem::swap(&mut z, &mut next);
            }
            while next_past < steps.len() && steps[next_past].0 <= t + lo {
                let (tj, du) = steps[next_past];
                for (zi, si) in z.iter_mut().zip(self.step_state(t + lo - tj)) {
                    *zi += du * si;
                }
                next_past += 1;
            }
            reach_end = reach_end.max(next_past);
            while reach_end < steps.len() && steps[reach_end].0 <= t + hi {
                reach_end += 1;
            }
            if budget::spent() {
                // The rest of the record is left unfinished (see `LtiResponse::walk`).
                z.iter_mut().for_each(|v| *v = f64::NAN);
                for k in k..grid.len() {
                    visit(k, grid.time(k), &z, &[]);
                }
                return;
            }
            visit(k, t, &z, &steps[next_past..reach_end]);
        }
    }

    /// For each readout row, its expectation `E[row·z(t_k + τ)]` at every sample.
    fn expected_rows(
        &self,
        steps: &[(f64, f64)],
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
        rows: &[&[f64]],
    ) -> Vec<Vec<f64>> {
        let d = self.dim;
        let (lo, hi) = jitter.reach();
        let full = self.rule_after(jitter, lo, &[lo], 1.0);
        let mut mean = vec![0.0; d * d];
        for (&tau, &w) in full.nodes.iter().zip(&full.weights) {
            // A matrix exponential per node: a spent budget leaves the mean unfinished, and
            // the walk below then every sample (NaN).
            if budget::spent() {
                break;
            }
            for (m, e) in mean.iter_mut().zip(self.exp(tau - lo)) {
                *m += w * e;
            }
        }
        // row·E[e^{M(τ−lo)}], one per readout.
        let through: Vec<Vec<f64>> = rows
            .iter()
            .map(|row| {
                let mut v = vec![0.0; d];
                vec_mat(row, &mean, &mut v);
                v
            })
            .collect();
        let mut out: Vec<Vec<f64>> = rows
            .iter()
            .map(|_| Vec::with_capacity(grid.len()))
            .collect();
        let mut late = vec![0.0; d];
        self.walk(steps, grid, lo, hi, |_, t, z, in_reach| {
            late.iter_mut().for_each(|x| *x = 0.0);
            for &(tj, du) in in_reach {
                if budget::spent() {
                    late.iter_mut().for_each(|x| *x = f64::NAN);
                    break;
                }
                let c = tj - t;
                let rule = self.rule_after(jitter, c, &[c], 1.0);
                for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
                    for (l, s) in late.iter_mut().zip(self.step_state(tau - c)) {
                        *l += du * w * s;
                    }
                }
            }
            for ((col, v), row) in out.iter_mut().zip(&through).zip(rows) {
                col.push(dot(v, z) + dot(row, &late));
            }
        });
        out
    }

    /// `m_k = E[s(t_k + τ)]`.
    pub(crate) fn expected_values(
        &self,
        steps: &[(f64, f64)],
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> Vec<f64> {
        self.expected_rows(steps, grid, jitter, &[&self.value])
            .pop()
            .unwrap_or_default()
    }

    /// `m_k` and `∂m_k/∂θ_j` (as columns).
    pub(crate) fn expected_values_and_gradient(
        &self,
        steps: &[(f64, f64)],
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        let mut rows: Vec<&[f64]> = vec![&self.value];
        rows.extend(self.grads.iter().map(|g| g.as_slice()));
        let mut cols = self.expected_rows(steps, grid, jitter, &rows);
        let values = cols.remove(0);
        (values, cols)
    }

    /// `E[ṡ(t_k + τ)]` between steps (the feed-through's jumps left to the caller).
    pub(crate) fn expected_rates(
        &self,
        steps: &[(f64, f64)],
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> Vec<f64> {
        self.expected_rows(steps, grid, jitter, &[&self.rate])
            .pop()
            .unwrap_or_default()
    }

    /// `E[s(t_k + τ)²]`: `s` at the jitter's quadrature nodes, the rule cut at the steps
    /// inside the sample's reach.
    pub(crate) fn expected_squares(
        &self,
        steps: &[(f64, f64)],
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> Vec<f64> {
        let d = self.dim;
        let (lo, hi) = jitter.reach();
        let full = self.rule_after(jitter, lo, &[lo], 2.0);
        // value·e^{M(τ_i − lo)} at the full rule's nodes, shared by every sample whose reach
        // holds no step.
        let full_rows: Vec<Vec<f64>> = full
            .nodes
            .iter()
            .map(|&tau| {
                let mut v = vec![0.0; d];
                vec_mat(&self.value, &self.exp(tau - lo), &mut v);
                v
            })
            .collect();
        let mut out = Vec::with_capacity(grid.len());
        let mut cuts = Vec::new();
        self.walk(steps, grid, lo, hi, |_, t, z, in_reach| {
            if in_reach.is_empty() {
                out.push(
                    full_rows
                        .iter()
                        .zip(&full.weights)
                        .map(|(v, w)| w * dot(v, z).powi(2))
                        .sum(),
                );
                return;
            }
            cuts.clear();
            cuts.push(lo);
            cuts.extend(in_reach.iter().map(|s| s.0 - t));
            let rule = self.rule_after(jitter, lo, &cuts, 2.0);
            let mut acc = 0.0;
            for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
                let zt = self.exp_apply(tau - lo, z, None);
                let mut s = dot(&self.value, &zt);
                for &(tj, du) in in_reach {
                    let x = tau - (tj - t);
                    if x >= 0.0 {
                        s += du * dot(&self.value, &self.step_state(x));
                    }
                }
                acc += w * s * s;
            }
            out.push(acc);
        });
        out
    }
}

/// Readouts of a free response; see [`Confluent::free_rows`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FreeRows {
    /// The free response.
    pub value: Vec<f64>,
    /// Its derivative with respect to each parameter of the model.
    pub grads: Vec<Vec<f64>>,
    /// Its derivative with respect to each coefficient `q_i`.
    pub basis: Vec<Vec<f64>>,
}

/// The readout of `P(s)/A²(s)` (`P` of degree at most `2n`, decreasing powers) from the
/// scaled companion state and the input level: `P = P_0 A² + R`, `R` read from the state,
/// `P_0` (the feed-through) from the level.
fn readout(a2: &[f64], scale: f64, p: &[f64]) -> Vec<f64> {
    let dim = a2.len();
    let m = dim - 1;
    let p = poly::pad(p, dim);
    let direct = p[0];
    let mut row: Vec<f64> = (1..=m)
        .map(|i| (p[i] - direct * a2[i]) * scale.powi(1 - i as i32))
        .collect();
    row.push(direct);
    row
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{RationalModel, TransferFunction};

    #[test]
    fn structured_generator_product_equals_the_dense_one_to_the_bit() {
        // A repeated pair, an integrator with a zero, a triple real pole.
        let models = [
            TransferFunction::new(&[5.0], &[1.0, 4.0, 14.0, 20.0, 25.0]).unwrap(),
            TransferFunction::new(&[1.0, 3.0], &[1.0, 1.0, 0.0]).unwrap(),
            TransferFunction::new(&[2.0], &[1.0, 3.0, 3.0, 1.0]).unwrap(),
        ];
        for r in &models {
            let cf = Confluent::new(&r.rational().coefficients());
            let d = cf.dim;
            for seed in 0..50u32 {
                let v: Vec<f64> = (0..d)
                    .map(|i| ((seed * 31 + i as u32 * 17) % 97) as f64 / 13.0 - 3.5)
                    .collect();
                let (mut dense, mut fast) = (vec![0.0; d], vec![0.0; d]);
                mat_vec(&cf.generator, &v, &mut dense);
                cf.generator_apply(&v, &mut fast);
                // Equal values are equal bits but for the sign of a zero.
                assert_eq!(dense, fast, "{r:?}");
            }
        }
    }
}
