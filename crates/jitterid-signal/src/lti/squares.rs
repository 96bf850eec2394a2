//! The second moment `E[s(t_k + τ)²]` of a linear response, the `λ_k` of the likelihoods: by the
//! jitter's quadrature rules on each sample's reach for a piecewise-constant input, by the
//! square's expansion over pairs of poles where those rules would be too large, and in closed
//! form for tones.

use super::LtiResponse;
use crate::input::Input;
use crate::rational::RationalModel;
use crate::reach::{InReach, Route, SquaresRule};
use crate::signal::Jacobian;
use crate::SampleGrid;
use jitterid_jitter::JitterModel;
use num_complex::Complex64;
use std::f64::consts::TAU;

impl<M: RationalModel> LtiResponse<M> {
    /// `E[s(t_k + τ)²]` for a piecewise-constant input: `s` on each sample's reach is the past
    /// steps' modal state plus the steps inside the reach, evaluated at the jitter's quadrature
    /// nodes in `O(poles + steps in reach)` per node. The rules ([`SquaresRule`]) are refined
    /// only where a transient is alive, after a step or the start of the reach. When even that
    /// needs too many nodes (a fast, lightly damped pole: `|p|/|Re p|` nodes per piece), the
    /// square is expanded instead ([`squares_by_expansion`](Self::squares_by_expansion)).
    pub(super) fn piecewise_squares(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> Vec<f64> {
        let Some(m) = self.modal() else {
            let (cf, _) = self.confluent_prefix();
            return cf.expected_squares(&self.steps, grid, jitter);
        };
        let reps = self.representatives();
        let poles: Vec<Complex64> = reps.iter().map(|&(i, _)| m.poles[i]).collect();
        let coef: Vec<Complex64> = reps
            .iter()
            .map(|&(i, w)| m.residues[i] / m.poles[i] * w)
            .collect();
        let (lo, hi) = jitter.reach();
        let rules = SquaresRule::new(jitter, &poles);
        if !rules.affordable() {
            return self.squares_by_expansion(grid, jitter, &poles, &coef);
        }
        let (mut full_nodes, mut full_weights) = (Vec::new(), Vec::new());
        rules.build(&[], &mut full_nodes, &mut full_weights);
        let (mut cut_nodes, mut cut_weights, mut cuts) = (Vec::new(), Vec::new(), Vec::new());
        let mut out = vec![0.0; grid.len()];
        self.walk(
            grid,
            lo,
            hi,
            &poles,
            false,
            |k, t, u_past, x, _, in_reach| {
                let (nodes, weights) = if in_reach.is_empty() {
                    (&full_nodes, &full_weights)
                } else {
                    cuts.clear();
                    cuts.extend(in_reach.iter().map(|s| s.0 - t));
                    rules.build(&cuts, &mut cut_nodes, &mut cut_weights);
                    (&cut_nodes, &cut_weights)
                };
                let mut acc = 0.0;
                for (&tau, &w) in nodes.iter().zip(weights) {
                    let mut s = m.dc_gain * u_past;
                    for i in 0..poles.len() {
                        s += (coef[i] * x[i] * (poles[i] * (tau - lo)).exp()).re;
                    }
                    for &(tj, du) in in_reach {
                        let xj = tau - (tj - t);
                        if xj >= 0.0 {
                            let mut step = m.dc_gain;
                            for i in 0..poles.len() {
                                step += (coef[i] * (poles[i] * xj).exp()).re;
                            }
                            s += du * step;
                        }
                    }
                    acc += w * s * s;
                }
                out[k] = acc;
            },
        );
        out
    }

    /// `E[s(t_k + τ)²]` by expanding the square. Between consecutive steps in the reach
    /// (`c_0 = lo`, then the steps' `c_m`), `s = C_m + Σ_i Re(a_mi e^{p_i(τ − c_m)})`, and
    /// `Re(a) Re(b) = ½ Re(ab + a b̄)`, so `E[s² 1{c_m ≤ τ < c_{m+1}}]` needs
    /// `D_q(c) = E[e^{q(τ−c)} 1{τ ≥ c}]` at `q = p_i`, `p_i + p_j` and `p_i + p̄_j` (all stable),
    /// through `D_q(c_m) − e^{q(c_{m+1} − c_m)} D_q(c_{m+1})`: the first-moment functions of
    /// [`InReach`], whose cost does not grow with `|p|`.
    ///
    /// Exact like the quadrature route, but its rounding error is `ε (|C| + Σ|a_i|)²` rather
    /// than `ε |s| (|C| + Σ|a_i|)`, so it serves only where the quadrature would need too many
    /// nodes.
    pub(super) fn squares_by_expansion(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
        poles: &[Complex64],
        coef: &[Complex64],
    ) -> Vec<f64> {
        let dc = self.modal().map_or(0.0, |m| m.dc_gain);
        let np = poles.len();
        let pairs: Vec<(usize, usize)> =
            (0..np).flat_map(|i| (i..np).map(move |j| (i, j))).collect();
        // Exponents: p_i, then p_i + p_j and p_i + p̄_j for i ≤ j.
        let mut q: Vec<Complex64> = poles.to_vec();
        q.extend(pairs.iter().map(|&(i, j)| poles[i] + poles[j]));
        q.extend(pairs.iter().map(|&(i, j)| poles[i] + poles[j].conj()));
        let (lo, hi) = jitter.reach();
        let mut queries = 0;
        self.walk(grid, lo, hi, &[], false, |_, _, _, _, _, in_reach| {
            queries += in_reach.len();
        });
        let reach = InReach::new(jitter, &q, false, Route::Auto(queries));
        let zero = Complex64::new(0.0, 0.0);
        let (mut here, mut next) = (vec![zero; reach.width()], vec![zero; reach.width()]);
        let mut a = vec![zero; np];
        let mut out = vec![0.0; grid.len()];
        self.walk(
            grid,
            lo,
            hi,
            poles,
            false,
            |k, t, u_past, x, _, in_reach| {
                let mut level = dc * u_past;
                for ((a, c), x) in a.iter_mut().zip(coef).zip(x) {
                    *a = c * x;
                }
                here.copy_from_slice(reach.at_start());
                let mut c = lo;
                let mut acc = 0.0;
                for m in 0..=in_reach.len() {
                    // The values at the next step (none beyond the reach), and the distance.
                    let (c_next, delta) = match in_reach.get(m) {
                        Some(&(tj, _)) => {
                            reach.eval(tj - t, &mut next);
                            (tj - t, tj - t - c)
                        }
                        None => {
                            next.fill(zero);
                            (c, 0.0)
                        }
                    };
                    // E[e^{q(τ−c)} 1{c ≤ τ < c_next}] for every exponent.
                    let d = |l: usize| here[1 + l] - (q[l] * delta).exp() * next[1 + l];
                    let mut seg = level * level * (here[0].re - next[0].re);
                    for (i, ai) in a.iter().enumerate() {
                        seg += 2.0 * level * (ai * d(i)).re;
                    }
                    for (l, &(i, j)) in pairs.iter().enumerate() {
                        let plus = (a[i] * a[j] * d(np + l)).re;
                        let minus = (a[i] * a[j].conj() * d(np + pairs.len() + l)).re;
                        seg += if i == j {
                            0.5 * (plus + minus)
                        } else {
                            plus + minus
                        };
                    }
                    acc += seg;
                    if let Some(&(_, du)) = in_reach.get(m) {
                        // Move the reference to the step and add it.
                        for ((a, p), cf) in a.iter_mut().zip(poles).zip(coef) {
                            *a = *a * (p * delta).exp() + du * cf;
                        }
                        level += du * dc;
                        c = c_next;
                        std::mem::swap(&mut here, &mut next);
                    }
                }
                out[k] = acc;
            },
        );
        out
    }

    /// `E[s(t_k + τ)²]` for tones: with `a_l = A_l G(i2πf_l) e^{iφ_l}`,
    /// `s² = Σ_l Σ_m ½ Re(a_l ā_m e^{i(ω_l−ω_m)t} − a_l a_m e^{i(ω_l+ω_m)t})`, so the expectation
    /// needs `γ` at the sums and differences of the tones' frequencies.
    pub(super) fn tones_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let Input::Tones(ms) = &self.input else {
            return vec![0.0; grid.len()];
        };
        let tones: Vec<(f64, Complex64)> = ms
            .tones()
            .iter()
            .map(|c| {
                let g = self.model.frequency_response(c.frequency);
                (c.frequency, g * Complex64::from_polar(c.amplitude, c.phase))
            })
            .collect();
        grid.times()
            .map(|t| {
                // `O(L²)` per sample: unfinished once the budget is spent.
                if jitterid_numeric::budget::spent() {
                    return f64::NAN;
                }
                let mut acc = 0.0;
                for &(fl, al) in &tones {
                    for &(fm, am) in &tones {
                        let diff = al
                            * am.conj()
                            * Complex64::from_polar(1.0, TAU * (fl - fm) * t)
                            * jitter.cf(-(fl - fm));
                        let sum = al
                            * am
                            * Complex64::from_polar(1.0, TAU * (fl + fm) * t)
                            * jitter.cf(-(fl + fm));
                        acc += 0.5 * (diff - sum).re;
                    }
                }
                acc
            })
            .collect()
    }

    pub(super) fn tones_expectation(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
        grad: Option<&mut Jacobian>,
    ) -> Vec<f64> {
        let Input::Tones(m) = &self.input else {
            return vec![0.0; grid.len()];
        };
        let np = self.model.params().len();
        let mut out = vec![0.0; grid.len()];
        let mut dg = vec![Complex64::new(0.0, 0.0); np];
        let mut grad = grad;
        for tone in m.tones() {
            if jitterid_numeric::budget::spent() {
                // Unfinished: the caller's budget reports it.
                out.iter_mut().for_each(|v| *v = f64::NAN);
                return out;
            }
            let s = Complex64::new(0.0, TAU * tone.frequency);
            let g = self.model.response(s);
            self.model.rational().response_gradient(s, &mut dg);
            // E[e^{i2πf τ}] = γ(−f).
            let damp = jitter.cf(-tone.frequency);
            for (k, t) in grid.times().enumerate() {
                let e =
                    Complex64::from_polar(tone.amplitude, TAU * tone.frequency * t + tone.phase)
                        * damp;
                out[k] += (g * e).im;
                if let Some(cols) = grad.as_deref_mut() {
                    for (col, d) in cols.iter_mut().zip(&dg) {
                        col[k] += (d * e).im;
                    }
                }
            }
        }
        out
    }
}
