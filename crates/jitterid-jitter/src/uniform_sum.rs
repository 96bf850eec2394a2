//! The uniform-sum family of the paper's eq. (15), in its corrected form.

use crate::error::{param_count, positive};
use crate::model::{cexp, phasor};
use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::{Rng, RngCore};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// See [`UniformSum::MAX_N`].
const MAX_N: u32 = 200;

/// Sum of `n + 1` independent uniforms: `τ = U_1 + … + U_{n+1}`, `U_j ~ U[-a/(n+1), a/(n+1)]`.
///
/// Support `[-a, a]`, mean 0, variance `a²/(3(n+1))`, and
/// `γ(f) = [sin x / x]^{n+1}` with `x = 2πfa/(n+1)`. `n = 0` is uniform on `[-a, a]`, `n = 1`
/// triangular, and large `n` tends to the Gaussian of equal variance. The paper prints `πfa`
/// instead of `2πfa`, which contradicts its own support and variance; see the crate docs.
///
/// Only `a` is a continuous parameter ([`params`](JitterModel::params) is `[a]`); the integer
/// `n` is structural, changed with [`with_n`](Self::with_n), and estimated by profiling.
///
/// The density is the scaled Irwin–Hall density, evaluated with a recursion of non-negative
/// terms so that it stays accurate for every `n ≤` [`MAX_N`](Self::MAX_N). (The textbook
/// alternating sum loses about 8 digits at the centre for `n = 20` and all of them by
/// `n ≈ 40`.)
///
/// ```
/// use jitterid_jitter::{JitterModel, UniformSum};
/// let j = UniformSum::new(0, 0.5).unwrap(); // U[-1/2, 1/2]
/// assert!((j.variance() - 1.0 / 12.0).abs() < 1e-17);
/// assert_eq!(j.params(), vec![0.5]);
/// assert_eq!(j.with_n(2).unwrap().n(), 2);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "UniformSumRaw")]
pub struct UniformSum {
    n: u32,
    a: f64,
}

/// Unvalidated form, so that deserialisation goes through [`UniformSum::new`].
#[derive(Deserialize)]
struct UniformSumRaw {
    n: u32,
    a: f64,
}

impl TryFrom<UniformSumRaw> for UniformSum {
    type Error = JitterError;
    fn try_from(raw: UniformSumRaw) -> Result<Self, JitterError> {
        UniformSum::new(raw.n, raw.a)
    }
}

impl UniformSum {
    /// Largest `n` accepted. The density costs `O(n²)` per evaluation and its rule has
    /// `16(n+1)` nodes; far below this bound the family is already indistinguishable from a
    /// Gaussian.
    pub const MAX_N: u32 = MAX_N;

    /// Sum of `n + 1` uniforms with total half-width `a` (seconds). `a` must be finite and
    /// `> 0`, and `n ≤` [`MAX_N`](Self::MAX_N).
    pub fn new(n: u32, a: f64) -> Result<Self, JitterError> {
        if n > MAX_N {
            return Err(JitterError::OutOfRange {
                name: "n",
                value: f64::from(n),
                range: "[0, 200]",
            });
        }
        Ok(UniformSum {
            n,
            a: positive("a", a)?,
        })
    }

    /// The same half-width `a` with another number of terms `n + 1`.
    pub fn with_n(&self, n: u32) -> Result<Self, JitterError> {
        UniformSum::new(n, self.a)
    }

    /// `n`: the sum has `n + 1` terms.
    pub fn n(&self) -> u32 {
        self.n
    }

    /// Half-width `a` of the support `[-a, a]`.
    pub fn a(&self) -> f64 {
        self.a
    }

    /// Number of terms `m = n + 1`.
    fn terms(&self) -> u32 {
        self.n + 1
    }

    /// Half-width `a/(n+1)` of each uniform term.
    fn half_width(&self) -> f64 {
        self.a / f64::from(self.terms())
    }

    /// `(sin x / x, cos x - sin x / x)` at `x = 2πq`, accurate for every finite `q`: a series
    /// near 0 (the difference cancels there) and a phase reduced modulo one period elsewhere.
    fn sinc_terms(q: f64) -> (f64, f64) {
        let x = 2.0 * PI * q;
        if x.abs() < 1.0 {
            // sin x/x = Σ t_k, t_k = (-x²)^k/(2k+1)!; cos x - sin x/x = Σ 2k t_k.
            // At |x| < 1 the terms after k = 12 are below 1e-26.
            let x2 = x * x;
            let (mut t, mut s, mut d) = (1.0, 1.0, 0.0);
            for k in 1..=12 {
                let kf = f64::from(k);
                t *= -x2 / ((2.0 * kf) * (2.0 * kf + 1.0));
                s += t;
                d += 2.0 * kf * t;
            }
            (s, d)
        } else {
            let e = phasor(q); // cos x - i sin x
                               // x is infinite only if q is; the phase of a huge double is then taken as 0.
            let s = if x.is_finite() { -e.im / x } else { 0.0 };
            (s, e.re - s)
        }
    }
}

/// Density of the standard Irwin–Hall law (sum of `m` uniforms on `[0, 1]`) at `x ∈ [0, m/2]`.
///
/// Uses `f_k(y) = [y f_{k-1}(y) + (k - y) f_{k-1}(y - 1)] / (k - 1)`, whose two terms are
/// non-negative on the support, so rounding errors never cancel. For fixed `x`, the values
/// `g[i] = f_k(x - i)` for `i = 0..=⌊x⌋` are updated in place for `k = 2..=m`; terms with
/// `x - i < 0` vanish and are never stored. Cost `O(m x)`.
fn irwin_hall(m: usize, x: f64) -> f64 {
    if m <= PIECE_TERMS {
        return irwin_hall_piece(m, x);
    }
    // A small stack buffer for the usual small n: zeroing the full one costs more than the
    // recursion itself.
    if m < 16 {
        irwin_hall_in(m, x, &mut [0.0; 17])
    } else {
        irwin_hall_in(m, x, &mut [0.0; MAX_N as usize + 2])
    }
}

/// Most terms `m` whose density is evaluated from its piece polynomials.
const PIECE_TERMS: usize = 16;

/// For `m ≤ PIECE_TERMS`: the polynomial of the piece `[i, i + 1]`, `i ≤ m/2`, in
/// `u = x − i`, `f(i + u) = Σ_j c_j u^j` (entry `[i][j]`).
///
/// From `f(x) = Σ_{k ≤ i} (−1)^k C(m, k) (x − k)^{m−1} / (m − 1)!` on the piece, the
/// coefficient of `u^j` is `C(m−1, j) S_j / (m − 1)!` with the integer
/// `S_j = Σ_{k ≤ i} (−1)^k C(m, k) (i − k)^{m−1−j}`, computed exactly (`i128`), so each
/// coefficient is rounded once or twice. On `[0, m/2]` the terms `|c_j| u^j` add up to at
/// most 2.5 times the density (a test checks it), so Horner's rule loses nothing to
/// cancellation: the result is within a few ulp, as the recurrence's, at a fraction of its
/// `O(m²)` cost.
fn pieces_of(m: usize) -> &'static [Vec<f64>] {
    static TABLES: [OnceLock<Vec<Vec<f64>>>; PIECE_TERMS + 1] =
        [const { OnceLock::new() }; PIECE_TERMS + 1];
    TABLES[m].get_or_init(|| {
        let binom = |n: usize, k: usize| -> i128 {
            (0..k).fold(1i128, |c, r| c * (n - r) as i128 / (r as i128 + 1))
        };
        let d = m - 1;
        let factorial = (1..=d).map(|k| k as f64).product::<f64>();
        (0..=m / 2)
            .map(|i| {
                (0..m)
                    .map(|j| {
                        let s: i128 = (0..=i)
                            .map(|k| {
                                let sign = if k % 2 == 0 { 1 } else { -1 };
                                sign * binom(m, k) * ((i - k) as i128).pow((d - j) as u32)
                            })
                            .sum();
                        (binom(d, j) * s) as f64 / factorial
                    })
                    .collect()
            })
            .collect()
    })
}

/// [`irwin_hall`] for `m ≤ PIECE_TERMS` by the piece polynomials of [`pieces_of`].
fn irwin_hall_piece(m: usize, x: f64) -> f64 {
    let pieces = pieces_of(m);
    let i = (x.floor().max(0.0) as usize).min(pieces.len() - 1);
    let u = x - i as f64;
    let c = &pieces[i];
    let mut p = c[m - 1];
    for &cj in c[..m - 1].iter().rev() {
        p = p * u + cj;
    }
    p
}

fn irwin_hall_in(m: usize, x: f64, g: &mut [f64]) -> f64 {
    let imax = (x.floor() as usize).min(m - 1);
    // f_1 = 1 on [0, 1), half-open so that integer knots are not counted twice.
    for (i, gi) in g.iter_mut().enumerate().take(imax + 1) {
        *gi = if x - (i as f64) < 1.0 { 1.0 } else { 0.0 };
    }
    for k in 2..=m {
        let kf = k as f64;
        let inv = 1.0 / (kf - 1.0);
        for i in 0..=imax {
            let y = x - i as f64;
            // g[i + 1] still holds f_{k-1}(y - 1): increasing i updates in place.
            g[i] = (y * g[i] + (kf - y) * g[i + 1]) * inv;
        }
    }
    g[0]
}

/// `sinh(y)/y` by its series, for `|y| < 1/2`: the terms after `y^18/19!` are below `1e-22`.
fn sinhc_series(y: Complex64) -> Complex64 {
    let y2 = y * y;
    let mut t = Complex64::new(1.0, 0.0);
    let mut s = t;
    for k in 1..=9 {
        let kf = f64::from(k);
        t = t * y2 / ((2.0 * kf) * (2.0 * kf + 1.0));
        s += t;
    }
    s
}

impl JitterModel for UniformSum {
    fn name(&self) -> &'static str {
        "uniform-sum"
    }

    fn param_names(&self) -> Vec<String> {
        vec!["a".to_string()]
    }

    fn even_params(&self) -> Vec<bool> {
        // A law symmetric about 0 and scaled by its one parameter: γ is even in it.
        vec![true]
    }

    fn params(&self) -> Vec<f64> {
        vec![self.a]
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 1, params)?;
        UniformSum::new(self.n, params[0])
    }

    fn cf(&self, f: f64) -> Complex64 {
        let (s, _) = Self::sinc_terms(f * self.half_width());
        Complex64::new(s.powi(self.terms() as i32), 0.0)
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        // γ = s(x)^m with x ∝ a, so ∂γ/∂a = m s^{m-1} s'(x) x / a = m s^{m-1} (cos x - s) / a.
        let m = self.terms() as i32;
        let (s, d) = Self::sinc_terms(f * self.half_width());
        let p = s.powi(m - 1);
        let g = if p == 0.0 {
            0.0
        } else {
            f64::from(m) * p * d / self.a
        };
        vec![Complex64::new(g, 0.0)]
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        let m = self.terms();
        // sinh(y)/y is even in y: work with Re y ≥ 0.
        let mut y = z * self.half_width();
        if y.re < 0.0 {
            y = -y;
        }
        let w = if y.norm() < 0.5 {
            sinhc_series(y).powi(m as i32)
        } else if y.re * f64::from(m) <= 600.0 {
            // |sinh(y)/y|^m ≤ e^{m Re y} ≤ e^600: no overflow in the power.
            let w = y.sinh() / y;
            if w.im == 0.0 {
                Complex64::new(w.re.powi(m as i32), 0.0)
            } else {
                w.powi(m as i32)
            }
        } else {
            // ln(sinh(y)/y) = y + ln((1 - e^{-2y})/2) - ln y, with Re y ≥ 600/m ≥ 2.9;
            // the power is then an exponential that may overflow to +∞ on its own.
            let l = y + ((1.0 - cexp(-2.0 * y)) * 0.5).ln() - y.ln();
            cexp(f64::from(m) * l)
        };
        Some(w)
    }

    fn pdf(&self, tau: f64) -> f64 {
        if tau.is_nan() || tau.abs() > self.a {
            return 0.0;
        }
        let w = 2.0 * self.half_width();
        // By symmetry, the distance to the nearer end of the support in units of one
        // uniform's width: the Irwin–Hall argument in [0, m/2].
        let x = ((self.a - tau.abs()) / w).min(0.5 * f64::from(self.terms()));
        irwin_hall(self.terms() as usize, x) / w
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        // The density is a polynomial of degree n between the knots -a + 2a j/(n+1). For
        // n ≤ 15 a 16-point rule integrates it times any polynomial of degree ≤ 16 exactly.
        // For larger n it is log-concave and close to a Gaussian whose σ exceeds the knot
        // spacing; its log-derivative times the spacing is below ~9 wherever the piece
        // carries more than 1e-25 of the mass, which Gauss–Legendre-16 resolves to 1e-15.
        let m = self.terms();
        let knot = |j: u32| self.a * ((2.0 * f64::from(j) - f64::from(m)) / f64::from(m));
        (0..m).map(|j| (knot(j), knot(j + 1))).collect()
    }

    fn mean(&self) -> f64 {
        0.0
    }

    fn variance(&self) -> f64 {
        self.a * self.a / (3.0 * f64::from(self.terms()))
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        let h = self.half_width();
        (0..self.terms())
            .map(|_| h * (2.0 * rng.random::<f64>() - 1.0))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Textbook alternating-sum Irwin–Hall density; fine for small m only.
    fn irwin_hall_alternating(m: usize, x: f64) -> f64 {
        let mut s = 0.0;
        let mut binom = 1.0;
        let mut fact = 1.0;
        for k in 1..m {
            fact *= k as f64;
        }
        for k in 0..=m {
            if x - k as f64 > 0.0 {
                let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                s += sign * binom * (x - k as f64).powi(m as i32 - 1);
            }
            binom = binom * (m - k) as f64 / (k + 1) as f64;
        }
        s / fact
    }

    /// Exact moments E[τ²], E[τ⁴], E[τ⁶] from the cumulants of U[-h, h]
    /// (κ₂ = h²/3, κ₄ = -2h⁴/15, κ₆ = 16h⁶/63), which add over the m terms.
    fn exact_moments(n: u32, a: f64) -> [f64; 3] {
        let m = f64::from(n + 1);
        let h = a / m;
        let (k2, k4, k6) = (
            m * h * h / 3.0,
            -2.0 * m * h.powi(4) / 15.0,
            16.0 * m * h.powi(6) / 63.0,
        );
        [
            k2,
            k4 + 3.0 * k2 * k2,
            k6 + 15.0 * k4 * k2 + 15.0 * k2.powi(3),
        ]
    }

    #[test]
    fn constructor_validates() {
        assert!(matches!(
            UniformSum::new(0, f64::NAN),
            Err(JitterError::NotFinite { name: "a", .. })
        ));
        assert!(matches!(
            UniformSum::new(2, f64::INFINITY),
            Err(JitterError::NotFinite { .. })
        ));
        assert!(matches!(
            UniformSum::new(2, 0.0),
            Err(JitterError::NotPositive { name: "a", .. })
        ));
        assert!(matches!(
            UniformSum::new(2, -0.5),
            Err(JitterError::NotPositive { .. })
        ));
        assert!(matches!(
            UniformSum::new(MAX_N + 1, 1.0),
            Err(JitterError::OutOfRange { name: "n", range, .. }) if range.contains(&MAX_N.to_string())
        ));
        assert!(UniformSum::new(MAX_N, 1.0).is_ok());
        assert!(UniformSum::new(3, 1.0).unwrap().with_n(MAX_N + 1).is_err());
    }

    #[test]
    fn special_values() {
        let u = UniformSum::new(0, 0.5).unwrap();
        assert!((u.variance() - 1.0 / 12.0).abs() < 1e-17);
        assert_eq!(u.pdf(0.3), 1.0);
        assert_eq!(u.pdf(0.5), 1.0);
        assert_eq!(u.pdf(0.51), 0.0);
        assert_eq!(u.pdf(f64::NAN), 0.0);
        // γ(1) = sin(π)/π = 0 up to rounding; γ(1/2) = sin(π/2)/(π/2) = 2/π.
        assert!(u.cf(1.0).re.abs() < 1e-16);
        assert!((u.cf(0.5).re - 2.0 / PI).abs() < 1e-16);
        // Triangle: n = 1 on [-1, 1] has p(τ) = 1 - |τ|.
        let t = UniformSum::new(1, 1.0).unwrap();
        for tau in [-0.9, -0.25, 0.0, 0.5, 0.999] {
            assert!((t.pdf(tau) - (1.0 - f64::abs(tau))).abs() < 1e-15, "{tau}");
        }
        assert_eq!(t.pieces(), vec![(-1.0, 0.0), (0.0, 1.0)]);
        // The paper's Table 2 jitter.
        let a = 0.5 / 3f64.sqrt();
        let j = UniformSum::new(2, a).unwrap();
        assert!((j.std_dev() - a / 3.0).abs() < 1e-17);
    }

    #[test]
    fn cf_at_large_n_and_huge_frequency_is_finite_and_tiny() {
        let j = UniformSum::new(50, 1.0).unwrap();
        for f in [1e2, 1e4, 1e8, 1e15, 1e300, f64::MAX] {
            for f in [f, -f] {
                let g = j.cf(f);
                assert!(g.re.is_finite() && g.im == 0.0, "f = {f}");
                assert!(g.re.abs() < 1e-50, "f = {f}: {g}");
                let d = j.cf_gradient(f);
                assert!(d[0].re.is_finite(), "f = {f}");
            }
        }
        // Near zero: the series keeps γ ≤ 1 and 1 - γ ≈ (2πfσ)²/2 to full relative accuracy.
        let f = 1e-9;
        let g = j.cf(f).re;
        assert!(g <= 1.0);
        let x = 2.0 * PI * f / 51.0;
        let d = j.cf_gradient(f);
        let exact = 51.0 * (-x * x / 3.0);
        assert!((d[0].re - exact).abs() < 1e-14 * exact.abs());
    }

    #[test]
    fn pdf_is_stable_for_large_n() {
        let j = UniformSum::new(50, 1.0).unwrap();
        let sigma = j.std_dev();
        let gauss = |t: f64| (-0.5 * (t / sigma).powi(2)).exp() / (sigma * (2.0 * PI).sqrt());
        for k in 0..=400 {
            let tau = -1.0 + k as f64 / 200.0;
            let p = j.pdf(tau);
            assert!(p >= 0.0 && p.is_finite(), "{tau}: {p}");
            if tau.abs() <= sigma {
                assert!(
                    (p / gauss(tau) - 1.0).abs() < 0.02,
                    "{tau}: {p} vs {}",
                    gauss(tau)
                );
            }
        }
        // The far tail is the monomial x^50/50! exactly.
        let x: f64 = 0.3;
        let direct = x.powi(50) / (1..=50).map(f64::from).product::<f64>();
        assert!((irwin_hall(51, x) - direct).abs() < 1e-14 * direct);
    }

    #[test]
    fn piece_polynomials_agree_with_the_recurrence_without_cancelling() {
        // The recurrence (the route for m > PIECE_TERMS) never cancels: the two routes agree
        // to a few ulp, and the pieces' terms add up to at most 2.5 times the value
        // (the worst case, m = 4 at x = 2).
        for m in 1..=PIECE_TERMS {
            let pieces = pieces_of(m);
            for k in 0..=400 {
                let x = 0.5 * m as f64 * f64::from(k) / 400.0;
                let slow = irwin_hall_in(m, x, &mut [0.0; 17]);
                let fast = irwin_hall_piece(m, x);
                assert!(
                    (fast - slow).abs() <= 8.0 * f64::EPSILON * slow,
                    "m = {m}, x = {x}: {fast} vs {slow}"
                );
                let i = (x.floor() as usize).min(pieces.len() - 1);
                let u = x - i as f64;
                let mass: f64 = pieces[i]
                    .iter()
                    .enumerate()
                    .map(|(j, c)| c.abs() * u.powi(j as i32))
                    .sum();
                assert!(mass <= 2.5 * fast, "m = {m}, x = {x}: {mass} vs {fast}");
            }
        }
    }

    #[test]
    fn pdf_matches_alternating_sum_for_small_n() {
        for m in 1..=6 {
            for k in 0..=60 {
                let x = 0.5 * m as f64 * k as f64 / 60.0 + 1e-9;
                let (a, b) = (irwin_hall(m, x), irwin_hall_alternating(m, x));
                assert!((a - b).abs() < 1e-13, "m = {m}, x = {x}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn rule_moments_are_exact_for_all_n() {
        for n in [0, 1, 2, 7, 15, 16, 31, 32, 50, 100, MAX_N] {
            for a in [1e-6, 0.3, 5.0] {
                let j = UniformSum::new(n, a).unwrap();
                let r = j.rule(&[], 0.0);
                let [m2, m4, m6] = exact_moments(n, a);
                // Plain summation of N positive terms: rounding ≈ √N ε, allowed 4√N ε.
                let tol = 4.0 * (r.len() as f64).sqrt() * f64::EPSILON;
                assert!((r.mass() - 1.0).abs() < tol, "n = {n}: {}", r.mass() - 1.0);
                let e2 = r.expect(|t| t * t);
                let e4 = r.expect(|t| t.powi(4));
                let e6 = r.expect(|t| t.powi(6));
                assert!(
                    (e2 / m2 - 1.0).abs() < tol,
                    "n = {n}, a = {a}: {}",
                    e2 / m2 - 1.0
                );
                assert!(
                    (e4 / m4 - 1.0).abs() < tol,
                    "n = {n}, a = {a}: {}",
                    e4 / m4 - 1.0
                );
                assert!(
                    (e6 / m6 - 1.0).abs() < tol,
                    "n = {n}, a = {a}: {}",
                    e6 / m6 - 1.0
                );
                assert!((j.variance() / m2 - 1.0).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn mgf_matches_closed_form_and_rule() {
        for n in [0, 2, 50] {
            let j = UniformSum::new(n, 0.4).unwrap();
            let m = f64::from(n + 1);
            for z in [
                Complex64::new(0.0, 0.0),
                Complex64::new(1e-3, -2e-3),
                Complex64::new(-3.0, 1.0),
                Complex64::new(20.0, -40.0),
                Complex64::new(500.0, 7.0),
                // y = z a/m = 13 + 0.5i for n = 50: the logarithmic branch, still finite.
                Complex64::new(1657.5, 63.75),
            ] {
                let got = j.mgf(z).unwrap();
                let y = z * 0.4 / m;
                let direct = if y.norm() == 0.0 {
                    Complex64::new(1.0, 0.0)
                } else {
                    (y.sinh() / y).powf(m)
                };
                assert!(
                    (got - direct).norm() <= 1e-12 * direct.norm(),
                    "n = {n}, z = {z}: {got} vs {direct}"
                );
                if z.norm() < 100.0 {
                    let r = j.rule(&[], z.norm());
                    let e = r.expect(|t| (z * t).exp().re)
                        + Complex64::i() * r.expect(|t| (z * t).exp().im);
                    assert!((got - e).norm() <= 1e-13 * got.norm(), "n = {n}, z = {z}");
                }
            }
        }
        // Overflow is +∞, never NaN.
        let j = UniformSum::new(3, 1.0).unwrap();
        assert_eq!(
            j.mgf(Complex64::new(1e4, 0.0)),
            Some(Complex64::new(f64::INFINITY, 0.0))
        );
        assert!(j.mgf(Complex64::new(-1e4, 0.0)).unwrap().re.is_infinite());
    }

    #[test]
    fn serde_validates() {
        let j = UniformSum::new(2, 0.25).unwrap();
        let s = serde_json::to_string(&j).unwrap();
        assert_eq!(s, r#"{"n":2,"a":0.25}"#);
        assert_eq!(serde_json::from_str::<UniformSum>(&s).unwrap(), j);
        assert!(serde_json::from_str::<UniformSum>(r#"{"n":2,"a":0.0}"#).is_err());
        assert!(serde_json::from_str::<UniformSum>(r#"{"n":999,"a":1.0}"#).is_err());
    }
}
