//! The 17-point Clenshaw–Curtis rule: a closed rule (it evaluates both ends of the interval)
//! that, beside the open 16-point Gauss–Legendre rule of [`gauss`](crate::gauss), lets an
//! adaptive reference integration see a jump that lies next to a bisection point.

use std::sync::OnceLock;

/// Nodes `cos(kπ/16)` and weights of the 17-point Clenshaw–Curtis rule on `[-1, 1]`, computed
/// once.
///
/// ```
/// let (x, w) = jitterid_numeric::clenshaw_curtis::cc17();
/// assert_eq!((x[0], x[16]), (1.0, -1.0));
/// assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-15);
/// ```
pub fn cc17() -> &'static (Vec<f64>, Vec<f64>) {
    static RULE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    RULE.get_or_init(|| {
        const N: usize = 16;
        let theta = |k: usize| k as f64 * std::f64::consts::PI / N as f64;
        let nodes = (0..=N).map(|k| theta(k).cos()).collect();
        let weights = (0..=N)
            .map(|k| {
                let sum: f64 = (1..=N / 2)
                    .map(|j| {
                        let b = if j == N / 2 { 1.0 } else { 2.0 };
                        b / (4.0 * (j * j) as f64 - 1.0) * (2.0 * j as f64 * theta(k)).cos()
                    })
                    .sum();
                let c = if k == 0 || k == N { 1.0 } else { 2.0 };
                c / N as f64 * (1.0 - sum)
            })
            .collect();
        (nodes, weights)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_to_degree_17() {
        // A 17-point Clenshaw–Curtis rule is exact for polynomials of degree ≤ 17 (odd ones by
        // symmetry): ∫_{-1}^{1} x^16 dx = 2/17.
        let (x, w) = cc17();
        let s: f64 = x.iter().zip(w).map(|(x, w)| w * x.powi(16)).sum();
        assert!((s - 2.0 / 17.0).abs() < 1e-15, "{s}");
        let odd: f64 = x.iter().zip(w).map(|(x, w)| w * x.powi(17)).sum();
        assert!(odd.abs() < 1e-15);
    }
}
