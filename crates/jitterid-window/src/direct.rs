//! The direct DTFT at one frequency, `Σ_k v_k e^{-i2πkx}`, stable for any record length and
//! frequency (the accuracy argument is in the docs of [`crate::dtft`]): the one kernel that the
//! transforms of a record and the windows' kernels both evaluate.

use jitterid_numeric::phase::{cis_neg_cycles, Cycles};
use num_complex::Complex64;

/// Re-anchoring period of the rotation recurrence.
const BLOCK: usize = 64;

/// Neumaier-compensated complex sum.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct CompensatedSum {
    re: f64,
    im: f64,
    c_re: f64,
    c_im: f64,
}

#[inline]
fn neumaier(sum: &mut f64, comp: &mut f64, x: f64) {
    let t = *sum + x;
    if sum.abs() >= x.abs() {
        *comp += (*sum - t) + x;
    } else {
        *comp += (x - t) + *sum;
    }
    *sum = t;
}

impl CompensatedSum {
    #[inline]
    pub(crate) fn add(&mut self, z: Complex64) {
        neumaier(&mut self.re, &mut self.c_re, z.re);
        neumaier(&mut self.im, &mut self.c_im, z.im);
    }

    #[inline]
    pub(crate) fn value(&self) -> Complex64 {
        Complex64::new(self.re + self.c_re, self.im + self.c_im)
    }
}

/// Number of interleaved rotation chains (shorter dependency chains, fewer rounding steps).
const CHAINS: usize = 4;

/// `Σ_k v_k e^{-i2πkx}` for `x` in cycles per sample: `O(N)`, stable for any `N` and `x`.
///
/// Each block of [`BLOCK`] samples starts from a rotation computed directly from the exactly
/// reduced phase `k·x mod 1`; inside a block four interleaved chains advance by `e^{-i2π4x}`, so
/// no rotation is more than 16 multiplications away from a direct evaluation.
pub(crate) fn dtft_at(values: &[f64], x: Cycles) -> Complex64 {
    let one = Complex64::new(1.0, 0.0);
    let offsets = [
        one,
        cis_neg_cycles(x.times(1.0)),
        cis_neg_cycles(x.times(2.0)),
        cis_neg_cycles(x.times(3.0)),
    ];
    let step = cis_neg_cycles(x.times(CHAINS as f64));
    let (sr, si) = (step.re, step.im);
    let mut sum = CompensatedSum::default();
    for (b, chunk) in values.chunks(BLOCK).enumerate() {
        let anchor = cis_neg_cycles(x.times((b * BLOCK) as f64));
        let z = offsets.map(|o| anchor * o);
        let mut zr = z.map(|c| c.re);
        let mut zi = z.map(|c| c.im);
        let mut ar = [0.0; CHAINS];
        let mut ai = [0.0; CHAINS];
        let mut quads = chunk.chunks_exact(CHAINS);
        for quad in &mut quads {
            for j in 0..CHAINS {
                let v = quad[j];
                ar[j] += zr[j] * v;
                ai[j] += zi[j] * v;
                let r = zr[j] * sr - zi[j] * si;
                zi[j] = zr[j] * si + zi[j] * sr;
                zr[j] = r;
            }
        }
        for (j, &v) in quads.remainder().iter().enumerate() {
            ar[j] += zr[j] * v;
            ai[j] += zi[j] * v;
        }
        sum.add(Complex64::new(
            (ar[0] + ar[1]) + (ar[2] + ar[3]),
            (ai[0] + ai[1]) + (ai[2] + ai[3]),
        ));
    }
    sum.value()
}
