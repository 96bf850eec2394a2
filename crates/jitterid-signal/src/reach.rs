//! Expectations over the jitter of the modal terms of input steps inside a sample's reach.
//!
//! A step at `c = t_j − t_k` (in jitter time, `lo < c ≤ hi`) enters the first moment of
//! sample `k` through
//!
//! * `P(c) = P(τ ≥ c)`,
//! * `A_i(c) = E[e^{p_i(τ−c)} 1{τ ≥ c}]` for each representative pole, and, for gradients,
//! * `B_i(c) = E[(τ−c) e^{p_i(τ−c)} 1{τ ≥ c}]`,
//!
//! all bounded (`|A_i| ≤ P ≤ 1` as `Re p_i < 0`) and functions of `c` alone: one evaluation of
//! `m_k` over a long record asks for the same few functions at many points. [`InReach`] answers
//! in three layers.
//!
//! 1. **Knot states.** The jitter's knots (ends of its pieces, atoms) cut the reach into
//!    intervals on which the density is analytic. The values at every knot (left limits, so an
//!    atom at `c` counts) come from one backward sweep
//!    `F(k_m) = ∫_{[k_m, k_{m+1})} … + T(k_{m+1} − k_m) F(k_{m+1})`, with the transport
//!    `T(δ): (P, A, B) ↦ (P, e^{pδ}A, e^{pδ}(B + δA))`. `|e^{pδ}| ≤ 1`, so rounding errors do not
//!    grow along the sweep.
//! 2. **Direct route.** At any `c`: quadrature from `c` to the next knot plus the transported
//!    state of that knot, so one interval of quadrature instead of the whole reach.
//! 3. **Table.** When many steps fall inside reaches, a piecewise Chebyshev interpolant of all
//!    the functions on each knot interval, built from the direct route and checked against it;
//!    a query is then `O(degree × poles)` with no density evaluation and no allocation.
//!
//! Quadrature is 16-point Gauss–Legendre on sub-intervals of width at most `6/rate`, as in the
//! jitter crate's rules, but the rate is applied only where a modal term is alive: `e^{p_i x}`
//! has fallen below `e^{−DECAY}` once `x ≥ DECAY/|Re p_i|`, and beyond that distance only the
//! mass is needed, which the density's pieces resolve unrefined. Where even that window would
//! need many sub-intervals (a fast, lightly damped pole: `|p|/|Re p|` of them), Filon's method
//! integrates the density's degree-15 interpolant against `e^{p x}` exactly. A query then costs
//! `O(16 × knots in the window)` density evaluations whatever `|p|` and the reach, instead of
//! `O(|p| × reach)`.
//!
//! [`SquaresRule`] applies the same windowed refinement to the quadrature rules of the second
//! moment `E[s(t_k + τ)²]`, and tells when they would still be too large (the response then
//! expands the square and uses [`InReach`] at sums of poles).
//!
//! Why one file of about 940 lines (a sixth of them documentation, a quarter tests): the rules
//! for the first and the second moment share the windowing, the knot sweep and the Filon
//! switch described above, and are checked against each other.

use jitterid_jitter::JitterModel;
use jitterid_numeric::chebyshev::ChebyshevBasis;
use jitterid_numeric::complex::cexp;
use jitterid_numeric::filon::FilonIntegrand;
use jitterid_numeric::gauss::{gl16, panels, subdivisions, GL_ORDER};
use num_complex::Complex64;
use std::sync::OnceLock;

/// Beyond `x = DECAY/|Re p|` a modal term `e^{p x}` is below `e^{−50} ≈ 1.9e-22` of its value
/// at the step. Dropping it there changes `A` by less than `2e-22 · P` and `B` by less than
/// `DECAY e^{−DECAY}/|Re p| ≈ 3e-20` of `B`'s natural scale `1/(e|Re p|)`: far below rounding.
/// (The underflow limit, 745, would cost 15 times the nodes for no visible difference.)
const DECAY: f64 = 50.0;

/// Interpolation points per table segment (Chebyshev points of the first kind): degree 23.
/// `e^{zx}` on `[−1, 1]` is interpolated to `1e-14` for `|z| ≲ 4.8`, so a segment spans about
/// `10/|p|` where the functions oscillate, and a whole knot interval where they are smooth.
const CHEB_N: usize = 24;

/// Accepted interpolation error of a table segment, relative to each function's scale (its
/// largest modulus over the knots and every point evaluated while building). Checked at the
/// extrema of `T_24` (both ends included), where the leading error term `a_24 T_24` peaks.
const TABLE_TOL: f64 = 1e-14;

/// Inside a knot interval, segments are built right to left, each anchored at the value at its
/// right end, which the previous segment computed. Each link adds a rounding error of a few ulps
/// of the scale; the anchor is recomputed from the knot state after this many links so that the
/// chained error stays below `~20 ε` of the scale.
const REANCHOR: usize = 8;

/// Largest number of table segments; beyond it the direct route is used.
const MAX_SEGMENTS: usize = 1 << 14;

const ZERO: Complex64 = Complex64::new(0.0, 0.0);

/// Gauss–Legendre quadrature of the density on `τ ∈ [origin + a, origin + b]`, refined for
/// `rate`: calls `f(x, w)` with `x = τ − origin` and the density folded into `w`, and returns
/// the number of density evaluations. The nodes are placed in `x` so that `x` (on which the
/// modal terms depend, at rate `|p|`) carries no rounding error of `origin`.
fn quadrature(
    jitter: &dyn JitterModel,
    origin: f64,
    a: f64,
    b: f64,
    rate: f64,
    mut f: impl FnMut(f64, f64),
) -> usize {
    if !(b > a) {
        return 0;
    }
    let (x, w) = gl16();
    let n = subdivisions(rate, b - a);
    for (mid, half) in panels(a, b, n) {
        for (xi, wi) in x.iter().zip(w) {
            let t = mid + half * xi;
            let d = jitter.pdf(origin + t);
            if d != 0.0 {
                f(t, half * wi * d);
            }
        }
    }
    n * GL_ORDER
}

/// A zone needing more Gauss–Legendre sub-intervals than this is integrated by Filon's method
/// (16 density evaluations whatever the rate); below it the plain rule is as cheap and needs
/// nothing of the density beyond the pieces' contract.
const FILON_PARTS: usize = 4;

/// Refinement zones after an origin (a step, or the start of the reach): `(x_end, rate)` with
/// increasing `x_end`; on `[previous x_end, x_end)` the poles still alive vary at most at
/// `rate` (`factor` times the largest `|p|` among them). Beyond the last `x_end` every modal
/// term has decayed below `e^{−DECAY}`.
pub(crate) fn zones(poles: &[Complex64], factor: f64) -> Vec<(f64, f64)> {
    let mut life: Vec<(f64, f64)> = poles
        .iter()
        .map(|p| {
            let x = DECAY / -p.re;
            (if x > 0.0 { x } else { f64::INFINITY }, factor * p.norm())
        })
        .collect();
    life.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(life.len());
    for (i, &(x, _)) in life.iter().enumerate() {
        if out.last().is_some_and(|z| z.0 == x) {
            continue;
        }
        let rate = life[i..].iter().map(|l| l.1).fold(0.0, f64::max);
        out.push((x, rate));
    }
    out
}

/// The knots of a jitter law: the ends of its pieces and its atoms, sorted and distinct.
#[derive(Debug, Clone)]
struct Support {
    knots: Vec<f64>,
    /// Total atom mass at each knot.
    atoms: Vec<f64>,
    /// Whether `[knots[m], knots[m + 1]]` lies inside a piece (carries density).
    dense: Vec<bool>,
}

impl Support {
    fn new(jitter: &dyn JitterModel) -> Self {
        let pieces: Vec<(f64, f64)> = jitter
            .pieces()
            .into_iter()
            .filter(|&(a, b)| a < b && a.is_finite() && b.is_finite())
            .collect();
        let atoms = jitter.atoms();
        let mut knots: Vec<f64> = pieces
            .iter()
            .flat_map(|&(a, b)| [a, b])
            .chain(atoms.iter().map(|a| a.position))
            .filter(|x| x.is_finite())
            .collect();
        knots.sort_by(f64::total_cmp);
        knots.dedup();
        let mass = knots
            .iter()
            .map(|&k| {
                atoms
                    .iter()
                    .filter(|a| a.position == k)
                    .map(|a| a.mass)
                    .sum()
            })
            .collect();
        let dense = knots
            .windows(2)
            .map(|w| {
                let mid = 0.5 * (w[0] + w[1]);
                pieces.iter().any(|&(a, b)| a <= mid && mid <= b)
            })
            .collect();
        Support {
            knots,
            atoms: mass,
            dense,
        }
    }
}

/// How [`InReach`] answers queries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Route {
    /// Build the table when about this many queries are expected and answering them directly
    /// would cost more than the table (at most half the direct cost is spent trying).
    Auto(usize),
    /// Quadrature at every query.
    #[cfg_attr(not(test), allow(dead_code))]
    Direct,
    /// Always build the table (falls back to the direct route only past [`MAX_SEGMENTS`]).
    #[cfg_attr(not(test), allow(dead_code))]
    Table,
}

/// `(P, A_i…, B_i…)` at any `c` in the reach; see the module docs.
pub(crate) struct InReach<'a> {
    jitter: &'a dyn JitterModel,
    support: Support,
    poles: Vec<Complex64>,
    with_b: bool,
    zones: Vec<(f64, f64)>,
    /// Per knot, the left limits `(P, A_i…, B_i…)` there (atoms at the knot included).
    states: Vec<Complex64>,
    table: Option<Table>,
}

impl<'a> InReach<'a> {
    /// The functions of `jitter` for `poles` (with `B` when `with_b`).
    pub(crate) fn new(
        jitter: &'a dyn JitterModel,
        poles: &[Complex64],
        with_b: bool,
        route: Route,
    ) -> Self {
        let support = Support::new(jitter);
        let mut this = InReach {
            jitter,
            poles: poles.to_vec(),
            with_b,
            zones: zones(poles, 1.0),
            states: Vec::new(),
            table: None,
            support,
        };
        this.states = this.knot_states();
        let budget = match route {
            Route::Direct => None,
            Route::Table => Some(f64::INFINITY),
            Route::Auto(queries) => {
                let direct = queries as f64 * this.direct_cost();
                let floor = ((2 * CHEB_N + 1) * GL_ORDER * this.support.dense.len()) as f64;
                (direct > 4.0 * floor).then_some(0.5 * direct)
            }
        };
        this.table = budget.and_then(|b| this.build_table(b));
        this
    }

    /// Number of values per point: `P`, then `A_i`, then `B_i` when requested.
    pub(crate) fn width(&self) -> usize {
        1 + self.poles.len() * if self.with_b { 2 } else { 1 }
    }

    /// Whether queries go through the table.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn tabulated(&self) -> bool {
        self.table.is_some()
    }

    /// The values at the start of the reach, atoms there included: `P = 1` (the rule's mass),
    /// `A_i = E[e^{p_i(τ − lo)}]`, `B_i = E[(τ − lo) e^{p_i(τ − lo)}]`.
    pub(crate) fn at_start(&self) -> &[Complex64] {
        &self.states[..self.width()]
    }

    /// The values at `c` into `out` (length [`width`](Self::width)). `c` at or below the first
    /// knot is taken just above it (a step there is inside the reach only by rounding, and the
    /// atom at the knot does not see it); `c` above the last knot is taken at it.
    pub(crate) fn eval(&self, c: f64, out: &mut [Complex64]) {
        match &self.table {
            Some(t) => t.eval(c, out),
            None => self.direct(c, out),
        }
    }

    /// [`eval`](Self::eval) by quadrature.
    pub(crate) fn direct(&self, c: f64, out: &mut [Complex64]) {
        out.fill(ZERO);
        let k = &self.support.knots;
        let nf = self.width();
        let Some(&last) = k.last() else {
            return;
        };
        if k.len() == 1 || c >= last {
            out.copy_from_slice(&self.states[(k.len() - 1) * nf..]);
            return;
        }
        let m = k.partition_point(|&x| x < c);
        if m > 0 && k[m] == c {
            out.copy_from_slice(&self.states[m * nf..(m + 1) * nf]);
            return;
        }
        let (c, m) = if m == 0 { (k[0], 1) } else { (c, m) };
        let len = k[m] - c;
        if self.support.dense[m - 1] {
            self.integrate(c, len, out);
        }
        self.transport(&self.states[m * nf..(m + 1) * nf], len, out);
    }

    /// Adds `∫_{[c, c + len)} (1, e^{p_i x}, x e^{p_i x}) p(τ) dτ` with `x = τ − c` (density
    /// only; atoms sit on knots and are added with the knot states), for `[c, c + len]` inside
    /// one knot interval. Returns the number of density evaluations.
    fn integrate(&self, c: f64, len: f64, out: &mut [Complex64]) -> usize {
        let mut count = 0;
        let mut start = 0.0;
        for &(x_end, rate) in &self.zones {
            if start >= len {
                break;
            }
            let end = x_end.min(len);
            if end > start {
                count += if subdivisions(rate, end - start) > FILON_PARTS {
                    self.filon(c, start, end, out)
                } else {
                    quadrature(self.jitter, c, start, end, rate, |x, w| {
                        self.add_node(x, w, out)
                    })
                };
                start = end;
            }
        }
        // Every modal term has decayed: the mass only, which the piece resolves unrefined.
        if start < len {
            count += quadrature(self.jitter, c, start, len, 0.0, |_, w| out[0] += w);
        }
        count
    }

    /// Adds one quadrature node `(x, w)` to `(P, A_i…, B_i…)`.
    #[inline]
    fn add_node(&self, x: f64, w: f64, out: &mut [Complex64]) {
        let np = self.poles.len();
        out[0] += w;
        for (i, p) in self.poles.iter().enumerate() {
            let e = cexp(p * x) * w;
            out[1 + i] += e;
            if self.with_b {
                out[1 + np + i] += e * x;
            }
        }
    }

    /// Adds the integrals over `x ∈ [xa, xb]` (inside one knot interval) by Filon's method: the
    /// density is replaced by its degree-15 interpolant at the 16 Gauss–Legendre nodes, which
    /// is integrated against `e^{p x}` exactly, so that the cost does not grow with
    /// `|p|·(xb − xa)` (a lightly damped fast pole would otherwise need `|p|/|Re p|`
    /// sub-intervals). The mass is the plain Gauss–Legendre sum, as everywhere.
    ///
    /// This asks a little more of the density than the pieces' contract (that 16 nodes
    /// integrate it times smooth factors): that its degree-15 interpolant on a piece be close to
    /// it. For every family of the jitter crate the difference is far below rounding where
    /// the density matters (pieces narrower than a standard deviation, polynomial pieces of
    /// degree ≤ 15 exact); the property test checks the result against fully refined rules.
    fn filon(&self, c: f64, xa: f64, xb: f64, out: &mut [Complex64]) -> usize {
        let np = self.poles.len();
        let (s, w) = gl16();
        let h = 0.5 * (xb - xa);
        let xm = xa + h;
        let mut f = [0.0; GL_ORDER];
        for (fj, sj) in f.iter_mut().zip(s) {
            *fj = self.jitter.pdf(c + (xm + h * sj));
        }
        out[0] += h * f.iter().zip(w).map(|(f, w)| f * w).sum::<f64>();
        let integrand = FilonIntegrand::new(&f);
        for (i, p) in self.poles.iter().enumerate() {
            // `∫ e^{px} p(τ) dx = h e^{p xa} ∫ e^{ω(s+1)} f(s) ds` with `|e^{ω(s+1)}| ≤ 1`, and
            // the same with `x = xa + h(s+1)` for `B`; a slow pole (`|ω| ≤ 3`) is resolved by
            // the nodes themselves, as in `quadrature`.
            let (a, m) = integrand.integrate(p * h);
            let scale = cexp(p * xa) * h;
            out[1 + i] += scale * a;
            if self.with_b {
                out[1 + np + i] += scale * (a * xa + m * h);
            }
        }
        2 * GL_ORDER
    }

    /// Adds `T(δ) src` to `out`: the values at `c` of what lies at `c + δ` and beyond.
    fn transport(&self, src: &[Complex64], delta: f64, out: &mut [Complex64]) {
        let np = self.poles.len();
        out[0] += src[0];
        for (i, p) in self.poles.iter().enumerate() {
            let e = cexp(p * delta);
            out[1 + i] += e * src[1 + i];
            if self.with_b {
                out[1 + np + i] += e * (src[1 + np + i] + delta * src[1 + i]);
            }
        }
    }

    /// The left limits at every knot, by the backward sweep.
    fn knot_states(&self) -> Vec<Complex64> {
        let k = &self.support.knots;
        let nf = self.width();
        let mut states = vec![ZERO; k.len().max(1) * nf];
        let Some(last) = k.len().checked_sub(1) else {
            return states;
        };
        let mut v = vec![ZERO; nf];
        for m in (0..=last).rev() {
            v.fill(ZERO);
            if m < last {
                if self.support.dense[m] {
                    self.integrate(k[m], k[m + 1] - k[m], &mut v);
                }
                self.transport(&states[(m + 1) * nf..(m + 2) * nf], k[m + 1] - k[m], &mut v);
            }
            let mass = self.support.atoms[m];
            v[0] += mass;
            for a in &mut v[1..=self.poles.len()] {
                *a += mass;
            }
            states[m * nf..(m + 1) * nf].copy_from_slice(&v);
        }
        states
    }

    /// Density evaluations of one direct query, averaged over `c` uniform on the reach.
    fn direct_cost(&self) -> f64 {
        let k = &self.support.knots;
        let total = match (k.first(), k.last()) {
            (Some(a), Some(b)) if b > a => b - a,
            _ => return 1.0,
        };
        let mut cost = 0.0;
        for (m, w) in k.windows(2).enumerate() {
            if self.support.dense[m] {
                let width = w[1] - w[0];
                cost += width / total * self.nodes_over(0.5 * width) as f64;
            }
        }
        cost + 1.0
    }

    /// Density evaluations of [`integrate`](Self::integrate) over a length `len`.
    fn nodes_over(&self, len: f64) -> usize {
        let mut n = 0;
        let mut start = 0.0;
        for &(x_end, rate) in &self.zones {
            if start >= len {
                break;
            }
            let end = x_end.min(len);
            if end > start {
                let k = subdivisions(rate, end - start);
                n += if k > FILON_PARTS { 2 } else { k } * GL_ORDER;
                start = end;
            }
        }
        if start < len {
            n += GL_ORDER;
        }
        n
    }

    /// The piecewise Chebyshev table, or `None` when it would cost more than `budget` density
    /// evaluations or [`MAX_SEGMENTS`] segments.
    fn build_table(&self, budget: f64) -> Option<Table> {
        let k = &self.support.knots;
        if k.len() < 2 {
            return None;
        }
        let nf = self.width();
        let n = CHEB_N;
        let basis = basis();
        let mut scale = vec![0.0f64; nf];
        for s in self.states.chunks(nf) {
            for (sc, v) in scale.iter_mut().zip(s) {
                *sc = sc.max(v.norm());
            }
        }
        let mut spent = 0usize;
        let mut table = Table::default();
        // Values at the n nodes, then at the n + 1 test points (from the right end to the left).
        let mut vals = vec![ZERO; (2 * n + 1) * nf];
        let mut coef = vec![ZERO; n * nf];
        let mut node_vals = [ZERO; CHEB_N];
        let mut anchor = vec![ZERO; nf];
        for m in 0..k.len() - 1 {
            let (k0, k1) = (k[m], k[m + 1]);
            let dense = self.support.dense[m];
            let knot = &self.states[(m + 1) * nf..(m + 2) * nf];
            anchor.copy_from_slice(knot);
            let mut links = 0;
            let mut stack = vec![(k0, k1)];
            let mut done: Vec<(f64, f64, Vec<Complex64>)> = Vec::new();
            // Invariant: the top of the stack ends where `anchor` was evaluated.
            while let Some((a, b)) = stack.pop() {
                let half = 0.5 * (b - a);
                let mid = a + half;
                for (i, v) in vals.chunks_mut(nf).enumerate() {
                    // Distance from the anchor, computed from the segment's own geometry so
                    // that it carries no rounding error of `c` (the functions vary at `|p|`).
                    let (c, delta) = match i.checked_sub(n) {
                        None => (
                            b - half * (1.0 - basis.nodes()[i]),
                            half * (1.0 - basis.nodes()[i]),
                        ),
                        Some(0) => (b, 0.0),
                        Some(l) if l == n => (a, b - a),
                        Some(l) => (
                            b - half * (1.0 - basis.extrema()[l]),
                            half * (1.0 - basis.extrema()[l]),
                        ),
                    };
                    v.fill(ZERO);
                    if dense {
                        spent += self.integrate(c, delta, v);
                    }
                    self.transport(&anchor, delta, v);
                }
                if spent as f64 > budget || table.len() + done.len() >= MAX_SEGMENTS {
                    return None;
                }
                for v in vals.chunks(nf) {
                    for (sc, x) in scale.iter_mut().zip(v) {
                        *sc = sc.max(x.norm());
                    }
                }
                for (f, co) in coef.chunks_mut(n).enumerate() {
                    for (x, v) in node_vals.iter_mut().zip(vals.chunks(nf)) {
                        *x = v[f];
                    }
                    basis.coefficients_into(&node_vals, co);
                }
                let fits = (0..=n).all(|l| {
                    let want = &vals[(n + l) * nf..(n + l + 1) * nf];
                    (0..nf).all(|f| {
                        let got = basis.value_at_extremum(&coef[f * n..(f + 1) * n], l);
                        (got - want[f]).norm() <= TABLE_TOL * scale[f]
                    })
                });
                // A segment a few ulps wide is accepted as it is: its points coincide.
                let tiny = half <= 4.0 * f64::EPSILON * (a.abs() + b.abs() + (k1 - k0));
                if fits || tiny {
                    done.push((a, b, coef.clone()));
                    anchor.copy_from_slice(&vals[2 * n * nf..]);
                    links += 1;
                    if links >= REANCHOR && a > k0 {
                        anchor.fill(ZERO);
                        if dense {
                            spent += self.integrate(a, k1 - a, &mut anchor);
                        }
                        self.transport(knot, k1 - a, &mut anchor);
                        links = 0;
                    }
                } else {
                    stack.push((a, mid));
                    stack.push((mid, b));
                }
            }
            for (a, b, c) in done.into_iter().rev() {
                table.push(a, b, &c);
            }
        }
        Some(table)
    }
}

/// The Chebyshev basis of [`CHEB_N`] points, computed once.
fn basis() -> &'static ChebyshevBasis {
    static B: OnceLock<ChebyshevBasis> = OnceLock::new();
    B.get_or_init(|| ChebyshevBasis::new(CHEB_N))
}

/// Segments `(a, b]` covering the reach, each with the Chebyshev coefficients of every function.
#[derive(Debug, Default)]
struct Table {
    ends: Vec<f64>,
    inv_half: Vec<f64>,
    /// `[segment][function][degree]`.
    coefs: Vec<Complex64>,
}

impl Table {
    fn len(&self) -> usize {
        self.ends.len()
    }

    fn push(&mut self, a: f64, b: f64, coefs: &[Complex64]) {
        self.ends.push(b);
        self.inv_half.push(2.0 / (b - a));
        self.coefs.extend_from_slice(coefs);
    }

    fn eval(&self, c: f64, out: &mut [Complex64]) {
        let s = self
            .ends
            .partition_point(|&e| e < c)
            .min(self.ends.len() - 1);
        // From the segment's right end, where fast modal terms vary most, so that `x` carries no
        // rounding error beyond that of `c`. Outside the reach only by rounding: the nearest
        // end (see `InReach::eval`).
        let x = (1.0 - (self.ends[s] - c) * self.inv_half[s]).clamp(-1.0, 1.0);
        let mut t = [0.0; CHEB_N];
        t[0] = 1.0;
        t[1] = x;
        for j in 2..CHEB_N {
            t[j] = 2.0 * x * t[j - 1] - t[j - 2];
        }
        let nf = out.len();
        let co = &self.coefs[s * nf * CHEB_N..(s + 1) * nf * CHEB_N];
        for (o, cf) in out.iter_mut().zip(co.chunks_exact(CHEB_N)) {
            let (mut re, mut im) = (0.0, 0.0);
            for (a, tj) in cf.iter().zip(&t) {
                re += a.re * tj;
                im += a.im * tj;
            }
            *o = Complex64::new(re, im);
        }
    }
}

/// Largest number of Gauss–Legendre sub-intervals per knot interval in a rule of
/// [`SquaresRule`]; beyond it the second moment is computed by expanding the square.
const SQUARES_MAX_PARTS: usize = 32;

/// Quadrature rules for `E[h(τ)]` with `h(τ) = s(t_k + τ)²` of an LTI response: `h` is analytic
/// between the steps inside the reach (the cuts), and after each cut (and after the start of the
/// reach, where the earlier steps' transients are seen from) it varies at twice the poles'
/// rates only until their modal terms decay; beyond that it is constant to `e^{−DECAY}`, and the
/// density's pieces are used unrefined.
pub(crate) struct SquaresRule<'a> {
    jitter: &'a dyn JitterModel,
    support: Support,
    zones: Vec<(f64, f64)>,
}

impl<'a> SquaresRule<'a> {
    /// Rules for a response with these poles under `jitter`.
    pub(crate) fn new(jitter: &'a dyn JitterModel, poles: &[Complex64]) -> Self {
        SquaresRule {
            jitter,
            support: Support::new(jitter),
            zones: zones(poles, 2.0),
        }
    }

    /// Whether the rules stay small: at most [`SQUARES_MAX_PARTS`] sub-intervals on any knot
    /// interval, seen from a step at its start (the worst place).
    pub(crate) fn affordable(&self) -> bool {
        self.support.knots.windows(2).all(|w| {
            let len = w[1] - w[0];
            let mut start = 0.0;
            let mut total = 0;
            for &(x_end, rate) in &self.zones {
                if start >= len {
                    break;
                }
                let end = x_end.min(len);
                if end > start {
                    total += subdivisions(rate, end - start);
                    start = end;
                }
            }
            total <= SQUARES_MAX_PARTS
        })
    }

    /// The rule for the sorted `cuts` (in jitter time, inside the reach) into `nodes` and
    /// `weights` (cleared first).
    pub(crate) fn build(&self, cuts: &[f64], nodes: &mut Vec<f64>, weights: &mut Vec<f64>) {
        nodes.clear();
        weights.clear();
        let k = &self.support.knots;
        let mut push = |t: f64, w: f64| {
            nodes.push(t);
            weights.push(w);
        };
        let mut next = 0;
        for (m, w) in k.windows(2).enumerate() {
            if !self.support.dense[m] {
                continue;
            }
            let (k0, k1) = (w[0], w[1]);
            let mut a = k0;
            loop {
                while next < cuts.len() && cuts[next] <= a {
                    next += 1;
                }
                let origin = if next > 0 {
                    cuts[next - 1].max(k[0])
                } else {
                    k[0]
                };
                let b = match cuts.get(next) {
                    Some(&c) if c < k1 => c,
                    _ => k1,
                };
                let mut start = a;
                for &(x_end, rate) in &self.zones {
                    if start >= b {
                        break;
                    }
                    let end = (origin + x_end).min(b);
                    if end > start {
                        quadrature(self.jitter, 0.0, start, end, rate, &mut push);
                        start = end;
                    }
                }
                if start < b {
                    quadrature(self.jitter, 0.0, start, b, 0.0, &mut push);
                }
                if b >= k1 {
                    break;
                }
                a = b;
            }
        }
        for (&t, &mass) in k.iter().zip(&self.support.atoms) {
            if mass != 0.0 {
                push(t, mass);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid_jitter::{ExponentialDelay, Gaussian, Laplace, Shifted, TwoPoint, UniformSum};
    use proptest::prelude::*;

    /// The reference: the jitter crate's rule over `τ ≥ c`, refined at the fastest pole's rate
    /// over the whole rest of the reach (the route used before the in-reach functions existed).
    /// Also the expectations of the moduli of the integrands (`P`, `E[|e^{p x}|]`,
    /// `E[|x e^{p x}|]` over `τ ≥ c`) into `l1`: the scale of the rounding errors of any
    /// quadrature of these functions.
    fn reference(
        j: &dyn JitterModel,
        poles: &[Complex64],
        c: f64,
        out: &mut [Complex64],
        l1: &mut [f64],
    ) {
        let np = poles.len();
        let rate = poles.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let rule = j.rule_from(c, &[], rate);
        out.fill(ZERO);
        l1.fill(0.0);
        for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
            let x = tau - c;
            out[0] += w;
            l1[0] += w;
            for (i, p) in poles.iter().enumerate() {
                let e = (p * x).exp() * w;
                out[1 + i] += e;
                out[1 + np + i] += e * x;
                l1[1 + i] += e.norm();
                l1[1 + np + i] += e.norm() * x;
            }
        }
    }

    fn jitter_strategy() -> impl Strategy<Value = Box<dyn JitterModel>> {
        let scale = -3.0f64..1.0; // log10 of the width parameter
        prop_oneof![
            (0u32..=50, scale.clone()).prop_map(|(n, s)| Box::new(
                UniformSum::new(n, 10f64.powf(s)).unwrap()
            ) as Box<dyn JitterModel>),
            scale
                .clone()
                .prop_map(|s| Box::new(Gaussian::new(10f64.powf(s)).unwrap()) as _),
            scale
                .clone()
                .prop_map(|s| Box::new(Laplace::new(10f64.powf(s)).unwrap()) as _),
            scale
                .clone()
                .prop_map(|s| Box::new(TwoPoint::new(10f64.powf(s)).unwrap()) as _),
            scale
                .clone()
                .prop_map(|s| Box::new(ExponentialDelay::new(10f64.powf(s)).unwrap()) as _),
            (0u32..=8, scale, -2.0f64..2.0).prop_map(|(n, s, o)| {
                let inner = UniformSum::new(n, 10f64.powf(s)).unwrap();
                Box::new(Shifted::new(inner, o * 10f64.powf(s)).unwrap()) as _
            }),
        ]
    }

    /// Up to three representative poles, `|p| × reach` from 1e-3 to 3e3 and damping ratios
    /// from 0.01 to 1 (the reference rule refines at most 4096 × 6 / |p| per piece, so the
    /// modulus stays where it is exact).
    fn poles_strategy() -> impl Strategy<Value = Vec<(f64, f64)>> {
        prop::collection::vec((-3.0f64..3.5, -2.0f64..0.0, any::<bool>()), 1..=3).prop_map(|v| {
            v.into_iter()
                .map(|(m, z, real)| {
                    let (modulus, zeta) = (10f64.powf(m), 10f64.powf(z));
                    if real {
                        (modulus, 1.0)
                    } else {
                        (modulus, zeta)
                    }
                })
                .collect()
        })
    }

    fn poles_for(j: &dyn JitterModel, spec: &[(f64, f64)]) -> Vec<Complex64> {
        let (lo, hi) = j.reach();
        spec.iter()
            .map(|&(m, zeta)| {
                let modulus = m / (hi - lo);
                Complex64::new(
                    -zeta * modulus,
                    modulus * (1.0 - zeta * zeta).max(0.0).sqrt(),
                )
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 64,
            failure_persistence: None,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x0072_6561_6368),
            ..ProptestConfig::default()
        })]

        /// The table against the direct route, and both against the jitter crate's full rule,
        /// at random points, at every knot, just above each knot, and at the end of the reach.
        ///
        /// Errors are measured against each function's scale `S_f`: the largest expectation of
        /// the modulus of its integrand (`P`, `E[|e^{p x}|]`, `E[|x e^{p x}|]` over `τ ≥ c`)
        /// over the knots, the points checked and points log-spaced on both sides of every knot
        /// (where fast poles' boundary layers peak). Every quadrature of `f` rounds at about
        /// `ε S_f`, and for a lightly damped pole `S_f` exceeds `max |f|` by about `1/ζ`
        /// (cancellation of the oscillation), so no route can promise better.
        ///
        /// Table against direct route: `1e-13 S_f`. The table is built to `1e-14` of the
        /// largest `|f|` at the points where its leading error term peaks (both ends of every
        /// segment included); both routes evaluate the functions of the distance to the next
        /// knot without rounding `c` into it, and are sums of at most a few thousand terms
        /// (rounding `≲ 1e-15 S_f`). `1e-13` leaves an order of magnitude while catching any
        /// wrong segment, knot or atom convention, which is off by `1e-4` or more.
        ///
        /// Against the full rule: the same, plus that rule's own rounding. Its nodes are
        /// absolute times `τ`, so `x = τ − c` carries an error up to `ε·R` (`R` the largest
        /// `|τ|` of the reach), which `e^{p x}` turns into `ε·R·|p|` relative; the
        /// allowance is `8 ε R |p| S_f` on top of `1e-13 S_f`.
        #[test]
        fn table_and_direct_route_equal_full_quadrature(
            j in jitter_strategy(),
            spec in poles_strategy(),
            with_b in any::<bool>(),
            us in prop::collection::vec(0.0f64..=1.0, 24),
        ) {
            let j = j.as_ref();
            let poles = poles_for(j, &spec);
            let table = InReach::new(j, &poles, with_b, Route::Table);
            prop_assert!(table.tabulated(), "{j:?} {poles:?}");
            let direct = InReach::new(j, &poles, with_b, Route::Direct);
            let (lo, hi) = j.reach();
            let mut points: Vec<f64> = us.iter().map(|u| lo + u * (hi - lo)).collect();
            let mut probes = Vec::new();
            let knots = &table.support.knots;
            for (i, &k) in knots.iter().enumerate() {
                points.push(k);
                points.push(k + (hi - lo) * 1e-9);
                // Probes near at most 8 knots: the boundary layers are alike at every knot.
                if i % knots.len().div_ceil(8) == 0 || i + 1 == knots.len() {
                    for e in 0..24 {
                        let d = (hi - lo) * 10f64.powf(-0.5 * f64::from(e));
                        probes.extend([k - d, k + d]);
                    }
                }
            }
            points.retain(|&c| c > lo && c <= hi);
            probes.retain(|&c| c > lo && c <= hi);
            let np = poles.len();
            let nf = table.width();
            let mut want = vec![ZERO; 1 + 2 * np];
            let mut l1 = vec![0.0; 1 + 2 * np];
            let mut scale = vec![0.0f64; nf];
            for &c in probes.iter().chain(&points).chain([&lo]) {
                reference(j, &poles, c, &mut want, &mut l1);
                for (s, m) in scale.iter_mut().zip(&l1) {
                    *s = s.max(*m);
                }
            }
            let fastest = poles.iter().map(|p| p.norm()).fold(0.0, f64::max);
            let floor = 8.0 * f64::EPSILON * lo.abs().max(hi.abs()) * fastest;
            let mut got_t = vec![ZERO; nf];
            let mut got_d = vec![ZERO; nf];
            for &c in &points {
                reference(j, &poles, c, &mut want, &mut l1);
                table.eval(c, &mut got_t);
                direct.eval(c, &mut got_d);
                for f in 0..nf {
                    let tol = 1e-13 * scale[f];
                    prop_assert!((got_t[f] - got_d[f]).norm() <= tol,
                        "table, f {f} at c = {c:e}: {} vs {} (scale {:e}); {j:?} {poles:?}",
                        got_t[f], got_d[f], scale[f]);
                    prop_assert!((got_d[f] - want[f]).norm() <= tol + floor * scale[f],
                        "direct, f {f} at c = {c:e}: {} vs {} (scale {:e}); {j:?} {poles:?}",
                        got_d[f], want[f], scale[f]);
                }
            }
            // The start of the reach, atoms there included, is the full expectation.
            reference(j, &poles, lo, &mut want, &mut l1);
            for f in 0..nf {
                prop_assert!(
                    (table.at_start()[f] - want[f]).norm() <= (1e-13 + floor) * scale[f]
                );
            }
        }
    }

    #[test]
    fn a_fast_pole_costs_nodes_near_the_step_only() {
        // |p| × reach = 1e8: the full rule would refine the whole reach (capped at 4096 × 16
        // nodes per piece); the direct route needs the first DECAY/|p| only.
        let j = UniformSum::new(54, 0.5).unwrap();
        let poles = [Complex64::new(-1e8, 0.0), Complex64::new(-0.5, 0.0)];
        let r = InReach::new(&j, &poles, true, Route::Direct);
        let mut out = vec![ZERO; r.width()];
        let n = r.integrate(0.001, 0.009, &mut out);
        assert!(n <= 16 * 12, "{n} density evaluations");
        assert!(r.direct_cost() < 200.0, "{}", r.direct_cost());
    }

    #[test]
    fn squares_rule_integrates_like_the_full_rule() {
        // E[h] for h = (1 + e^{p(τ−c)} 1{τ≥c})², against the full refined rule with the cut.
        let p = Complex64::new(-3.0, 40.0);
        for j in [
            Box::new(UniformSum::new(3, 0.7).unwrap()) as Box<dyn JitterModel>,
            Box::new(Gaussian::new(0.2).unwrap()),
            Box::new(Shifted::new(TwoPoint::new(0.3).unwrap(), 0.1).unwrap()),
        ] {
            let rule = SquaresRule::new(j.as_ref(), &[p]);
            let (mut nodes, mut weights) = (Vec::new(), Vec::new());
            let c = 0.05;
            rule.build(&[c], &mut nodes, &mut weights);
            let h = |t: f64| {
                let s = 1.0 + if t >= c { (p * (t - c)).exp().re } else { 0.0 };
                s * s
            };
            let got: f64 = nodes.iter().zip(&weights).map(|(&t, &w)| w * h(t)).sum();
            let want = j.rule(&[c], 2.0 * p.norm()).expect(h);
            assert!(
                (got - want).abs() < 1e-14 * want.abs(),
                "{}: {got} vs {want}",
                j.name()
            );
        }
    }
}
