//! Chebyshev interpolation: the basis of any degree ([`ChebyshevBasis`]), Clenshaw evaluation
//! ([`clenshaw`]), conversion to monomials ([`to_monomial`]), and adaptive piecewise tables
//! of several real channels ([`PiecewiseChebyshev`]).
//!
//! Interpolation is at the `n` Chebyshev points of the first kind `x_i = cos(π(i + ½)/n)`;
//! the coefficients of `Σ c_j T_j(x)` are a discrete cosine transform of the values.

use num_complex::Complex64;
use std::f64::consts::PI;
use std::ops::{Add, Mul, Sub};

/// A value that Chebyshev coefficients can hold: `f64` or `Complex64`.
pub trait ChebValue:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self>
{
    /// The zero value.
    fn zero() -> Self;
}

impl ChebValue for f64 {
    fn zero() -> Self {
        0.0
    }
}

impl ChebValue for Complex64 {
    fn zero() -> Self {
        Complex64::new(0.0, 0.0)
    }
}

/// The interpolation points and transforms for `n` Chebyshev points of the first kind.
#[derive(Debug, Clone, PartialEq)]
pub struct ChebyshevBasis {
    nodes: Vec<f64>,
    /// Row-major `n × n`: `c_j = Σ_i dct[j n + i] f(x_i)`.
    dct: Vec<f64>,
    /// The extrema of `T_n`, `cos(πl/n)`, `l = 0..=n` (ends included).
    extrema: Vec<f64>,
    /// Row-major `(n + 1) × n`: `T_j` at extremum `l`, `cos(πjl/n)`.
    at_extrema: Vec<f64>,
}

impl ChebyshevBasis {
    /// The basis of `n ≥ 2` points (degree `n - 1`); `n` below 2 is taken as 2.
    pub fn new(n: usize) -> Self {
        let n = n.max(2);
        let nf = n as f64;
        let nodes = (0..n).map(|i| (PI * (i as f64 + 0.5) / nf).cos()).collect();
        let mut dct = vec![0.0; n * n];
        for j in 0..n {
            let s = if j == 0 { 1.0 / nf } else { 2.0 / nf };
            for i in 0..n {
                dct[j * n + i] = s * (PI * j as f64 * (i as f64 + 0.5) / nf).cos();
            }
        }
        let extrema = (0..=n).map(|l| (PI * l as f64 / nf).cos()).collect();
        let at_extrema = (0..=n)
            .flat_map(|l| (0..n).map(move |j| (PI * (j * l) as f64 / nf).cos()))
            .collect();
        ChebyshevBasis {
            nodes,
            dct,
            extrema,
            at_extrema,
        }
    }

    /// Number of points (degree + 1).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Always false: a basis has at least two points.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The interpolation points `x_i = cos(π(i + ½)/n)`, decreasing.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// The extrema `cos(πl/n)` of `T_n`, `l = 0..=n`: where the interpolation error's leading
    /// term `a_n T_n` peaks, so the points to check an interpolant at.
    pub fn extrema(&self) -> &[f64] {
        &self.extrema
    }

    /// `Σ c_j T_j` at extremum `l` of [`extrema`](Self::extrema), summed in increasing `j`
    /// with `T_j = cos(πjl/n)` exact to rounding (no recurrence): the check of an interpolant
    /// at the points where its error peaks. Zero for `l > n`.
    pub fn value_at_extremum<T: ChebValue>(&self, c: &[T], l: usize) -> T {
        let n = self.len();
        self.at_extrema
            .get(l * n..(l + 1) * n)
            .map_or(T::zero(), |row| {
                c.iter()
                    .zip(row)
                    .fold(T::zero(), |acc, (&c, &t)| acc + c * t)
            })
    }

    /// Chebyshev coefficients of the interpolant through `values` at [`nodes`](Self::nodes),
    /// written to `out` (both of length [`len`](Self::len); extra entries are ignored).
    pub fn coefficients_into<T: ChebValue>(&self, values: &[T], out: &mut [T]) {
        let n = self.len();
        for (j, o) in out.iter_mut().enumerate().take(n) {
            let row = &self.dct[j * n..(j + 1) * n];
            *o = row
                .iter()
                .zip(values)
                .fold(T::zero(), |acc, (&d, &v)| acc + v * d);
        }
    }

    /// Chebyshev coefficients of the interpolant through `values` at the nodes.
    pub fn coefficients<T: ChebValue>(&self, values: &[T]) -> Vec<T> {
        let mut out = vec![T::zero(); self.len()];
        self.coefficients_into(values, &mut out);
        out
    }
}

/// `Σ c_j T_j(x)` by Clenshaw's recurrence (0 for no coefficient).
///
/// ```
/// use jitterid_numeric::chebyshev::clenshaw;
/// // T_2(x) = 2x² - 1.
/// assert_eq!(clenshaw(&[0.0, 0.0, 1.0], 0.5), -0.5);
/// ```
#[inline]
pub fn clenshaw<T: ChebValue>(c: &[T], x: f64) -> T {
    let Some((&c0, rest)) = c.split_first() else {
        return T::zero();
    };
    let x2 = 2.0 * x;
    let (mut b1, mut b2) = (T::zero(), T::zero());
    for &cj in rest.iter().rev() {
        let b0 = cj + b1 * x2 - b2;
        b2 = b1;
        b1 = b0;
    }
    c0 + b1 * x - b2
}

/// Monomial coefficients `a_k` with `Σ c_j T_j(x) = Σ a_k x^k` (for Horner evaluation of
/// many points at once; well conditioned only for low degree, up to about 16).
pub fn to_monomial(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    let mut out = vec![0.0; n];
    if n == 0 {
        return out;
    }
    // T_0 = 1, T_1 = x, T_{j+1} = 2x T_j − T_{j−1}, as coefficient rows.
    let mut t_prev = vec![0.0; n];
    let mut t_cur = vec![0.0; n];
    t_prev[0] = 1.0;
    out[0] += c[0];
    if n > 1 {
        t_cur[1] = 1.0;
        out[1] += c[1];
    }
    for &cj in c.iter().skip(2) {
        let mut next = vec![0.0; n];
        for k in 0..n - 1 {
            next[k + 1] += 2.0 * t_cur[k];
        }
        for k in 0..n {
            next[k] -= t_prev[k];
            out[k] += cj * next[k];
        }
        t_prev = std::mem::replace(&mut t_cur, next);
    }
    out
}

/// Largest number of halvings of one input interval in [`PiecewiseChebyshev::build`].
pub const MAX_DEPTH: u32 = 12;

/// Errors up to this multiple of the tolerance that halving no longer reduces are taken as the
/// function's own rounding noise.
const NOISE_FLOOR: f64 = 1e5;

/// Where [`PiecewiseChebyshev::build_checked`] compares a segment's interpolant with the
/// function: at extrema of `T_points`, where the leading error term peaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CheckPoints {
    /// Every extremum `cos(πl/n)`, `l = 0..=n`, the segment's ends included.
    Extrema,
    /// The interior extrema only, `l = 1..n`: two evaluations of the function fewer per
    /// segment.
    InteriorExtrema,
}

/// A piecewise Chebyshev interpolant of `channels` real functions on sorted, non-overlapping
/// segments.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseChebyshev {
    basis: ChebyshevBasis,
    starts: Vec<f64>,
    ends: Vec<f64>,
    channels: usize,
    /// Segment-major, then channel, then the coefficients.
    coefs: Vec<f64>,
}

impl PiecewiseChebyshev {
    /// Interpolates `f` (which writes `channels` values at `t`) with `points` Chebyshev points
    /// per segment on each of `intervals`, halving a segment (at most [`MAX_DEPTH`] times)
    /// until the interpolant matches `f` at the extrema of `T_points` within
    /// `rel_tol × (channel's max |f| on the segment + the largest |f| of the channel seen so
    /// far)`: relative to the function's scale, so that the rounding noise of `f` where it
    /// nearly cancels does not force endless halving. Intervals that are empty or not finite
    /// are skipped.
    pub fn build(
        intervals: &[(f64, f64)],
        points: usize,
        channels: usize,
        rel_tol: f64,
        f: impl FnMut(f64, &mut [f64]),
    ) -> Self {
        Self::build_checked(
            intervals,
            points,
            channels,
            rel_tol,
            CheckPoints::Extrema,
            f,
        )
    }

    /// [`build`](Self::build), checking each segment at `checks`.
    pub fn build_checked(
        intervals: &[(f64, f64)],
        points: usize,
        channels: usize,
        rel_tol: f64,
        checks: CheckPoints,
        mut f: impl FnMut(f64, &mut [f64]),
    ) -> Self {
        let basis = ChebyshevBasis::new(points);
        let n = basis.len();
        let tests = match checks {
            CheckPoints::Extrema => &basis.extrema[..],
            CheckPoints::InteriorExtrema => &basis.extrema[1..n],
        }
        .to_vec();
        let mut out = PiecewiseChebyshev {
            basis,
            starts: Vec::new(),
            ends: Vec::new(),
            channels,
            coefs: Vec::new(),
        };
        let mut global = vec![0.0f64; channels];
        let mut vals = vec![0.0; channels];
        let mut node_vals = vec![vec![0.0; n]; channels];
        let mut coefs = vec![vec![0.0; n]; channels];
        // (a, b, depth, the parent's largest relative error).
        let mut stack: Vec<(f64, f64, u32, f64)> = Vec::new();
        for &(a0, b0) in intervals {
            if !(b0 > a0 && a0.is_finite() && b0.is_finite()) {
                continue;
            }
            stack.push((a0, b0, 0, f64::INFINITY));
            // Depth-first, right half pushed first so that segments come out in order.
            while let Some((a, b, depth, parent_err)) = stack.pop() {
                let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
                let mut seg_max = vec![0.0f64; channels];
                for (i, &x) in out.basis.nodes.iter().enumerate() {
                    f(mid + half * x, &mut vals);
                    for c in 0..channels {
                        node_vals[c][i] = vals[c];
                        seg_max[c] = seg_max[c].max(vals[c].abs());
                    }
                }
                for (nv, co) in node_vals.iter().zip(&mut coefs) {
                    out.basis.coefficients_into(nv, co);
                }
                let mut worst = 0.0f64;
                if depth < MAX_DEPTH {
                    for &x in &tests {
                        f(mid + half * x, &mut vals);
                        for c in 0..channels {
                            let scale = rel_tol * (seg_max[c] + global[c]);
                            let err = (clenshaw(&coefs[c], x) - vals[c]).abs();
                            let r = if err == 0.0 { 0.0 } else { err / scale };
                            worst = if r.is_nan() {
                                f64::INFINITY
                            } else {
                                worst.max(r)
                            };
                        }
                    }
                }
                // Halving an analytic piece divides the error by about 2^n; if it no longer
                // falls by 4 near the tolerance, the error is the function's own rounding
                // noise, which no interpolant removes.
                let ok = worst <= 1.0 || (worst <= NOISE_FLOOR && worst > 0.25 * parent_err);
                if ok {
                    for c in 0..channels {
                        global[c] = global[c].max(seg_max[c]);
                    }
                    out.starts.push(a);
                    out.ends.push(b);
                    for c in &coefs {
                        out.coefs.extend_from_slice(c);
                    }
                } else {
                    stack.push((mid, b, depth + 1, worst));
                    stack.push((a, mid, depth + 1, worst));
                }
            }
        }
        out
    }

    /// Number of segments.
    #[inline]
    pub fn len(&self) -> usize {
        self.starts.len()
    }

    /// Whether the table has no segment.
    pub fn is_empty(&self) -> bool {
        self.starts.is_empty()
    }

    /// Number of channels.
    #[inline]
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The segments' starts, increasing.
    #[inline]
    pub fn starts(&self) -> &[f64] {
        &self.starts
    }

    /// The segments' ends, increasing (each at or before the next segment's start).
    #[inline]
    pub fn ends(&self) -> &[f64] {
        &self.ends
    }

    /// Every coefficient: segment-major, then channel, then the [`points`](Self::points)
    /// coefficients of degree `0, 1, …` (for callers that evaluate many channels at once).
    #[inline]
    pub fn coefficient_data(&self) -> &[f64] {
        &self.coefs
    }

    /// Interpolation points per segment (degree + 1).
    #[inline]
    pub fn points(&self) -> usize {
        self.basis.len()
    }

    /// The segment `[start, end]` of index `seg`.
    pub fn bounds(&self, seg: usize) -> Option<(f64, f64)> {
        Some((*self.starts.get(seg)?, *self.ends.get(seg)?))
    }

    /// The segment containing `t`, if any.
    #[inline]
    pub fn segment(&self, t: f64) -> Option<usize> {
        let i = self.starts.partition_point(|&a| a <= t).checked_sub(1)?;
        (t <= self.ends[i]).then_some(i)
    }

    /// The Chebyshev coefficients of channel `channel` on segment `seg`.
    pub fn coefficients(&self, seg: usize, channel: usize) -> Option<&[f64]> {
        if seg >= self.len() || channel >= self.channels {
            return None;
        }
        let n = self.basis.len();
        let s = (seg * self.channels + channel) * n;
        Some(&self.coefs[s..s + n])
    }

    /// Every channel at `t`, written to `out` (length [`channels`](Self::channels)); `false`
    /// (and `out` untouched) when `t` is outside every segment.
    pub fn eval(&self, t: f64, out: &mut [f64]) -> bool {
        let Some(seg) = self.segment(t) else {
            return false;
        };
        let (a, b) = (self.starts[seg], self.ends[seg]);
        let x = ((2.0 * t - a - b) / (b - a)).clamp(-1.0, 1.0);
        for (c, o) in out.iter_mut().enumerate().take(self.channels) {
            if let Some(co) = self.coefficients(seg, c) {
                *o = clenshaw(co, x);
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolant_reproduces_a_polynomial_of_its_degree() {
        // Independent route: the cubic's value, through the degree-3 interpolant.
        let b = ChebyshevBasis::new(4);
        let p = |x: f64| 1.0 - 2.0 * x + 0.5 * x * x * x;
        let vals: Vec<f64> = b.nodes().iter().map(|&x| p(x)).collect();
        let c = b.coefficients(&vals);
        // x³ = (3T_1 + T_3)/4: c = [1, -2 + 3/8, 0, 1/8].
        for (got, want) in c.iter().zip([1.0, -2.0 + 0.375, 0.0, 0.125]) {
            assert!((got - want).abs() < 1e-15, "{c:?}");
        }
        for x in [-1.0, -0.3, 0.7, 1.0] {
            assert!((clenshaw(&c, x) - p(x)).abs() < 1e-14);
            let m = to_monomial(&c);
            let horner = m.iter().rev().fold(0.0, |acc, a| acc * x + a);
            assert!((horner - p(x)).abs() < 1e-14);
        }
        assert_eq!(b.extrema().len(), 5);
        for (l, &y) in b.extrema().iter().enumerate() {
            assert!((b.value_at_extremum(&c, l) - p(y)).abs() < 1e-14, "{l}");
        }
        assert_eq!(b.value_at_extremum(&c, 5), 0.0);
    }

    #[test]
    fn complex_coefficients_match_the_real_and_imaginary_parts() {
        let b = ChebyshevBasis::new(24);
        let f = |x: f64| Complex64::new(0.0, 3.0 * x).exp();
        let vals: Vec<Complex64> = b.nodes().iter().map(|&x| f(x)).collect();
        let c = b.coefficients(&vals);
        for &x in b.extrema() {
            // e^{3ix} is interpolated to rounding by degree 23 (coefficients fall like 1.5^j/j!).
            assert!((clenshaw(&c, x) - f(x)).norm() < 1e-14, "{x}");
        }
    }

    #[test]
    fn piecewise_table_interpolates_and_splits_where_needed() {
        let f = |t: f64, out: &mut [f64]| {
            out[0] = (-3.0 * t).exp() + (t - 1.0).max(0.0);
            out[1] = (40.0 * t).sin();
        };
        let table = PiecewiseChebyshev::build(&[(0.0, 1.0), (1.0, 3.0)], 16, 2, 1e-13, f);
        assert!(table.len() > 8);
        let (mut v, mut w) = ([0.0; 2], [0.0; 2]);
        for k in 0..=300 {
            let t = k as f64 / 100.0;
            assert!(table.eval(t, &mut v));
            f(t, &mut w);
            // Build tolerance 1e-13 × (segment max + global max) ≤ 1e-13 × 2 × 2.
            assert!(
                (v[0] - w[0]).abs() < 4e-13 && (v[1] - w[1]).abs() < 4e-13,
                "{t}"
            );
        }
        assert!(!table.eval(-0.1, &mut v) && table.segment(3.1).is_none());
        // Checking the interior extrema only never asks for more segments.
        let interior = PiecewiseChebyshev::build_checked(
            &[(0.0, 1.0), (1.0, 3.0)],
            16,
            2,
            1e-13,
            CheckPoints::InteriorExtrema,
            f,
        );
        assert!(interior.len() <= table.len() && interior.len() > 8);
        assert_eq!(interior.starts().len(), interior.ends().len());
        assert_eq!(
            interior.coefficient_data().len(),
            interior.len() * 2 * interior.points()
        );
        assert!(table.coefficients(table.len(), 0).is_none());
    }
}
