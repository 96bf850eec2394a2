//! The restricted noise likelihood's FFT autocovariance (jitterid-estimate) against the
//! likelihood layer's direct sums (moved here from `restricted_noise.rs`'s unit tests, which
//! cannot see this crate).

use jitterid_estimate::support::measurement_autocovariance;
use jitterid_estimate::ArmaNoise;
use jitterid_likelihood::noise_autocovariance;

const PHI: f64 = 0.6;

#[test]
fn the_fft_autocovariance_is_the_direct_sums() {
    let noise = ArmaNoise::new(vec![0.3], vec![-PHI, 0.2]).unwrap();
    let fast = measurement_autocovariance(&noise, 0.5, 300);
    let direct = noise_autocovariance(&noise, 0.5, 300);
    for (a, b) in fast.iter().zip(&direct) {
        assert!((a - b).abs() <= 1e-12 * direct[0], "{a} vs {b}");
    }
}
