//! Piecewise Chebyshev interpolants: a signal `s(t)` (and its parameter gradient) tabulated
//! between its breakpoints, and a jitter density tabulated on its pieces, so that the exact
//! likelihood can evaluate them at many quadrature nodes for `O(1)` each.
//!
//! Each segment holds a degree-15 Chebyshev interpolant (16 points of the first kind) of every
//! channel. At build time the interpolant is compared with the function at the 15 interior
//! Chebyshev extrema; a segment whose error exceeds the tolerance is halved, so the table does
//! not rely on the model's declared rate being right.

#[cfg(doc)]
use jitterid_jitter::kernels::chebyshev::to_monomial;
use jitterid_jitter::kernels::chebyshev::{
    clenshaw, ChebyshevBasis, CheckPoints, PiecewiseChebyshev,
};
use std::sync::OnceLock;

/// Points per segment.
pub(crate) const CHEB_POINTS: usize = 16;

/// A Chebyshev basis of `N` points with its transform from node values to coefficients as a
/// fixed-size matrix, `dct[j][i]`, each entry computed by the formula of
/// [`ChebyshevBasis::new`] (so the same to the bit; a test checks the coefficients against the
/// basis').
pub(crate) struct ChebTables<const N: usize> {
    basis: ChebyshevBasis,
    dct: [[f64; N]; N],
}

impl<const N: usize> ChebTables<N> {
    fn new() -> Self {
        let nf = N as f64;
        ChebTables {
            basis: ChebyshevBasis::new(N),
            dct: std::array::from_fn(|j| {
                let s = if j == 0 { 1.0 / nf } else { 2.0 / nf };
                std::array::from_fn(|i| {
                    s * (std::f64::consts::PI * j as f64 * (i as f64 + 0.5) / nf).cos()
                })
            }),
        }
    }

    /// The basis.
    pub(crate) fn basis(&self) -> &ChebyshevBasis {
        &self.basis
    }

    /// Chebyshev coefficients of the values at the `N` nodes: the sums of
    /// [`ChebyshevBasis::coefficients_into`] in the same order, on fixed-size arrays (this runs
    /// for every sample of every likelihood evaluation, where the slice version's loops over a
    /// run-time length cost about five times as much).
    #[inline]
    pub(crate) fn coefficients(&self, values: &[f64; N]) -> [f64; N] {
        std::array::from_fn(|j| {
            let row = &self.dct[j];
            let mut acc = 0.0;
            for i in 0..N {
                acc += values[i] * row[i];
            }
            acc
        })
    }
}

impl<const N: usize> ChebTables<N> {
    /// Row `j` of the transform: `c_j = row · values`.
    #[inline]
    pub(crate) fn row(&self, j: usize) -> &[f64; N] {
        &self.dct[j]
    }

    /// The weights `w_i = Σ_j dct[j][i] μ_j` with `Σ_j c_j μ_j = Σ_i w_i v_i` for the
    /// coefficients `c` of any values `v`: the integral of the interpolant against moments `μ`
    /// as one dot product with the values (equal to the coefficients' sum up to rounding).
    pub(crate) fn weights(&self, mu: &[f64; N]) -> [f64; N] {
        std::array::from_fn(|i| (0..N).map(|j| self.dct[j][i] * mu[j]).sum())
    }
}

/// The tables of [`CHEB_POINTS`] points, computed once.
pub(crate) fn tables16() -> &'static ChebTables<CHEB_POINTS> {
    static T: OnceLock<ChebTables<CHEB_POINTS>> = OnceLock::new();
    T.get_or_init(ChebTables::new)
}

/// The tables of 32 points (the likelihood's wider shortcut), computed once.
pub(crate) fn tables32() -> &'static ChebTables<32> {
    static T: OnceLock<ChebTables<32>> = OnceLock::new();
    T.get_or_init(ChebTables::new)
}

/// Monomial coefficients `a_k` with `Σ c_j T_j(x) = Σ a_k x^k`: [`to_monomial`]'s operations
/// in its order, on fixed-size arrays (no allocation per recurrence step).
fn to_monomial16(c: &[f64]) -> [f64; CHEB_POINTS] {
    const N: usize = CHEB_POINTS;
    let mut out = [0.0; N];
    let mut t_prev = [0.0; N];
    let mut t_cur = [0.0; N];
    t_prev[0] = 1.0;
    t_cur[1] = 1.0;
    out[0] += c[0];
    out[1] += c[1];
    for &cj in &c[2..N] {
        let mut next = [0.0; N];
        for k in 0..N - 1 {
            next[k + 1] += 2.0 * t_cur[k];
        }
        for k in 0..N {
            next[k] -= t_prev[k];
            out[k] += cj * next[k];
        }
        t_prev = t_cur;
        t_cur = next;
    }
    out
}

/// A piecewise Chebyshev interpolant of `channels` real functions on sorted, non-overlapping
/// segments (the shared table), with channel 0 also in the monomial basis of the local variable
/// `x ∈ [−1, 1]`, per segment, for the batched Horner evaluation.
#[derive(Debug, Clone)]
pub(crate) struct PiecewiseCheb {
    table: PiecewiseChebyshev,
    mono0: Vec<[f64; CHEB_POINTS]>,
}

crate::simd::baseline_or_avx2! {
    /// Horner's rule for the monomial coefficients `m` of the local variable
    /// `x = clamp((t − mid)·scale, −1, 1)` (`centre = (mid, scale)`) at the 16 points `ts`,
    /// keeping the lanes in `lanes`. On x86-64 machines with AVX2 the same operations run four
    /// lanes to an instruction instead of two (`crate::simd`); no fused multiply–add is used,
    /// so the values are the same.
    fn horner16(
        m: &[f64; CHEB_POINTS],
        centre: (f64, f64),
        ts: &[f64; 16],
        out: &mut [f64; 16],
        lanes: std::ops::Range<usize>,
    ) {
        let (mid, scale) = centre;
        let mut x = [0.0; 16];
        for i in 0..16 {
            x[i] = ((ts[i] - mid) * scale).clamp(-1.0, 1.0);
        }
        let mut acc = [m[CHEB_POINTS - 1]; 16];
        for &mk in m[..CHEB_POINTS - 1].iter().rev() {
            for i in 0..16 {
                acc[i] = acc[i] * x[i] + mk;
            }
        }
        // A fixed-length select rather than a copy of the run-time range (a library call).
        for i in 0..16 {
            out[i] = if lanes.start <= i && i < lanes.end {
                acc[i]
            } else {
                out[i]
            };
        }
    }
}

/// Channels whose Clenshaw recurrences [`PiecewiseCheb::eval_all`] runs side by side.
const INTERLEAVED: usize = 8;

impl PiecewiseCheb {
    /// Interpolates `f` (which writes `channels` values at `t`) on each of `intervals`,
    /// halving a segment until the interpolant matches `f` at the interior Chebyshev extrema
    /// within `rel_tol × (channel's max |f| on the segment + the largest |f| of the channel
    /// seen so far)` ([`PiecewiseChebyshev::build_checked`]).
    pub(crate) fn build(
        intervals: &[(f64, f64)],
        channels: usize,
        rel_tol: f64,
        f: impl FnMut(f64, &mut [f64]),
    ) -> Self {
        let table = PiecewiseChebyshev::build_checked(
            intervals,
            CHEB_POINTS,
            channels,
            rel_tol,
            CheckPoints::InteriorExtrema,
            f,
        );
        let mono0 = (0..table.len())
            .map(|seg| {
                table
                    .coefficients(seg, 0)
                    .map_or([0.0; CHEB_POINTS], to_monomial16)
            })
            .collect();
        PiecewiseCheb { table, mono0 }
    }

    /// Number of segments.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.table.len()
    }

    /// The segment containing `t`, if any.
    #[inline]
    pub(crate) fn segment(&self, t: f64) -> Option<usize> {
        self.table.segment(t)
    }

    /// The segment containing `t`, trying `hint` and its successor first (updated).
    #[inline]
    pub(crate) fn segment_near(&self, t: f64, hint: &mut usize) -> Option<usize> {
        let h = *hint;
        let (starts, ends) = (self.table.starts(), self.table.ends());
        if h < self.table.len() && starts[h] <= t {
            if t <= ends[h] {
                return Some(h);
            }
            if h + 1 < self.table.len() && starts[h + 1] <= t && t <= ends[h + 1] {
                *hint = h + 1;
                return Some(h + 1);
            }
        }
        let s = self.segment(t)?;
        *hint = s;
        Some(s)
    }

    /// Channel 0 at the points `ts[lanes]` of one segment `seg`, into `out[lanes]` (Horner in
    /// the monomial basis, one lane per point). All 16 lanes are computed on fixed-size arrays,
    /// which the compiler turns into vector instructions, and only `lanes` are kept: a loop
    /// over a run-time range of lanes stays scalar and costs about twice as much. Each lane's
    /// operations do not depend on the others, so the kept values are the same either way.
    #[inline]
    fn eval0_lanes(
        &self,
        seg: usize,
        ts: &[f64; 16],
        out: &mut [f64; 16],
        lanes: std::ops::Range<usize>,
    ) {
        let (a, b) = (self.table.starts()[seg], self.table.ends()[seg]);
        horner16(
            &self.mono0[seg],
            (0.5 * (a + b), 2.0 / (b - a)),
            ts,
            out,
            lanes,
        );
    }

    /// Channel 0 at 16 increasing points, which may span several segments: each run of points
    /// in one segment is evaluated by Horner's rule, lane by lane. Points outside the table are
    /// flagged `false` in the returned mask (their values are left untouched).
    #[inline]
    pub(crate) fn eval0_sorted16(
        &self,
        ts: &[f64; 16],
        out: &mut [f64; 16],
        hint: &mut usize,
    ) -> [bool; 16] {
        let mut ok = [false; 16];
        let mut i = 0;
        while i < 16 {
            let Some(seg) = self.segment_near(ts[i], hint) else {
                i += 1;
                continue;
            };
            let end = self.table.ends()[seg];
            let mut j = i + 1;
            while j < 16 && ts[j] <= end {
                j += 1;
            }
            if j - i == 1 {
                out[i] = self.eval0(seg, ts[i]);
            } else {
                self.eval0_lanes(seg, ts, out, i..j);
            }
            ok[i..j].iter_mut().for_each(|o| *o = true);
            i = j;
        }
        ok
    }

    #[inline]
    fn local(&self, seg: usize, t: f64) -> f64 {
        let (a, b) = (self.table.starts()[seg], self.table.ends()[seg]);
        ((2.0 * t - a - b) / (b - a)).clamp(-1.0, 1.0)
    }

    /// Channel 0 at `t` in segment `seg`.
    #[inline]
    pub(crate) fn eval0(&self, seg: usize, t: f64) -> f64 {
        let x = self.local(seg, t);
        let base = seg * self.table.channels() * CHEB_POINTS;
        clenshaw(&self.table.coefficient_data()[base..base + CHEB_POINTS], x)
    }

    /// Every channel at `t` in segment `seg`: [`clenshaw`] for up to [`INTERLEAVED`] channels
    /// at a time, their recurrences interleaved (independent chains keep the floating-point
    /// units busy; each channel's operations and their order are those of `clenshaw`, so the
    /// values are the same to the bit).
    #[inline]
    pub(crate) fn eval_all(&self, seg: usize, t: f64, out: &mut [f64]) {
        let x = self.local(seg, t);
        let x2 = 2.0 * x;
        let base = seg * self.table.channels() * CHEB_POINTS;
        let coefs =
            &self.table.coefficient_data()[base..base + self.table.channels() * CHEB_POINTS];
        let n = out.len().min(self.table.channels());
        for (group, outs) in out[..n].chunks_mut(INTERLEAVED).enumerate() {
            let first = group * INTERLEAVED;
            let mut b1 = [0.0; INTERLEAVED];
            let mut b2 = [0.0; INTERLEAVED];
            for j in (1..CHEB_POINTS).rev() {
                for c in 0..outs.len() {
                    let b0 = coefs[(first + c) * CHEB_POINTS + j] + x2 * b1[c] - b2[c];
                    b2[c] = b1[c];
                    b1[c] = b0;
                }
            }
            for (c, o) in outs.iter_mut().enumerate() {
                *o = coefs[(first + c) * CHEB_POINTS] + x * b1[c] - b2[c];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_to_machine_precision_and_splits_where_needed() {
        // e^{-3t} on [0, 4] and a kink at 1: the caller splits at the kink.
        let f = |t: f64, out: &mut [f64]| {
            out[0] = (-3.0 * t).exp() + (t - 1.0).max(0.0);
            out[1] = t * t;
        };
        let table = PiecewiseCheb::build(&[(0.0, 1.0), (1.0, 4.0)], 2, 1e-14, f);
        assert!(table.len() >= 2);
        let mut v = [0.0; 2];
        let mut w = [0.0; 2];
        for k in 0..=400 {
            let t = k as f64 / 100.0;
            let seg = table.segment(t).unwrap();
            table.eval_all(seg, t, &mut v);
            f(t, &mut w);
            assert!(
                (v[0] - w[0]).abs() < 1e-14 * 4.0,
                "{t}: {} vs {}",
                v[0],
                w[0]
            );
            assert!((v[1] - w[1]).abs() < 1e-13, "{t}");
            assert_eq!(table.eval0(seg, t), v[0]);
        }
        assert!(table.segment(-0.1).is_none() && table.segment(4.1).is_none());
    }

    #[test]
    fn batched_horner_matches_clenshaw() {
        let f = |t: f64, out: &mut [f64]| out[0] = (-2.0 * t).exp() * (3.0 * t).cos() + 0.5;
        let table = PiecewiseCheb::build(&[(0.0, 2.0)], 1, 1e-14, f);
        let mut hint = 0;
        let ts: [f64; 16] = std::array::from_fn(|i| 0.05 + 0.12 * i as f64);
        let mut out = [0.0; 16];
        let ok = table.eval0_sorted16(&ts, &mut out, &mut hint);
        // Build tolerance: 1e-14 × (segment max + global max) ≤ 1e-14 × 2 × 1.5 here; the
        // monomial (Horner) and Chebyshev (Clenshaw) forms agree to a few ulps of the
        // monomial coefficients' sum (≤ 10 here).
        for i in 0..16 {
            assert!(ok[i]);
            let mut v = [0.0];
            f(ts[i], &mut v);
            assert!((out[i] - v[0]).abs() < 3e-14, "{i}: {} vs {}", out[i], v[0]);
            let seg = table.segment(ts[i]).unwrap();
            let c = table.eval0(seg, ts[i]);
            assert!(
                (out[i] - c).abs() < 10.0 * 4.0 * f64::EPSILON,
                "{i}: {} vs {c}",
                out[i]
            );
        }
    }

    #[test]
    fn interleaved_channels_equal_clenshaw_to_the_bit() {
        // 11 channels: one full group of 8 and a partial group of 3.
        let f = |t: f64, out: &mut [f64]| {
            for (c, o) in out.iter_mut().enumerate() {
                *o = (-(c as f64 + 1.0) * t).exp() * (2.0 * t + c as f64).sin();
            }
        };
        let table = PiecewiseCheb::build(&[(0.0, 2.0)], 11, 1e-13, f);
        let mut out = [0.0; 11];
        for k in 0..=50 {
            let t = k as f64 / 25.0;
            let seg = table.segment(t).unwrap();
            table.eval_all(seg, t, &mut out);
            let x = table.local(seg, t);
            for (c, &v) in out.iter().enumerate() {
                let s = (seg * 11 + c) * CHEB_POINTS;
                let direct = clenshaw(&table.table.coefficient_data()[s..s + CHEB_POINTS], x);
                assert_eq!(v.to_bits(), direct.to_bits(), "t = {t}, channel {c}");
            }
        }
    }

    /// Deterministic values spanning signs and magnitudes (a fixed linear congruential
    /// sequence).
    fn test_values<const N: usize>(seed: u64) -> [f64; N] {
        let mut state = seed;
        std::array::from_fn(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            (u - 0.5) * 10f64.powi((state % 7) as i32 - 3)
        })
    }

    #[test]
    fn fixed_size_coefficients_equal_the_basis_to_the_bit() {
        fn check<const N: usize>(tables: &ChebTables<N>) {
            for seed in 0..200 {
                let v = test_values::<N>(seed);
                let mut reference = [0.0; N];
                tables.basis().coefficients_into(&v, &mut reference);
                let fast = tables.coefficients(&v);
                for j in 0..N {
                    assert_eq!(
                        fast[j].to_bits(),
                        reference[j].to_bits(),
                        "{N} points, seed {seed}, c_{j}"
                    );
                }
            }
        }
        check(tables16());
        check(tables32());
    }

    #[test]
    fn fixed_size_monomials_equal_the_kernel_to_the_bit() {
        for seed in 0..200 {
            let c = test_values::<CHEB_POINTS>(seed);
            let reference = jitterid_jitter::kernels::chebyshev::to_monomial(&c);
            let fast = to_monomial16(&c);
            for k in 0..CHEB_POINTS {
                assert_eq!(
                    fast[k].to_bits(),
                    reference[k].to_bits(),
                    "seed {seed}, a_{k}"
                );
            }
        }
    }

    #[test]
    fn lanes_of_a_segment_equal_single_lane_horner_to_the_bit() {
        let f = |t: f64, out: &mut [f64]| out[0] = (-1.5 * t).exp() * (5.0 * t).sin() + 0.25;
        let table = PiecewiseCheb::build(&[(0.0, 3.0)], 1, 1e-14, f);
        assert!(table.len() > 1);
        // Points spanning several segments, so that runs start and end inside the 16 lanes.
        let ts: [f64; 16] = std::array::from_fn(|i| 0.1 + 0.17 * i as f64);
        let mut out = [f64::NAN; 16];
        let mut hint = 0;
        let ok = table.eval0_sorted16(&ts, &mut out, &mut hint);
        for i in 0..16 {
            assert!(ok[i]);
            // Horner on lane i alone, the operations of one lane of `eval0_lanes`.
            let seg = table.segment(ts[i]).unwrap();
            let alone = (i == 0 || table.segment(ts[i - 1]) != Some(seg))
                && (i == 15 || table.segment(ts[i + 1]) != Some(seg));
            if alone {
                // A run of one point uses Clenshaw (`eval0`).
                assert_eq!(out[i].to_bits(), table.eval0(seg, ts[i]).to_bits(), "{i}");
                continue;
            }
            let (a, b) = (table.table.starts()[seg], table.table.ends()[seg]);
            let (mid, scale) = (0.5 * (a + b), 2.0 / (b - a));
            let x = ((ts[i] - mid) * scale).clamp(-1.0, 1.0);
            let m = &table.mono0[seg];
            let mut acc = m[CHEB_POINTS - 1];
            for &mk in m[..CHEB_POINTS - 1].iter().rev() {
                acc = acc * x + mk;
            }
            assert_eq!(out[i].to_bits(), acc.to_bits(), "{i}");
        }
    }

    #[test]
    fn fast_oscillation_is_refined() {
        let f = |t: f64, out: &mut [f64]| out[0] = (40.0 * t).sin();
        let table = PiecewiseCheb::build(&[(0.0, 3.0)], 1, 1e-13, f);
        assert!(table.len() > 8);
        for k in 0..=300 {
            let t = k as f64 / 100.0;
            let seg = table.segment(t).unwrap();
            assert!(
                (table.eval0(seg, t) - (40.0 * t).sin()).abs() < 1e-12,
                "{t}"
            );
        }
    }
}
