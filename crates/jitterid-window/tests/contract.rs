//! `testing::check_contract` on every window of the crate, on the provided `O(N)` kernel, and
//! on broken windows that it must reject.

use jitterid_signal::SampleGrid;
use jitterid_window::testing::check_contract;
use jitterid_window::{Complex64, DirichletWindow, HannWindow, Window};

/// The provided kernel of a window, bypassing its closed form.
#[derive(Debug)]
struct Generic<W>(W);
impl<W: Window> Window for Generic<W> {
    fn weight(&self, k: usize, n: usize) -> f64 {
        self.0.weight(k, n)
    }
}

#[test]
fn every_shipped_window_meets_the_contract() {
    for w in [&DirichletWindow as &dyn Window, &HannWindow] {
        check_contract(w).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn the_provided_kernel_meets_the_contract() {
    check_contract(&Generic(DirichletWindow)).unwrap();
    check_contract(&Generic(HannWindow)).unwrap();
    // An asymmetric taper with arbitrary weights: the generic kernel has no symmetry to lean on.
    #[derive(Debug)]
    struct Ramp;
    impl Window for Ramp {
        fn weight(&self, k: usize, n: usize) -> f64 {
            if k < n {
                0.3 + (k as f64 * 0.737).sin().abs() * (k + 1) as f64 / n as f64
            } else {
                0.0
            }
        }
    }
    check_contract(&Ramp).unwrap();
}

#[test]
fn a_wrong_closed_form_kernel_is_caught() {
    // The symmetric Hann weights with the periodic window's closed-form kernel.
    #[derive(Debug)]
    struct Mismatched;
    impl Window for Mismatched {
        fn weight(&self, k: usize, n: usize) -> f64 {
            if k >= n || n < 2 {
                return f64::from(u8::from(k < n));
            }
            let s = (std::f64::consts::PI * k as f64 / (n - 1) as f64).sin();
            s * s
        }
        fn kernel(&self, grid: &SampleGrid, nu: f64) -> Complex64 {
            HannWindow.kernel(grid, nu)
        }
    }
    let err = check_contract(&Mismatched).unwrap_err();
    assert!(err.contains("kernel(N = "), "{err}");
}

#[test]
fn a_false_rectangular_claim_and_a_weight_beyond_the_record_are_caught() {
    #[derive(Debug)]
    struct Sloppy;
    impl Window for Sloppy {
        fn weight(&self, _k: usize, _n: usize) -> f64 {
            0.5
        }
        fn is_rectangular(&self) -> bool {
            true
        }
    }
    let err = check_contract(&Sloppy).unwrap_err();
    assert!(err.contains("is_rectangular()"), "{err}");
    assert!(err.contains("not 0 beyond the record"), "{err}");
}
