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
pub const MAX_SAMPLE_NODES: usize = 1 << 18;

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

/// `E[T_j((2τ − lo − hi)/(hi − lo))]` for `j < 16` and `j < 32`.
#[derive(Debug, Clone)]
struct Moments {
    narrow: [f64; CHEB_POINTS],
    wide: [f64; 32],
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
            Moments {
                narrow: chebyshev_moments(&jitter.rule(&[], 0.0), lo, hi),
                wide: chebyshev_moments(&jitter.rule(&[], wide_rate), lo, hi),
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

/// Per-thread working storage of one sample's rule.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    tau: Vec<f64>,
    w: Vec<f64>,
    s: Vec<f64>,
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

impl<S: Signal + ?Sized> SampleModel<'_, S> {
    /// `log p(y)` of a sample requested at `t`, and, when `grad` is given (length
    /// `grad_channels + 1`), `∂ log p/∂θ_signal` followed by `∂ log p/∂σ_v`.
    pub(crate) fn log_p(
        &self,
        t: f64,
        y: f64,
        grad: Option<&mut [f64]>,
        scratch: &mut Scratch,
    ) -> Result<f64, RuleTooLarge> {
        let jp = self.jitter;
        // Segment searches start afresh for every sample: a node on the boundary of two table
        // segments then takes the same segment whichever samples this thread saw before, so a
        // sample's value does not depend on how samples are shared between threads.
        scratch.sig_hint = 0;
        scratch.pdf_hint = 0;
        let local = local_breaks(self.breaks, t, jp.lo, jp.hi);
        if self.opts.shortcut && local.is_empty() {
            if let Some(mu) = &jp.moments {
                let len = grad.as_deref().map(|g| g.len());
                let narrow = tables16();
                // The value and the number of points that gave it.
                let v = match self.shortcut(t, y, narrow, &mu.narrow, SHORTCUT_TV, len, scratch) {
                    Err(tv) if tv <= WIDE_SHORTCUT_TV => {
                        let wide = tables32();
                        self.shortcut(t, y, wide, &mu.wide, WIDE_SHORTCUT_TV, len, scratch)
                            .map(|v| (v, 32))
                    }
                    r => r.map(|v| (v, CHEB_POINTS)),
                };
                if let Ok((v, _points)) = v {
                    #[cfg(test)]
                    tests::note_shortcut(_points);
                    if let Some(g) = grad {
                        g.copy_from_slice(&scratch.ch[..g.len()]);
                    }
                    return Ok(v);
                }
            }
        }
        self.build_rule(t, y, &local, scratch)?;
        Ok(self.sum(t, y, grad, scratch))
    }

    /// The range of `s(t + τ)` over the coarse nodes of the jitter (for the Fisher
    /// information's grid in `y`).
    pub(crate) fn signal_range(&self, t: f64) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut hint = 0;
        for c in &self.jitter.coarse {
            for &tau in c.nodes.iter().chain([c.a, c.b].iter()) {
                let s = self.signal.value(t + tau, &mut hint);
                lo = lo.min(s);
                hi = hi.max(s);
            }
        }
        for a in &self.jitter.atoms {
            let s = self.signal.value(t + a.position, &mut hint);
            lo = lo.min(s);
            hi = hi.max(s);
        }
        (lo, hi)
    }

    /// The shortcut on `N` Chebyshev points over the reach (step 5 of the module docs): the
    /// value, or `Err(tv)` with the signal's total variation over the points when the
    /// interpolant of the Gaussian factor is not converged ([`ExactMl::shortcut_tolerance`];
    /// `tv` infinite when it
    /// exceeds `max_tv` and the transform was not taken).
    #[allow(clippy::too_many_arguments)]
    fn shortcut<const N: usize>(
        &self,
        t: f64,
        y: f64,
        tables: &ChebTables<N>,
        mu: &[f64; N],
        max_tv: f64,
        grad_len: Option<usize>,
        scratch: &mut Scratch,
    ) -> Result<f64, f64> {
        let jp = self.jitter;
        let nodes = tables.basis().nodes();
        let (mid, half) = (0.5 * (jp.lo + jp.hi), 0.5 * (jp.hi - jp.lo));
        let sigma = self.sigma;
        // The Chebyshev nodes in increasing order (the basis stores them decreasing).
        let mut taus = [0.0; N];
        for i in 0..N {
            taus[i] = mid + half * nodes[N - 1 - i];
        }
        let mut sv = [0.0; N];
        for (tc, sc) in taus.chunks_exact(16).zip(sv.chunks_exact_mut(16)) {
            // N is 16 or 32, so every chunk has 16 points (the rust-version predates
            // `as_chunks`).
            let (Ok(tc), Ok(sc)) = (<&[f64; 16]>::try_from(tc), <&mut [f64; 16]>::try_from(sc))
            else {
                return Err(f64::INFINITY);
            };
            self.signal.values16(t, tc, sc, &mut scratch.sig_hint);
        }
        let tv: f64 = sv.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
        if !(tv <= max_tv * sigma) {
            return Err(f64::INFINITY);
        }
        // Back to the basis' order.
        let mut s = [0.0; N];
        for i in 0..N {
            s[i] = sv[N - 1 - i];
        }
        let inv2 = 0.5 / (sigma * sigma);
        let mut e = [0.0; N];
        let mut d0 = f64::INFINITY;
        for (ei, si) in e.iter_mut().zip(&s) {
            *ei = y - si;
            d0 = d0.min(*ei * *ei);
        }
        let mut h = [0.0; N];
        for (hi, ei) in h.iter_mut().zip(&e) {
            let q = -(ei * ei - d0) * inv2;
            let v = exp_nonpositive(q);
            *hi = if q >= EXP_FLOOR { v } else { 0.0 };
        }
        let c = tables.coefficients(&h);
        let total: f64 = c.iter().zip(mu).map(|(c, m)| c * m).sum();
        if !(total > 0.0) || c[N - 2].abs() + c[N - 1].abs() > self.opts.shortcut_tolerance * total
        {
            return Err(tv / sigma);
        }
        let log_p = -d0 * inv2 + total.ln() - sigma.ln() - HALF_LN_2PI;
        if let Some(len) = grad_len {
            let ns = len - 1;
            scratch.ch.clear();
            scratch.ch.resize(len, 0.0);
            let dot = |v: &[f64; N]| -> f64 {
                tables
                    .coefficients(v)
                    .iter()
                    .zip(mu)
                    .map(|(c, m)| c * m)
                    .sum::<f64>()
                    / total
            };
            if ns > 0 {
                let mut chans = std::mem::take(&mut scratch.chans);
                chans.resize(1 + self.signal.grad_channels, 0.0);
                // `h e ∂s/∂θ_j` at the nodes, parameter-major.
                let mut g = std::mem::take(&mut scratch.node_gradients);
                g.clear();
                g.resize(ns * N, 0.0);
                for (i, &x) in nodes.iter().enumerate() {
                    self.signal
                        .all(t + mid + half * x, &mut chans, &mut scratch.sig_hint);
                    for j in 0..ns {
                        g[j * N + i] = h[i] * e[i] * chans[1 + j];
                    }
                }
                for j in 0..ns {
                    let mut v = [0.0; N];
                    v.copy_from_slice(&g[j * N..(j + 1) * N]);
                    scratch.ch[j] = dot(&v) / (sigma * sigma);
                }
                scratch.chans = chans;
                scratch.node_gradients = g;
            }
            let mut q = [0.0; N];
            for i in 0..N {
                q[i] = h[i] * e[i] * e[i];
            }
            scratch.ch[ns] = dot(&q) / (sigma * sigma * sigma) - 1.0 / sigma;
        }
        Ok(log_p)
    }

    /// Pushes a 16-point rule on `[a, b]` (density from the table) with the signal values.
    fn push_gl(&self, t: f64, a: f64, b: f64, scratch: &mut Scratch) {
        let (x, w) = gl16();
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        let mut taus = [0.0; 16];
        for i in 0..16 {
            taus[i] = mid + half * x[i];
        }
        let mut p = [0.0; 16];
        self.jitter.pdf16(&taus, &mut p, &mut scratch.pdf_hint);
        let mut sv = [0.0; 16];
        self.signal
            .values16(t, &taus, &mut sv, &mut scratch.sig_hint);
        for i in 0..16 {
            let wi = half * w[i] * p[i];
            if wi > 0.0 {
                scratch.tau.push(taus[i]);
                scratch.w.push(wi);
                scratch.s.push(sv[i]);
            }
        }
    }

    /// One coarse interval `[a, b]` with its 16 nodes (and weights, when shared): either its
    /// rule is pushed (the signal moves little), or it is kept for refinement. Returns whether
    /// a node or gap comes within the window of `y`.
    fn coarse(
        &self,
        t: f64,
        y: f64,
        (a, b): (f64, f64),
        nodes: &[f64; 16],
        weights: Option<&[f64; 16]>,
        scratch: &mut Scratch,
    ) -> bool {
        let res = self.opts.resolution * self.sigma;
        let reach = self.opts.window * self.sigma;
        let mut sv = [0.0; 16];
        self.signal
            .values16(t, nodes, &mut sv, &mut scratch.sig_hint);
        let mut pt = [0.0; 18];
        let mut pv = [0.0; 18];
        pt[1..17].copy_from_slice(nodes);
        pv[1..17].copy_from_slice(&sv);
        // The ends, by linear extrapolation from the outer nodes (within 0.6% of the width).
        pt[0] = a;
        pt[17] = b;
        pv[0] = pv[1] + (pv[1] - pv[2]) * (pt[1] - a) / (pt[2] - pt[1]);
        pv[17] = pv[16] + (pv[16] - pv[15]) * (b - pt[16]) / (pt[16] - pt[15]);
        let tv: f64 = pv.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
        if tv <= res {
            let mut near = false;
            let mut own = [0.0; 16];
            let ws = match weights {
                Some(ws) => ws,
                None => {
                    let (_, gw) = gl16();
                    let half = 0.5 * (b - a);
                    self.jitter.pdf16(nodes, &mut own, &mut scratch.pdf_hint);
                    for i in 0..16 {
                        own[i] *= half * gw[i];
                    }
                    &own
                }
            };
            for i in 0..16 {
                if ws[i] > 0.0 {
                    scratch.tau.push(nodes[i]);
                    scratch.w.push(ws[i]);
                    scratch.s.push(sv[i]);
                    near |= (y - sv[i]).abs() <= reach;
                }
            }
            return near;
        }
        // Steep: margins for the curvature between points, and activity.
        let mut slope = [0.0; 17];
        for j in 0..17 {
            let dt = pt[j + 1] - pt[j];
            slope[j] = if dt > 0.0 {
                (pv[j + 1] - pv[j]) / dt
            } else {
                0.0
            };
        }
        let mut curv = [0.0; 18];
        for j in 1..17 {
            let dt = pt[j + 1] - pt[j - 1];
            curv[j] = if dt > 0.0 {
                (2.0 * (slope[j] - slope[j - 1]) / dt).abs()
            } else {
                0.0
            };
        }
        curv[0] = curv[1];
        curv[17] = curv[16];
        let mut st = Steep {
            t: pt,
            v: pv,
            margin: [0.0; 17],
            active: [false; 17],
        };
        let mut near = false;
        for j in 0..17 {
            let dt = pt[j + 1] - pt[j];
            st.margin[j] = curv[j].max(curv[j + 1]) * dt * dt / 4.0;
            let (lo, hi) = (pv[j].min(pv[j + 1]), pv[j].max(pv[j + 1]));
            st.active[j] = y >= lo - st.margin[j] - reach && y <= hi + st.margin[j] + reach;
            near |= st.active[j];
        }
        scratch.steep.push(st);
        near
    }

    fn build_rule(
        &self,
        t: f64,
        y: f64,
        local: &[f64],
        scratch: &mut Scratch,
    ) -> Result<(), RuleTooLarge> {
        let jp = self.jitter;
        let res = self.opts.resolution * self.sigma;
        scratch.tau.clear();
        scratch.w.clear();
        scratch.s.clear();
        scratch.steep.clear();
        let mut near = false;
        if local.is_empty() {
            for c in &jp.coarse {
                near |= self.coarse(t, y, (c.a, c.b), &c.nodes, Some(&c.weights), scratch);
            }
        } else {
            let (x, _) = gl16();
            let mut cut = std::mem::take(&mut scratch.cut);
            cut.clear();
            for c in &jp.coarse {
                let mut a = c.a;
                for &bk in local.iter().filter(|&&bk| bk > c.a && bk < c.b) {
                    cut.push((a, bk));
                    a = bk;
                }
                cut.push((a, c.b));
            }
            for &(a, b) in &cut {
                let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
                let mut nodes = [0.0; 16];
                for i in 0..16 {
                    nodes[i] = mid + half * x[i];
                }
                near |= self.coarse(t, y, (a, b), &nodes, None, scratch);
            }
            scratch.cut = cut;
        }
        // Refine the steep intervals.
        let steep = std::mem::take(&mut scratch.steep);
        for st in &steep {
            self.refine(t, st, !near, res, scratch);
            if scratch.tau.len() > MAX_SAMPLE_NODES {
                scratch.steep = steep;
                return Err(RuleTooLarge);
            }
        }
        scratch.steep = steep;
        for atom in &jp.atoms {
            scratch.tau.push(atom.position);
            scratch.w.push(atom.mass);
            let s = self.signal.value(t + atom.position, &mut scratch.sig_hint);
            scratch.s.push(s);
        }
        Ok(())
    }

    /// Splits a steep interval into sub-intervals of signal range about `res` and pushes the
    /// rules (see the module docs). `all_active` refines everything.
    fn refine(&self, t: f64, st: &Steep, all_active: bool, res: f64, scratch: &mut Scratch) {
        let mut tv = [0.0; 17];
        let mut cum = [0.0; 18];
        for j in 0..17 {
            tv[j] = (st.v[j + 1] - st.v[j]).abs() + 2.0 * st.margin[j];
            cum[j + 1] = cum[j] + tv[j];
        }
        let total = cum[17];
        let m = ((total / res).ceil() as usize).clamp(1, MAX_SUBDIVISIONS);
        // Boundary i of m, by inverting the piecewise-linear cumulative variation.
        let boundary = |i: usize, gap: &mut usize| -> f64 {
            if i == 0 {
                return st.t[0];
            }
            if i == m {
                *gap = 16;
                return st.t[17];
            }
            let c = total * i as f64 / m as f64;
            while *gap < 16 && cum[*gap + 1] < c {
                *gap += 1;
            }
            let j = *gap;
            let frac = if tv[j] > 0.0 {
                ((c - cum[j]) / tv[j]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            st.t[j] + frac * (st.t[j + 1] - st.t[j])
        };
        let mut gap = 0usize;
        let mut a = boundary(0, &mut gap);
        let mut run_start: Option<f64> = None;
        for i in 0..m {
            let first_gap = gap;
            let b = boundary(i + 1, &mut gap);
            // [a, b] overlaps the gaps first_gap..=gap.
            let active = all_active || st.active[first_gap..=gap].iter().any(|&x| x);
            if active {
                if let Some(r) = run_start.take() {
                    self.push_gl(t, r, a, scratch);
                }
                self.push_gl(t, a, b, scratch);
            } else if run_start.is_none() {
                run_start = Some(a);
            }
            a = b;
        }
        if let Some(r) = run_start {
            self.push_gl(t, r, a, scratch);
        }
    }

    /// Log-sum-exp of the collected rule, with the gradient.
    fn sum(&self, t: f64, y: f64, grad: Option<&mut [f64]>, scratch: &mut Scratch) -> f64 {
        let sigma = self.sigma;
        let inv2 = 0.5 / (sigma * sigma);
        let lmax = max_exponent(&scratch.s, y, inv2);
        if !lmax.is_finite() {
            if let Some(g) = grad {
                g.fill(f64::NAN);
            }
            return f64::NEG_INFINITY;
        }
        scratch.terms.clear();
        scratch.terms.resize(scratch.s.len(), 0.0);
        let mut total = weighted_terms(&scratch.s, &scratch.w, (y, inv2, lmax), &mut scratch.terms);
        let mut shift = lmax;
        let mut use_logs = false;
        if !(total > 1e-280) {
            // The largest exponent sits on negligible weights: include the weights' logs.
            use_logs = true;
            shift = f64::NEG_INFINITY;
            for (&s, &w) in scratch.s.iter().zip(&scratch.w) {
                let e = y - s;
                shift = shift.max(w.ln() - e * e * inv2);
            }
            total = 0.0;
            for (&s, &w) in scratch.s.iter().zip(&scratch.w) {
                let e = y - s;
                total += (w.ln() - e * e * inv2 - shift).exp();
            }
        }
        let log_p = shift + total.ln() - sigma.ln() - HALF_LN_2PI;
        if let Some(g) = grad {
            let ns = g.len() - 1;
            g.fill(0.0);
            let mut chans = std::mem::take(&mut scratch.chans);
            chans.resize(1 + self.signal.grad_channels, 0.0);
            for i in 0..scratch.s.len() {
                let e = y - scratch.s[i];
                let r = if use_logs {
                    (scratch.w[i].ln() - e * e * inv2 - shift).exp() / total
                } else {
                    scratch.terms[i] / total
                };
                if r < 1e-300 {
                    continue;
                }
                g[ns] += r * e * e;
                if ns > 0 {
                    self.signal
                        .all(t + scratch.tau[i], &mut chans, &mut scratch.sig_hint);
                    for j in 0..ns {
                        g[j] += r * e * chans[1 + j];
                    }
                }
            }
            scratch.chans = chans;
            let s2 = sigma * sigma;
            for gj in g[..ns].iter_mut() {
                *gj /= s2;
            }
            g[ns] = g[ns] / (s2 * sigma) - 1.0 / sigma;
        }
        log_p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid_estimate::{ModelStructure, Record};
    use jitterid_jitter::{Gaussian, TwoPoint, UniformSum};
    use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, Zpk};
    use rand::rngs::StdRng;
    use rand::SeedableRng;
    use std::cell::Cell;

    thread_local! {
        /// Samples that took the 16- and the 32-point shortcut on this thread.
        static TAKEN: Cell<[usize; 2]> = const { Cell::new([0; 2]) };
    }

    pub(super) fn note_shortcut(points: usize) {
        TAKEN.with(|c| {
            let mut v = c.get();
            v[usize::from(points == 32)] += 1;
            c.set(v);
        });
    }

    #[test]
    fn wide_moments_agree_with_a_rule_of_twice_the_panels() {
        // The 32 moments from the rule of WIDE_MOMENT_PANELS panels against one of twice as
        // many, and their first 16 against the narrow moments (a rule without panels).
        let jitters: Vec<Box<dyn JitterModel>> = vec![
            Box::new(UniformSum::new(0, 0.5).unwrap()),
            Box::new(UniformSum::new(1, 0.5).unwrap()),
            Box::new(UniformSum::new(3, 0.7).unwrap()),
            Box::new(UniformSum::new(9, 1.2).unwrap()),
            Box::new(Gaussian::new(0.17).unwrap()),
            Box::new(TwoPoint::new(0.3).unwrap()),
        ];
        for j in &jitters {
            let (lo, hi) = j.reach();
            let rate = WIDE_MOMENT_PANELS * MAX_RATE_WIDTH / (hi - lo);
            let wide: [f64; 32] = chebyshev_moments(&j.rule(&[], rate), lo, hi);
            let finer: [f64; 32] = chebyshev_moments(&j.rule(&[], 2.0 * rate), lo, hi);
            let narrow: [f64; CHEB_POINTS] = chebyshev_moments(&j.rule(&[], 0.0), lo, hi);
            for k in 0..32 {
                assert!(
                    (wide[k] - finer[k]).abs() <= 1e-14,
                    "{j:?}: μ_{k} {} vs {}",
                    wide[k],
                    finer[k]
                );
            }
            for k in 0..CHEB_POINTS {
                assert!(
                    (wide[k] - narrow[k]).abs() <= 1e-14,
                    "{j:?}: μ_{k} {} vs {}",
                    wide[k],
                    narrow[k]
                );
            }
        }
    }

    #[test]
    fn both_shortcuts_agree_with_the_general_rule() {
        // The Table 1 system: long flat stretches (the 16-point shortcut), the tails of its
        // step responses (the 32-point one) and steps inside the reach (the general rule).
        let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).unwrap();
        let n = 200;
        let grid = jitterid_signal::SampleGrid::new(0.0, 1.0, n).unwrap();
        let mut rng = StdRng::seed_from_u64(11);
        let u = RandomBinary::paper()
            .generate(0.0, n as f64 + 1.0, &mut rng)
            .unwrap();
        let signal = LtiResponse::new(g, u);
        check(UniformSum::new(0, 0.5).unwrap(), &signal, grid, &mut rng);
        check(UniformSum::new(3, 0.6).unwrap(), &signal, grid, &mut rng);
        check(Gaussian::new(0.17).unwrap(), &signal, grid, &mut rng);
    }

    /// The per-sample `log p` with and without the shortcuts, which must agree, and the
    /// shortcuts must both have been taken.
    fn check<J: JitterModel + Clone>(
        j: J,
        signal: &LtiResponse<Zpk>,
        grid: jitterid_signal::SampleGrid,
        rng: &mut StdRng,
    ) {
        let sigma = 0.01;
        let serial = |shortcut| ExactMl {
            shortcut,
            parallel: false,
            ..ExactMl::default()
        };
        let data = simulate(signal, &j, &grid, sigma, rng).unwrap();
        let record = Record::new(grid, data.y).unwrap();
        let structure = ModelStructure::oe(signal.clone(), j)
            .with_noise_std(sigma)
            .unwrap();
        TAKEN.with(|c| c.set([0; 2]));
        let fast = serial(true)
            .log_likelihoods(&structure, &record, sigma)
            .unwrap();
        let taken = TAKEN.with(Cell::get);
        let general = serial(false)
            .log_likelihoods(&structure, &record, sigma)
            .unwrap();
        let name = format!("{:?}", structure.jitter);
        // Both are accurate to about 1e-13 of p(y_k).
        for (k, (a, b)) in fast.iter().zip(&general).enumerate() {
            assert!((a - b).abs() <= 1e-11, "{name}, sample {k}: {a} vs {b}");
        }
        assert!(
            taken[0] > 0 && taken[1] > 0,
            "{name}: shortcuts taken (16, 32 points): {taken:?}"
        );
    }
}
