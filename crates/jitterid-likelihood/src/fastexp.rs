//! `e^q` for `q ≤ 0` in straight-line arithmetic, so that the likelihood's loops over
//! quadrature nodes compile to vector instructions.
//!
//! The exact likelihood takes one exponential per node, and a call to the C library's `exp`
//! per node cost about as much as the rest of the node's work together. Here `q = k ln 2 + r`
//! with `k` rounded to the nearest integer (by adding `1.5 · 2⁵²`, which also leaves `k` in the
//! low bits of the sum), `|r| ≤ ½ ln 2`, `e^r` by its Taylor polynomial of degree 13
//! (truncation below `5e-18` relative), and `2^k` assembled from `k`'s bits. Only additions,
//! multiplications and integer operations, no branches and no fused multiply–add, so the
//! result is the same on every x86-64 or other IEEE machine and for any vector width. A test
//! bounds the error at 2 ulp of the library's value.

/// `log₂ e`.
const LOG2E: f64 = std::f64::consts::LOG2_E;
/// `ln 2` split so that `k · LN2_HI` is exact for `|k| < 2¹¹` (fdlibm's constants).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// `1.5 · 2⁵²`: adding it rounds to an integer held in the low mantissa bits.
const ROUND: f64 = 6_755_399_441_055_744.0;

/// Below this `q` the callers take `e^q` as 0: `2^k` would not be a normal number, and such a
/// term is below `1e-307` of the largest one, which is 1.
pub(crate) const EXP_FLOOR: f64 = -708.0;

/// `e^q` for `EXP_FLOOR ≤ q ≤ 0` (any other finite `q` gives a meaningless but finite value,
/// which callers select away).
#[inline(always)]
pub(crate) fn exp_nonpositive(q: f64) -> f64 {
    let t = q * LOG2E + ROUND;
    let k = t - ROUND;
    let r = (q - k * LN2_HI) - k * LN2_LO;
    // Taylor coefficients 1/j!, j = 13 down to 0.
    const C: [f64; 14] = [
        1.0 / 6_227_020_800.0,
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ];
    let mut p = C[0];
    for &c in &C[1..] {
        p = p * r + c;
    }
    // The low 12 bits of `t`'s representation are `k` (two's complement); `k + 1023` is the
    // biased exponent of `2^k`.
    let scale = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    p * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        let spacing = f64::from_bits(b.to_bits() + 1) - b;
        (a - b).abs() / spacing
    }

    #[test]
    fn within_two_ulp_of_the_library_exp_on_its_range() {
        // A dense sweep of [EXP_FLOOR, 0] plus the points around every multiple of ln 2 / 2
        // (where the rounding of k switches).
        let mut worst: f64 = 0.0;
        let n = 2_000_000;
        for i in 0..=n {
            let q = EXP_FLOOR * f64::from(i) / f64::from(n);
            worst = worst.max(ulps(exp_nonpositive(q), q.exp()));
        }
        for j in 0..=2043 {
            let q0 = -f64::from(j) * std::f64::consts::LN_2 / 2.0;
            for d in [-1e-12, 0.0, 1e-12] {
                let q = (q0 + d).min(0.0);
                if q >= EXP_FLOOR {
                    worst = worst.max(ulps(exp_nonpositive(q), q.exp()));
                }
            }
        }
        assert!(worst <= 2.0, "worst error {worst} ulp");
    }

    #[test]
    fn exact_at_zero_and_small_arguments() {
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(-0.0), 1.0);
        for q in [-1e-300, -1e-17, -1e-9] {
            assert!(ulps(exp_nonpositive(q), q.exp()) <= 1.0, "{q}");
        }
    }
}
