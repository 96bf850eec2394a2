//! Discrete-time Fourier transforms of a record: direct (any frequency), FFT (the DFT grid),
//! and [`transform`], which picks between them.
//!
//! Convention: `X(f) = Σ_{k=0}^{N-1} w_k x_k e^{-i2πf kT}`, the phase referred to `k·T`, i.e.
//! to the record's first instant `t0` (the samples are at `t0 + kT`).
//!
//! # Accuracy of the direct DTFT
//!
//! The naive recurrence `z ← z·e^{-i2πfT}` loses about one ulp of phase per step, and
//! computing `f·k·T` directly loses the digits of the product above the unit. Here the phase
//! `f·T` is split exactly into a double-double with a fused multiply-add and reduced modulo 1;
//! every 64 samples the rotation is re-anchored from `k·(fT) mod 1`, itself computed with an
//! exact product (within a block four interleaved chains each advance by `e^{-i2π·4fT}`, at
//! most 16 steps from an anchor), and the 64-term block sums are added with Neumaier's
//! compensated summation.
//! The error is then a few `1e-16 · Σ|w_k x_k|` at most, independent of `N` and `f`. Measured
//! against a compensated direct sum with every phase reduced exactly (`tests/dtft.rs`): below
//! `2e-15 · |X(f)|` (about `1e-18 · Σ|x_k|`) for random data at `N = 10^5` and `N = 10^6`, for
//! `f·k·T` up to `10^7` cycles.

use crate::direct::dtft_at;
use crate::frequencies::FrequencySet;
use crate::window::Window;
use crate::WindowError;
use jitterid_numeric::phase::Cycles;
use jitterid_signal::SampleGrid;
use num_complex::Complex64;
use rustfft::{Fft, FftPlanner};
use std::cell::RefCell;
use std::sync::{Arc, Mutex, OnceLock};

fn check_finite(name: &'static str, values: &[f64]) -> Result<(), WindowError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(WindowError::NonFinite {
            name,
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

fn check_len(name: &'static str, expected: usize, values: &[f64]) -> Result<(), WindowError> {
    if values.len() == expected {
        Ok(())
    } else {
        Err(WindowError::WrongLength {
            name,
            expected,
            got: values.len(),
        })
    }
}

/// `w_k x_k`, or a copy of `x` without weights.
fn weighted(data: &[f64], weights: Option<&[f64]>) -> Vec<f64> {
    match weights {
        Some(w) => data.iter().zip(w).map(|(x, w)| x * w).collect(),
        None => data.to_vec(),
    }
}

/// The direct DTFT `X(f) = Σ_k w_k x_k e^{-i2πf kT}` of a record at arbitrary frequencies.
///
/// `data` (and `weights`, if given) must have length `N = grid.len()` and be finite; the
/// frequencies (Hz) must be finite but may lie anywhere (the transform has period `1/T`).
/// Cost `O(N)` per frequency; accurate to a few `1e-16 · Σ_k |w_k x_k|` for any `N` and `f`
/// (see the module docs).
pub fn dtft(
    grid: &SampleGrid,
    data: &[f64],
    weights: Option<&[f64]>,
    freqs: &[f64],
) -> Result<Vec<Complex64>, WindowError> {
    let n = grid.len();
    check_len("data", n, data)?;
    check_finite("data", data)?;
    if let Some(w) = weights {
        check_len("weights", n, w)?;
        check_finite("weights", w)?;
    }
    if let Some(index) = freqs.iter().position(|f| !f.is_finite()) {
        return Err(WindowError::FrequencyNotFinite {
            index,
            value: freqs[index],
        });
    }
    let v = weighted(data, weights);
    let t = grid.interval();
    Ok(freqs
        .iter()
        .map(|&f| dtft_at(&v, Cycles::new(f, t)))
        .collect())
}

fn planner() -> &'static Mutex<FftPlanner<f64>> {
    static PLANNER: OnceLock<Mutex<FftPlanner<f64>>> = OnceLock::new();
    PLANNER.get_or_init(|| Mutex::new(FftPlanner::new()))
}

/// A forward FFT plan of length `n`, planned once per length and shared.
fn plan(n: usize) -> Arc<dyn Fft<f64>> {
    let mut guard = match planner().lock() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    };
    guard.plan_fft_forward(n)
}

/// `values` as complex numbers, the buffer an FFT works in.
fn complex_buffer(values: &[f64]) -> Vec<Complex64> {
    values.iter().map(|&v| Complex64::new(v, 0.0)).collect()
}

/// Replaces `buffer` (any length, empty included) by its forward DFT
/// `X_j = Σ_k x_k e^{-i2πjk/N}`, with the plan of that length shared with [`transform`] and
/// [`fft_grid`] (a long record's plan is held once).
pub fn fft_in_place(buffer: &mut [Complex64]) {
    if buffer.is_empty() {
        return;
    }
    let fft = plan(buffer.len());
    if buffer.len() < WORKSPACE_MAX_LEN {
        let done = WORKSPACE.with(|w| match w.try_borrow_mut() {
            Ok(mut w) => {
                let scratch = scratch_of(&mut w.scratch, fft.get_inplace_scratch_len());
                fft.process_with_scratch(buffer, scratch);
                true
            }
            Err(_) => false,
        });
        if done {
            return;
        }
    }
    fft.process(buffer);
}

/// Records shorter than this are transformed in a buffer and scratch kept per thread
/// ([`Workspace`]), at most a few MiB; longer ones allocate both per transform and free them
/// at once, so that a long record's peak memory does not carry them between transforms.
const WORKSPACE_MAX_LEN: usize = 1 << 16;

/// The FFT buffer and scratch of the last transform on this thread, reused by the next.
///
/// A fit transforms records of the same length many times per step. Allocating and freeing
/// the two length-`N` buffers each time makes the allocator return the top of its heap to
/// the system and fault it back in on the next transform (for `N` in the tens of thousands,
/// above its initial threshold), which costs more than the FFT itself on a loaded machine.
#[derive(Default)]
struct Workspace {
    buffer: Vec<Complex64>,
    scratch: Vec<Complex64>,
}

/// `scratch`'s first `len` entries, grown to that length if shorter.
fn scratch_of(scratch: &mut Vec<Complex64>, len: usize) -> &mut [Complex64] {
    if scratch.len() < len {
        scratch.resize(len, Complex64::new(0.0, 0.0));
    }
    &mut scratch[..len]
}

thread_local! {
    static WORKSPACE: RefCell<Workspace> = RefCell::new(Workspace::default());
}

/// `f` of the FFT of `values` (length `< WORKSPACE_MAX_LEN`, non-empty), computed in this
/// thread's [`Workspace`]; `None` if the workspace is in use (a transform inside `f`).
fn with_workspace_fft<T>(values: &[f64], f: impl FnOnce(&[Complex64]) -> T) -> Option<T> {
    WORKSPACE.with(|w| {
        let mut w = w.try_borrow_mut().ok()?;
        let fft = plan(values.len());
        let Workspace { buffer, scratch } = &mut *w;
        buffer.clear();
        buffer.extend(values.iter().map(|&v| Complex64::new(v, 0.0)));
        fft.process_with_scratch(buffer, scratch_of(scratch, fft.get_inplace_scratch_len()));
        Some(f(buffer))
    })
}

/// FFT of `values` (any length ≥ 1), unchecked.
fn fft_values(values: &[f64]) -> Vec<Complex64> {
    let mut buffer = complex_buffer(values);
    fft_in_place(&mut buffer);
    buffer
}

/// All `N` DFT-grid values `X(j/(NT)) = Σ_k w_k x_k e^{-i2πjk/N}`, `j = 0..N-1`, by FFT
/// (rustfft; plans are made once per length and shared between calls and threads).
///
/// `data` must be non-empty and finite; `weights`, if given, finite and of the same length.
pub fn fft_grid(data: &[f64], weights: Option<&[f64]>) -> Result<Vec<Complex64>, WindowError> {
    if data.is_empty() {
        return Err(WindowError::Empty { name: "data" });
    }
    check_finite("data", data)?;
    if let Some(w) = weights {
        check_len("weights", data.len(), w)?;
        check_finite("weights", w)?;
    }
    Ok(match weights {
        Some(_) => fft_values(&weighted(data, weights)),
        None => fft_values(data),
    })
}

/// Whether the FFT beats `m` direct DTFTs of length `n`.
fn fft_pays(m: usize, n: usize) -> bool {
    m as f64 > 2.0 * (n as f64).log2().max(1.0)
}

/// The windowed transform `Y_w(f) = Σ_k w_k y_k e^{-i2πf kT}` of a record at the frequencies of
/// a set, one output per frequency, in the set's order.
///
/// When the set lies on the DFT grid of this record and has more than about `2 log2 N`
/// frequencies, one FFT is used and only the requested bins are kept; otherwise each frequency
/// is a direct [`dtft`]. `data` must have length `N` and be finite; a vector passed by value
/// is freed before the FFT runs, which lowers the peak memory of a long record.
pub fn transform<W: Window + ?Sized, D: AsRef<[f64]>>(
    grid: &SampleGrid,
    window: &W,
    data: D,
    freqs: &FrequencySet,
) -> Result<Vec<Complex64>, WindowError> {
    let n = grid.len();
    check_len("data", n, data.as_ref())?;
    check_finite("data", data.as_ref())?;
    if window.is_rectangular() {
        return Ok(transform_weighted(grid, data, freqs));
    }
    let w = window.weights(n);
    check_len("weights", n, &w)?;
    check_finite("weights", &w)?;
    let values = weighted(data.as_ref(), Some(&w));
    drop(data);
    Ok(transform_weighted(grid, values, freqs))
}

/// [`transform`] without validation: wrong lengths or non-finite values give NaN outputs.
pub(crate) fn transform_unchecked<W: Window + ?Sized>(
    grid: &SampleGrid,
    window: &W,
    data: &[f64],
    freqs: &FrequencySet,
) -> Vec<Complex64> {
    let n = grid.len();
    if data.len() != n {
        return vec![Complex64::new(f64::NAN, f64::NAN); freqs.len()];
    }
    if window.is_rectangular() {
        return transform_weighted(grid, data, freqs);
    }
    let w = window.weights(n);
    if w.len() != n {
        return vec![Complex64::new(f64::NAN, f64::NAN); freqs.len()];
    }
    transform_weighted(grid, weighted(data, Some(&w)), freqs)
}

/// The transform of already weighted values of length `N`.
///
/// A set of the first bins in order (the half DFT grid) keeps that prefix of the spectrum in
/// place rather than copying it, so a long record holds one length-`N` buffer, not two.
fn transform_weighted<V: AsRef<[f64]>>(
    grid: &SampleGrid,
    values: V,
    freqs: &FrequencySet,
) -> Vec<Complex64> {
    let n = values.as_ref().len();
    if let Some(indices) = freqs.dft_indices() {
        if freqs.fits(grid) && fft_pays(freqs.len(), n) {
            if n < WORKSPACE_MAX_LEN {
                let kept =
                    with_workspace_fft(values.as_ref(), |spectrum| select_bins(spectrum, indices));
                if let Some(kept) = kept {
                    return kept;
                }
            }
            let mut spectrum = complex_buffer(values.as_ref());
            // An owned input is no longer needed once copied: free it before the FFT's scratch.
            drop(values);
            fft_in_place(&mut spectrum);
            let prefix =
                indices.len() <= spectrum.len() && indices.iter().enumerate().all(|(i, &j)| i == j);
            if prefix {
                spectrum.truncate(indices.len());
                spectrum.shrink_to_fit();
                return spectrum;
            }
            return indices
                .iter()
                .map(|&j| {
                    spectrum
                        .get(j)
                        .copied()
                        .unwrap_or(Complex64::new(f64::NAN, f64::NAN))
                })
                .collect();
        }
    }
    let t = grid.interval();
    freqs
        .frequencies()
        .iter()
        .map(|&f| dtft_at(values.as_ref(), Cycles::new(f, t)))
        .collect()
}

/// The bins `indices` of a spectrum (NaN for a bin past its end); the first bins in order (the
/// half DFT grid) as one copy of that prefix.
fn select_bins(spectrum: &[Complex64], indices: &[usize]) -> Vec<Complex64> {
    let prefix =
        indices.len() <= spectrum.len() && indices.iter().enumerate().all(|(i, &j)| i == j);
    if prefix {
        return spectrum[..indices.len()].to_vec();
    }
    indices
        .iter()
        .map(|&j| {
            spectrum
                .get(j)
                .copied()
                .unwrap_or(Complex64::new(f64::NAN, f64::NAN))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DirichletWindow, HannWindow};

    #[test]
    fn errors_name_the_offender() {
        let g = SampleGrid::new(0.0, 1.0, 3).unwrap();
        assert_eq!(
            dtft(&g, &[1.0, 2.0], None, &[0.1]),
            Err(WindowError::WrongLength {
                name: "data",
                expected: 3,
                got: 2
            })
        );
        assert!(matches!(
            dtft(&g, &[1.0, f64::NAN, 0.0], None, &[0.1]),
            Err(WindowError::NonFinite {
                name: "data",
                index: 1,
                ..
            })
        ));
        assert!(matches!(
            dtft(&g, &[1.0, 2.0, 3.0], Some(&[1.0]), &[0.1]),
            Err(WindowError::WrongLength {
                name: "weights",
                ..
            })
        ));
        assert!(matches!(
            dtft(&g, &[1.0, 2.0, 3.0], None, &[f64::NAN]),
            Err(WindowError::FrequencyNotFinite { index: 0, .. })
        ));
        assert!(matches!(
            fft_grid(&[], None),
            Err(WindowError::Empty { name: "data" })
        ));
        let s = FrequencySet::dft(&g);
        assert!(matches!(
            transform(&g, &HannWindow, [1.0, f64::INFINITY, 0.0], &s),
            Err(WindowError::NonFinite {
                name: "data",
                index: 1,
                ..
            })
        ));
    }

    #[test]
    fn workspace_transform_equals_an_allocating_fft() {
        // The per-thread buffers are reused across lengths (longer, then shorter, then longer
        // again) and must give bit for bit the FFT of freshly allocated ones (lengths where the
        // half grid is taken by FFT, not by direct sums).
        for n in [1000, 20_000, 999, 64, 20_000] {
            let g = SampleGrid::new(0.0, 1.0, n).unwrap();
            let x: Vec<f64> = (0..n).map(|k| ((k * k) % 97) as f64 - 48.0).collect();
            let mut want = complex_buffer(&x);
            plan(n).process(&mut want);
            let half = transform(&g, &DirichletWindow, &x, &FrequencySet::dft(&g)).unwrap();
            assert_eq!(half.len(), n / 2 + 1);
            assert!(half.iter().zip(&want).all(|(a, b)| a == b), "N = {n}");
            let mut got = complex_buffer(&x);
            fft_in_place(&mut got);
            assert_eq!(got, want, "N = {n}");
        }
    }

    #[test]
    fn small_dtft_by_hand() {
        let g = SampleGrid::new(5.0, 0.5, 2).unwrap();
        // X(f) = 1 + 2 e^{-i2π f 0.5}; at f = 0.5 Hz: 1 + 2 e^{-iπ/2} = 1 - 2i.
        let x = dtft(&g, &[1.0, 2.0], None, &[0.5]).unwrap();
        assert!((x[0] - Complex64::new(1.0, -2.0)).norm() < 1e-15);
        let s = FrequencySet::full_dft(&g);
        let y = transform(&g, &DirichletWindow, [1.0, 2.0], &s).unwrap();
        assert!((y[1] - Complex64::new(-1.0, 0.0)).norm() < 1e-15);
    }
}
