//! Contract checks that every [`Window`] must pass.
//!
//! Run [`check_contract`] in a test of any new window:
//!
//! ```
//! use jitterid_window::{testing::check_contract, HannWindow};
//! check_contract(&HannWindow).unwrap();
//! ```
//!
//! It holds the window's methods against each other and against a reference kernel that it
//! computes itself: the Neumaier-compensated direct sum `Σ_k w_k e^{-i2πνkT}` with every phase
//! `k·νT` reduced modulo one cycle exactly ([`jitterid_numeric::phase`]), not the crate's
//! blocked DTFT. A closed-form [`kernel`](Window::kernel) is thereby checked against the
//! weights it claims to transform, at record lengths from 1 to 1000 and frequencies from 0 to
//! millions of cycles per sample, on the DFT grid, next to it and between its points.

use crate::Window;
use jitterid_numeric::phase::{cis_neg_cycles, Cycles};
use jitterid_signal::SampleGrid;
use num_complex::Complex64;
use std::fmt::Write as _;

/// Record lengths checked: short, odd, even, powers of two and not.
pub const LENGTHS: [usize; 10] = [1, 2, 3, 4, 7, 16, 33, 100, 257, 1000];

/// Sampling intervals checked (s): one exact in binary and two that are not.
pub const INTERVALS: [f64; 3] = [1.0, 0.37, 1e-3];

/// Tolerance of the kernel against the reference, relative to `Σ|w_k|`: the closed forms and
/// the blocked DTFT are accurate to a few `1e-16` of it, a wrong formula is off by far more.
const KERNEL_TOL: f64 = 1e-12;

/// Frequencies, in cycles per sample `νT`, at which the kernel is checked for a record of `n`:
/// zero, DFT points and their neighbours, between grid points, negative, and large.
fn cycles(n: usize) -> Vec<f64> {
    let bin = 1.0 / n as f64;
    vec![
        0.0,
        bin,
        2.0 * bin,
        bin * (1.0 + 1e-9),
        0.5 * bin,
        0.123_456_789,
        0.5,
        -0.3,
        1.0,
        3.0 + 0.25 * bin,
        -7.77,
        1e6 + 0.31,
    ]
}

/// The reference kernel `Σ_k w_k e^{-i2πνkT}`, compensated, each phase reduced exactly.
pub fn reference_kernel(weights: &[f64], grid: &SampleGrid, nu: f64) -> Complex64 {
    let x = Cycles::new(nu, grid.interval());
    let (mut re, mut im) = (Compensated::default(), Compensated::default());
    for (k, &w) in weights.iter().enumerate() {
        let e = cis_neg_cycles(x.times(k as f64)) * w;
        re.add(e.re);
        im.add(e.im);
    }
    Complex64::new(re.value(), im.value())
}

/// Neumaier's compensated sum of reals.
#[derive(Default)]
struct Compensated {
    sum: f64,
    comp: f64,
}

impl Compensated {
    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        self.comp += if self.sum.abs() >= x.abs() {
            (self.sum - t) + x
        } else {
            (x - t) + self.sum
        };
        self.sum = t;
    }
    fn value(&self) -> f64 {
        self.sum + self.comp
    }
}

/// Checks `window` and reports every broken property, one per line:
///
/// * `weight(k, n)` is finite for `k < n` and `0` for `k ≥ n`;
/// * `weights(n)` equals `weight(k, n)` for every `k`, to the bit (a window that overrides
///   either must keep them the same);
/// * `is_rectangular()` holds only if every weight is 1;
/// * `kernel(grid, ν)` equals the reference `Σ_k w_k e^{-i2πνkT}` within `1e-12 Σ|w_k|`, at
///   every length of [`LENGTHS`], interval of [`INTERVALS`] and frequency from 0 to `10⁶/T`
///   (on, next to and between the DFT points, and negative);
/// * `kernel(grid, −ν)` is `conj kernel(grid, ν)` (real weights) and `kernel` does not depend
///   on the grid's start;
/// * a non-finite `ν` gives NaN.
pub fn check_contract<W: Window + ?Sized>(window: &W) -> Result<(), String> {
    let mut fails = Vec::new();
    for &n in &LENGTHS {
        let weights = window.weights(n);
        let each: Vec<f64> = (0..n).map(|k| window.weight(k, n)).collect();
        if weights.len() != n {
            fails.push(format!("weights({n}) has {} entries", weights.len()));
            continue;
        }
        if weights
            .iter()
            .zip(&each)
            .any(|(a, b)| a.to_bits() != b.to_bits())
        {
            fails.push(format!("weights({n}) differs from weight(k, {n})"));
        }
        if let Some(k) = each.iter().position(|w| !w.is_finite()) {
            fails.push(format!("weight({k}, {n}) = {} is not finite", each[k]));
            continue;
        }
        for k in [n, n + 1, 2 * n + 7] {
            let w = window.weight(k, n);
            if w != 0.0 {
                fails.push(format!("weight({k}, {n}) = {w}, not 0 beyond the record"));
            }
        }
        if window.is_rectangular() && each.iter().any(|&w| w != 1.0) {
            fails.push(format!("is_rectangular() but a weight of n = {n} is not 1"));
        }
        let scale: f64 = each
            .iter()
            .map(|w| w.abs())
            .sum::<f64>()
            .max(f64::MIN_POSITIVE);
        for &t in &INTERVALS {
            let grid = SampleGrid::new(0.0, t, n).expect("a valid grid");
            let moved = SampleGrid::new(-12.5, t, n).expect("a valid grid");
            for c in cycles(n) {
                let nu = c / t;
                let k = window.kernel(&grid, nu);
                let want = reference_kernel(&each, &grid, nu);
                if !((k - want).norm() <= KERNEL_TOL * scale) {
                    fails.push(format!(
                        "kernel(N = {n}, T = {t}, νT = {c}) = {k} but Σ w_k e^(-i2πνkT) = {want}"
                    ));
                }
                let mirrored = window.kernel(&grid, -nu);
                if !((mirrored - k.conj()).norm() <= KERNEL_TOL * scale) {
                    fails.push(format!(
                        "kernel(−ν) = {mirrored} but conj kernel(ν) = {} (N = {n}, T = {t}, νT = {c})",
                        k.conj()
                    ));
                }
                let other = window.kernel(&moved, nu);
                if !((other - k).norm() <= KERNEL_TOL * scale) {
                    fails.push(format!(
                        "kernel depends on the grid's start: {k} at 0, {other} at -12.5 (N = {n}, T = {t}, νT = {c})"
                    ));
                }
            }
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let k = window.kernel(&grid, bad);
                if !(k.re.is_nan() || k.im.is_nan()) {
                    fails.push(format!("kernel at ν = {bad} is {k}, not NaN (N = {n})"));
                }
            }
        }
    }
    if fails.is_empty() {
        return Ok(());
    }
    let mut msg = format!(
        "window {window:?} breaks {} contract check(s):",
        fails.len()
    );
    for f in fails {
        let _ = write!(msg, "\n  - {f}");
    }
    Err(msg)
}
