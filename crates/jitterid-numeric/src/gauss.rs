//! Gauss–Legendre rules: nodes and weights on `[-1, 1]`, and the cached 16-point rule that the
//! expectation rules, the signal crate's reach integrals and the exact likelihood share.

use std::sync::OnceLock;

/// Largest `rate × width` allowed on one sub-interval: with 16 nodes the Gauss–Legendre error
/// for `e^{zτ}` with `|z|·width ≤ 6` is below `1e-15` relative.
pub const MAX_RATE_WIDTH: f64 = 6.0;

/// Upper bound on the sub-intervals of one piece, so that a huge rate cannot exhaust memory.
pub const MAX_SUBDIVISIONS: usize = 4096;

/// Number of Gauss–Legendre nodes per sub-interval of the workspace's rules.
pub const GL_ORDER: usize = 16;

/// Gauss–Legendre nodes and weights on `[-1, 1]` for `n` points, by Newton's method on the
/// Legendre recurrence. Nodes are increasing and symmetric.
///
/// ```
/// use jitterid_numeric::gauss::gauss_legendre;
/// let (x, w) = gauss_legendre(3);
/// assert!((x[2] - 0.6f64.sqrt()).abs() < 1e-15 && (w[1] - 8.0 / 9.0).abs() < 1e-15);
/// ```
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        // Tricomi's initial guess, then Newton.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn1 = if n == 0 { 0.0 } else { p0 };
            dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    (nodes, weights)
}

/// The [`GL_ORDER`]-point Gauss–Legendre rule on `[-1, 1]` (nodes, weights), computed once.
pub fn gl16() -> &'static (Vec<f64>, Vec<f64>) {
    static RULE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    RULE.get_or_init(|| gauss_legendre(GL_ORDER))
}

/// Sub-intervals of a composite rule over `width` for an integrand varying at `rate`: enough
/// that `rate × sub-interval ≤` [`MAX_RATE_WIDTH`], at least one and at most
/// [`MAX_SUBDIVISIONS`] (one for a rate or width that is not positive and finite).
///
/// ```
/// use jitterid_numeric::gauss::subdivisions;
/// assert_eq!((subdivisions(7.0, 1.0), subdivisions(f64::NAN, 1.0)), (2, 1));
/// ```
pub fn subdivisions(rate: f64, width: f64) -> usize {
    if rate.is_finite() && rate > 0.0 && width > 0.0 {
        ((rate * width / MAX_RATE_WIDTH).ceil() as usize).clamp(1, MAX_SUBDIVISIONS)
    } else {
        1
    }
}

/// The `parts` equal sub-intervals of `[a, b]` (at least one) as `(midpoint, half-width)`, the
/// last one ending exactly at `b`: a composite rule maps node `x_i` of `[-1, 1]` to
/// `mid + half · x_i` with weight `half · w_i`.
///
/// ```
/// use jitterid_numeric::gauss::panels;
/// let p: Vec<(f64, f64)> = panels(0.0, 2.0, 2).collect();
/// assert_eq!(p, vec![(0.5, 0.5), (1.5, 0.5)]);
/// ```
pub fn panels(a: f64, b: f64, parts: usize) -> impl Iterator<Item = (f64, f64)> {
    let parts = parts.max(1);
    let h = (b - a) / parts as f64;
    (0..parts).map(move |p| {
        let lo = a + p as f64 * h;
        let hi = if p + 1 == parts { b } else { lo + h };
        (0.5 * (lo + hi), 0.5 * (hi - lo))
    })
}

/// `∫_a^b f(t) dt` by the 16-point rule on `parts` equal sub-intervals (at least one).
///
/// ```
/// use jitterid_numeric::gauss::integrate;
/// let s = integrate(0.0, std::f64::consts::PI, 1, f64::sin);
/// assert!((s - 2.0).abs() < 1e-15);
/// ```
pub fn integrate(a: f64, b: f64, parts: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let (x, w) = gl16();
    let mut total = 0.0;
    for (mid, half) in panels(a, b, parts) {
        total += half
            * x.iter()
                .zip(w)
                .map(|(xi, wi)| wi * f(mid + half * xi))
                .sum::<f64>();
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly() {
        let (x, w) = gauss_legendre(16);
        // Exact for degree <= 31: ∫_{-1}^{1} x^30 dx = 2/31.
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(30)).sum();
        assert!((s - 2.0 / 31.0).abs() < 1e-14, "{s}");
        let total: f64 = w.iter().sum();
        assert!((total - 2.0).abs() < 1e-14);
        assert!(x.windows(2).all(|p| p[0] < p[1]));
    }

    #[test]
    fn matches_the_closed_form_rules_of_low_order() {
        // Independent route: the 2- and 4-point rules in closed form.
        let (x, w) = gauss_legendre(2);
        // Newton converges to within a few ulps of the root.
        assert!(
            (x[1] - 1.0 / 3f64.sqrt()).abs() < 4.0 * f64::EPSILON && (w[0] - 1.0).abs() < 1e-15
        );
        let (x, w) = gauss_legendre(4);
        let inner = (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
        let wi = (18.0 + 30f64.sqrt()) / 36.0;
        assert!((x[2] - inner).abs() < 1e-15 && (w[2] - wi).abs() < 1e-15);
        assert_eq!(gl16().0.len(), GL_ORDER);
    }

    #[test]
    fn integrate_splits_into_parts() {
        // ∫_0^1 e^{-500 t} dt = (1 - e^{-500}) / 500, resolved by 100 parts.
        let s = integrate(0.0, 1.0, 100, |t| (-500.0 * t).exp());
        assert!((s - 1.0 / 500.0).abs() < 1e-16, "{s}");
    }
}
