//! The exact per-sample likelihood
//!
//! ```text
//! p(y_k) = ∫ φ_{σ_v}(y_k − s(t_k + τ)) p(τ; θ) dτ
//! ```
//!
//! by quadrature over the jitter, in logarithmic form (log-sum-exp over the nodes), with its
//! gradient.
//!
//! # Quadrature
//!
//! The integrand is smooth where the signal is, except that `φ_{σ_v}` is narrow: where the
//! signal moves by many `σ_v` across the jitter's reach (near an input step, on a fast tone),
//! the integrand is a spike of width `σ_v/|s'|` around the instants where `s(t_k + τ) = y_k`.
//! A rule that only resolves `s` misses it. The rule is therefore built per sample:
//!
//! 1. The jitter's pieces ([`JitterModel::pieces`]) are cut at the signal's breakpoints seen
//!    from the sample ([`local_breaks`]) and split so that `rate · width ≤ 6`; each interval
//!    gets a 16-point Gauss–Legendre rule, with the density folded into the weights.
//! 2. On an interval where `s` varies by less than `resolution · σ_v` (total variation over
//!    the nodes and ends, plus a curvature margin), that rule is used as it is.
//! 3. Otherwise the interval is cut into sub-intervals over which `s` varies by about
//!    `resolution · σ_v` each (equidistributed total variation), and every sub-interval where
//!    `s` comes within `window · σ_v` of `y_k` gets its own 16-point rule; the runs of
//!    sub-intervals farther away, which carry at most `e^{−window²/2}` of the peak, get one
//!    16-point rule each. If no part of the sample comes that close (the model is far from
//!    the data), every sub-interval gets its own rule.
//! 4. Atoms of the jitter are single nodes.
//! 5. Where the sample sees no breakpoint and `s` moves by at most `2σ_v` over the whole reach,
//!    the integrand is smooth on the reach: it is interpolated at 16 Chebyshev points and
//!    integrated against the jitter's Chebyshev moments `E[T_j(x(τ))]` (computed once per
//!    jitter parameter), provided the last Chebyshev coefficients are below `1e-13` of the
//!    result. Where they are not and `s` moves by at most `6σ_v`, the same is tried at 32
//!    points (the tails of step responses, where a 16-point interpolant of the Gaussian factor
//!    falls short but a 32-point one converges: a third of the nodes of the general rule);
//!    otherwise the general rule is used.
//!
//! With 16 nodes per `4σ_v` of signal range the Gaussian factor is integrated to about
//! `1e-16` relative. The signal is tabulated once per signal parameter as a piecewise
//! Chebyshev interpolant (cut at its breakpoints, checked against the signal at build time),
//! and the density once per jitter parameter, so a node costs two short polynomial
//! evaluations and one exponential.
//!
//! # Gradient
//!
//! `∂ log p(y_k)/∂θ = Σ_i r_i (y_k − s_i) ∂s(t_k + τ_i)/∂θ / σ_v²` over the same nodes `τ_i`
//! and responsibilities `r_i = w_i φ(y_k − s_i) / p(y_k)` as the value: one rule per sample
//! serves the value and every parameter, and the signal's gradient comes from the same
//! piecewise Chebyshev table as `s` (one channel per parameter, built from
//! [`Signal::value_gradient`]), so no parameter is differenced. The responsibilities are the
//! log-sum-exp's own terms, kept from the value's pass.
//!
//! # Threads
//!
//! Samples are independent, so they are shared among rayon's threads; every sample starts its
//! table searches afresh, so its terms do not depend on which thread computed it or what that
//! thread computed before, and the sums over samples are taken afterwards in sample order.
//! Values and gradients are therefore bit-identical for any number of threads.
//!
//! # Robustness
//!
//! Terms are summed relative to the largest exponent, and recomputed with the logarithms of
//! the weights if that sum underflows, so `log p` is finite whenever one node carries a
//! representable contribution. A sample whose likelihood is still zero is reported as
//! [`MlError::LikelihoodUnderflow`]; `σ_v = 0` as [`MlError::NoNoise`]; a reach wider than the
//! record as [`MlError::ReachExceedsRecord`]; a sample whose rule would hold more than
//! [`MAX_SAMPLE_NODES`] nodes as [`MlError::QuadratureTooLarge`] (a search treats all of them
//! as points outside the model's domain and steps back).

use super::cheb::{tables16, tables32, ChebTables, PiecewiseCheb, CHEB_POINTS};
use super::fastexp::{exp_nonpositive, EXP_FLOOR};
use super::MlError;
use jitterid_jitter::kernels::gauss::{gl16, subdivisions};
use jitterid_jitter::rule::{QuadratureRule, MAX_RATE_WIDTH, MAX_SUBDIVISIONS};
use jitterid_jitter::{Atom, JitterModel};
use jitterid_signal::{local_breaks, SampleGrid, Signal};
use serde::{Deserialize, Serialize};

/// `½ ln 2π`.
const HALF_LN_2PI: f64 = 0.918_938_533_204_672_8;

/// Relative accuracy asked of the signal and density tables.
const TABLE_TOL: f64 = 1e-13;

/// [`ExactMl::resolution`] of the screening form ([`LikelihoodCriterion::screening`]): a
/// 16-point rule over `8σ_v` of signal range integrates the Gaussian factor to `4e-10`
/// relative (`1e-13` over `6σ_v`, `5e-16` over `4σ_v`).
///
/// [`LikelihoodCriterion::screening`]: super::LikelihoodCriterion::screening
pub(crate) const SCREEN_RESOLUTION: f64 = 8.0;

/// [`ExactMl::window`] of the screening form: runs of sub-intervals farther than `6.5σ_v`
/// from `y_k` (at most `e^{−21} = 7e-10` of the peak) share one rule.
pub(crate) const SCREEN_WINDOW: f64 = 6.5;

/// [`ExactMl::shortcut_tolerance`] of the screening form.
pub(crate) const SCREEN_SHORTCUT_TOLERANCE: f64 = 1e-8;

/// The exact (non-Gaussian) maximum-likelihood criterion: the negative log-likelihood
/// `−Σ_k log p(y_k)` of independent samples `y_k = s(t_k + τ_k) + v_k` with white Gaussian
/// noise `v_k ~ N(0, σ_v²)`. The fields tune the quadrature (see the module docs); the
/// defaults give about 13 significant digits of every `log p(y_k)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExactMl {
    /// Signal range, in `σ_v`, of one refined sub-interval (default 4).
    pub resolution: f64,
    /// Distance from `y_k`, in `σ_v`, beyond which runs of sub-intervals share one rule
    /// (default 8.5: they carry at most `e^{−36}` of the peak).
    pub window: f64,
    /// Whether samples where the signal barely moves use the Chebyshev-moment shortcut
    /// (default true).
    pub shortcut: bool,
    /// Largest `|c_{N−2}| + |c_{N−1}|` of the shortcut's interpolant of the Gaussian factor,
    /// relative to the result, at which the shortcut is taken (default `1e-13`, about the
    /// relative error it leaves in `p(y_k)`).
    #[serde(default = "default_shortcut_tolerance")]
    pub shortcut_tolerance: f64,
    /// Whether samples are evaluated in parallel (rayon) for records of 64 samples or more
    /// (default true; results do not depend on it).
    pub parallel: bool,
}

impl Default for ExactMl {
    fn default() -> Self {
        ExactMl {
            resolution: 4.0,
            window: 8.5,
            shortcut: true,
            shortcut_tolerance: default_shortcut_tolerance(),
            parallel: true,
        }
    }
}

fn default_shortcut_tolerance() -> f64 {
    1e-13
}

impl ExactMl {
    pub(crate) fn validate(&self) -> Result<(), MlError> {
        let pos = |name, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(MlError::InvalidArgument {
                    name,
                    value: v,
                    reason: "must be finite and > 0",
                })
            }
        };
        pos("resolution", self.resolution)?;
        pos("window", self.window)?;
        pos("shortcut_tolerance", self.shortcut_tolerance)
    }
}

/// Most quadrature nodes the rule of one sample may hold. A sample needs many nodes only
/// where the noise level is tiny next to the signal's range over the jitter's reach and the
/// model passes nowhere near the sample (every sub-interval then gets its own rule, up to
/// [`MAX_SUBDIVISIONS`] per interval, and a wide reach has many intervals): a point whose
/// likelihood is astronomically small, which a search reaches only by an overlong trial step.
/// This bound (`2¹⁸`, four times the most that one refined interval can hold; a fully refined
/// sample of the `select` study at its estimate needs about 10³) caps the time and memory of one
/// evaluation instead of letting such a trial point run for minutes.
pub const MAX_SAMPLE_NODES: usize = jitterid_numeric::limits::MAX_QUADRATURE_NODES;

/// A sample's rule would exceed [`MAX_SAMPLE_NODES`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RuleTooLarge;

/// A coarse interval with its Gauss–Legendre nodes and density-weighted weights.
#[derive(Debug, Clone)]
struct Coarse {
    a: f64,
    b: f64,
    nodes: [f64; 16],
    weights: [f64; 16],
}

/// What the likelihood needs from the jitter at one parameter value.
#[derive(Debug, Clone)]
pub(crate) struct JitterPrep {
    lo: f64,
    hi: f64,
    /// Pieces split for the signal's rate (for samples without local breakpoints).
    coarse: Vec<Coarse>,
    atoms: Vec<Atom>,
    pdf: PiecewiseCheb,
    /// The jitter's Chebyshev moments over its reach, for the shortcut.
    moments: Option<Moments>,
}

/// `E[T_j((2τ − lo − hi)/(hi − lo))]` for `j < 16` and `j < 32`, and the node weights they
/// give ([`ChebTables::weights`]), which the Fisher information's cached route integrates with.
#[derive(Debug, Clone)]
struct Moments {
    narrow: [f64; CHEB_POINTS],
    wide: [f64; 32],
    narrow_weights: [f64; CHEB_POINTS],
    wide_weights: [f64; 32],
}

/// `E[T_j(x(τ))]`, `j < N`, over `rule`, `x` mapping `[lo, hi]` onto `[−1, 1]`.
fn chebyshev_moments<const N: usize>(rule: &QuadratureRule, lo: f64, hi: f64) -> [f64; N] {
    let mut mu = [0.0; N];
    for (&t, &w) in rule.nodes.iter().zip(&rule.weights) {
        let x = ((2.0 * t - lo - hi) / (hi - lo)).clamp(-1.0, 1.0);
        let (mut t0, mut t1) = (1.0, x);
        mu[0] += w;
        mu[1] += w * x;
        for m in mu.iter_mut().skip(2) {
            let t2 = 2.0 * x * t1 - t0;
            *m += w * t2;
            t0 = t1;
            t1 = t2;
        }
    }
    mu
}

/// Largest total variation of the signal over the reach, in `σ_v`, at which the 16-point
/// shortcut is tried: its Gaussian factor needs at most about `1σ_v` to converge to `1e-13`.
const SHORTCUT_TV: f64 = 2.0;

/// Largest total variation, in `σ_v`, at which the 32-point shortcut is tried after the
/// 16-point one did not converge: at 32 points the Gaussian factor converges to `1e-13` up to
/// about `5σ_v` of signal range (a linear signal: `c₃₀, c₃₁` are `6e-15` of the integral at
/// `4σ_v`, `1e-12` at `6σ_v`).
const WIDE_SHORTCUT_TV: f64 = 6.0;

/// Sub-intervals across the reach of the rule for the 32 moments: `T₃₁` times a density piece
/// of degree up to 9 has degree 40, beyond one 16-point rule's 31 on a piece as wide as the
/// reach; eight panels make the error about `8⁻³²` of that.
const WIDE_MOMENT_PANELS: f64 = 8.0;

/// Appends the 16-point rule of `[a, b]` with density `pdf` (at `τ`) folded in.
fn gl_interval(a: f64, b: f64, mut pdf: impl FnMut(f64) -> f64) -> Coarse {
    let (x, w) = gl16();
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let mut nodes = [0.0; 16];
    let mut weights = [0.0; 16];
    for i in 0..16 {
        nodes[i] = mid + half * x[i];
        weights[i] = half * w[i] * pdf(nodes[i]);
    }
    Coarse {
        a,
        b,
        nodes,
        weights,
    }
}

impl JitterPrep {
    pub(crate) fn new<J: JitterModel + ?Sized>(jitter: &J, rate: f64) -> Self {
        let (lo, hi) = jitter.reach();
        let pieces = jitter.pieces();
        let mut coarse = Vec::new();
        for &(a, b) in &pieces {
            let m = subdivisions(rate, b - a);
            let h = (b - a) / m as f64;
            for i in 0..m {
                let lo_i = a + i as f64 * h;
                let hi_i = if i + 1 == m { b } else { lo_i + h };
                coarse.push(gl_interval(lo_i, hi_i, |t| jitter.pdf(t)));
            }
        }
        let pdf = PiecewiseCheb::build(&pieces, 1, TABLE_TOL, |t, out| out[0] = jitter.pdf(t));
        let atoms = jitter.atoms();
        let moments = (hi > lo && lo.is_finite() && hi.is_finite()).then(|| {
            let wide_rate = WIDE_MOMENT_PANELS * MAX_RATE_WIDTH / (hi - lo);
            let narrow = chebyshev_moments(&jitter.rule(&[], 0.0), lo, hi);
            let wide = chebyshev_moments(&jitter.rule(&[], wide_rate), lo, hi);
            Moments {
                narrow_weights: tables16().weights(&narrow),
                wide_weights: tables32().weights(&wide),
                narrow,
                wide,
            }
        });
        JitterPrep {
            lo,
            hi,
            coarse,
            atoms,
            pdf,
            moments,
        }
    }

    /// The density at 16 increasing points.
    #[inline]
    fn pdf16(&self, taus: &[f64; 16], out: &mut [f64; 16], hint: &mut usize) {
        let ok = self.pdf.eval0_sorted16(taus, out, hint);
        for i in 0..16 {
            out[i] = if ok[i] { out[i].max(0.0) } else { 0.0 };
        }
    }
}

/// A table of the signal (and, with `channels > 1`, its parameter gradient) over the span
/// that the record's samples see through a jitter of reach `[lo, hi]`, with a margin.
pub(crate) fn signal_table<S: Signal + ?Sized>(
    signal: &S,
    grid: &SampleGrid,
    reach: (f64, f64),
    gradient: bool,
) -> PiecewiseCheb {
    let (lo, hi) = reach;
    let width = (hi - lo).max(grid.interval());
    let a = grid.start() + lo - 2.0 * width;
    let b = grid.time(grid.len() - 1) + hi + 2.0 * width;
    let mut cuts: Vec<f64> = signal
        .breakpoints()
        .into_iter()
        .filter(|&t| t > a && t < b)
        .collect();
    cuts.sort_by(f64::total_cmp);
    let rate = signal.rate();
    let max_w = if rate.is_finite() && rate > 0.0 {
        2.0 / rate
    } else {
        f64::INFINITY
    };
    let mut intervals = Vec::new();
    let mut start = a;
    for end in cuts.into_iter().chain(std::iter::once(b)) {
        if end > start {
            let m = if max_w.is_finite() {
                (((end - start) / max_w).ceil() as usize).max(1)
            } else {
                1
            };
            let h = (end - start) / m as f64;
            for i in 0..m {
                let s = start + i as f64 * h;
                intervals.push((s, if i + 1 == m { end } else { s + h }));
            }
        }
        start = end;
    }
    let p = signal.num_params();
    let channels = if gradient { 1 + p } else { 1 };
    PiecewiseCheb::build(&intervals, channels, TABLE_TOL, |t, out| {
        out[0] = if gradient {
            signal.value_and_gradient(t, &mut out[1..])
        } else {
            signal.value(t)
        };
    })
}

/// The signal through its table, falling back to the model outside the table's span.
pub(crate) struct SignalEval<'a, S: ?Sized> {
    pub(crate) signal: &'a S,
    pub(crate) table: &'a PiecewiseCheb,
    /// Number of gradient channels available in the table (0 if none).
    pub(crate) grad_channels: usize,
}

impl<S: Signal + ?Sized> SignalEval<'_, S> {
    #[inline]
    fn value(&self, t: f64, hint: &mut usize) -> f64 {
        match self.table.segment_near(t, hint) {
            Some(seg) => self.table.eval0(seg, t),
            None => self.signal.value(t),
        }
    }

    /// `s(t + τ_i)` at 16 increasing offsets.
    #[inline]
    fn values16(&self, t: f64, taus: &[f64; 16], out: &mut [f64; 16], hint: &mut usize) {
        let mut ts = [0.0; 16];
        for i in 0..16 {
            ts[i] = t + taus[i];
        }
        let ok = self.table.eval0_sorted16(&ts, out, hint);
        for i in 0..16 {
            if !ok[i] {
                out[i] = self.signal.value(ts[i]);
            }
        }
    }

    /// `[s, ∂s/∂θ…]` into `out` (length `1 + grad_channels`).
    #[inline]
    fn all(&self, t: f64, out: &mut [f64], hint: &mut usize) {
        match self.table.segment_near(t, hint) {
            Some(seg) => self.table.eval_all(seg, t, out),
            None => {
                out[0] = self.signal.value(t);
                self.signal.value_gradient(t, &mut out[1..]);
            }
        }
    }
}

/// A sample's quadrature rule over the jitter: the nodes `τ_i`, their weights (the density
/// folded in) and the signal `s(t + τ_i)` at them.
#[derive(Debug, Default, Clone)]
pub(crate) struct Rule {
    tau: Vec<f64>,
    w: Vec<f64>,
    s: Vec<f64>,
}

/// The signal at the shortcut's `N` nodes (in the basis' order) and its total variation over
/// them.
#[derive(Debug, Clone)]
pub(crate) struct ShortcutNodes<const N: usize> {
    s: [f64; N],
    tv: f64,
}

/// Per-thread working storage of one sample's rule.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    rule: Rule,
    steep: Vec<Steep>,
    cut: Vec<(f64, f64)>,
    ch: Vec<f64>,
    /// `[s, ∂s/∂θ…]` at one node.
    chans: Vec<f64>,
    /// `w_i e^{−(y − s_i)²/(2σ²) − max}` of the log-sum-exp, kept for the gradient.
    terms: Vec<f64>,
    /// `h e ∂s/∂θ_j` at the shortcut's 16 nodes, per parameter.
    node_gradients: Vec<f64>,
    sig_hint: usize,
    pdf_hint: usize,
}

#[derive(Debug, Clone)]
struct Steep {
    t: [f64; 18],
    v: [f64; 18],
    margin: [f64; 17],
    active: [bool; 17],
}

/// Everything needed to evaluate `log p(y)` of any sample of one record at one parameter.
pub(crate) struct SampleModel<'a, S: ?Sized> {
    pub(crate) opts: ExactMl,
    pub(crate) signal: SignalEval<'a, S>,
    pub(crate) jitter: &'a JitterPrep,
    pub(crate) breaks: &'a [f64],
    pub(crate) sigma: f64,
}

crate::simd::baseline_or_avx2! {
    /// `max_i −(y − s_i)²/(2σ²)` (`inv2 = 1/(2σ²)`), in four independent lanes so that the
    /// comparisons run as vector instructions; the maximum does not depend on their order.
    fn max_exponent(s: &[f64], y: f64, inv2: f64) -> f64 {
        let mut m = [f64::NEG_INFINITY; 4];
        let chunks = s.chunks_exact(4);
        let rest = chunks.remainder();
        for c in chunks {
            for j in 0..4 {
                let e = y - c[j];
                let v = -e * e * inv2;
                m[j] = if v > m[j] { v } else { m[j] };
            }
        }
        for &sj in rest {
            let e = y - sj;
            let v = -e * e * inv2;
            m[0] = if v > m[0] { v } else { m[0] };
        }
        m.iter()
            .fold(f64::NEG_INFINITY, |a, &b| if b > a { b } else { a })
    }
}

crate::simd::baseline_or_avx2! {
    /// The log-sum-exp's terms `w_i e^{−(y − s_i)²/(2σ²) − lmax}` (`p = (y, inv2, lmax)`)
    /// into `terms` (as long as `s`), and their sum (in four interleaved partial sums, added
    /// in a fixed order, so the same for any thread). Terms below `e^{EXP_FLOOR}` are 0.
    fn weighted_terms(s: &[f64], w: &[f64], p: (f64, f64, f64), terms: &mut [f64]) -> f64 {
        let (y, inv2, lmax) = p;
        for ((t, &si), &wi) in terms.iter_mut().zip(s).zip(w) {
            let e = y - si;
            let q = -e * e * inv2 - lmax;
            let v = wi * exp_nonpositive(q);
            *t = if q >= EXP_FLOOR { v } else { 0.0 };
        }
        let mut acc = [0.0; 4];
        let chunks = terms.chunks_exact(4);
        let rest = chunks.remainder();
        for c in chunks {
            for j in 0..4 {
                acc[j] += c[j];
            }
        }
        for (j, &r) in rest.iter().enumerate() {
            acc[j] += r;
        }
        (acc[0] + acc[1]) + (acc[2] + acc[3])
    }
}

mod cached;
mod sample;

pub(crate) use cached::SampleCache;

#[cfg(test)]
mod tests;
