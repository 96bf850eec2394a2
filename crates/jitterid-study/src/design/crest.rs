//! A multisine's peak and the phases that keep it low: the crest factor `max|u| / rms`.
//!
//! A signal generator's range bounds the peak, not the power; the lower the crest factor,
//! the more power (and so information) the same range carries. Schroeder's phases (a chirp's
//! group delay, spread over the record by each tone's share of the power) are the classical
//! start; the clipping algorithm of van der Ouderaa, Schoukens and Renneboog (1988) then
//! lowers the crest further: clip the signal below its peak, keep the phases of the clipped
//! signal's spectrum at the tones and restore their amplitudes, repeat. It is deterministic,
//! and the best phases seen are kept, so the result is never worse than Schroeder's.

use jitterid::signal::Tone;
use std::f64::consts::TAU;

/// Clipping iterations after Schroeder's phases.
const CLIP_ITERATIONS: usize = 60;

/// Points per period of the highest tone when a peak is searched on a grid (before the
/// Newton refinement of the grid's maxima).
const POINTS_PER_PERIOD: f64 = 32.0;

/// Most grid points of a peak search.
const MAX_POINTS: usize = 1 << 20;

/// `u(t) = Σ aᵢ sin(2π fᵢ t + φᵢ)` and its first two derivatives.
fn value3(tones: &[Tone], t: f64) -> (f64, f64, f64) {
    let mut out = (0.0, 0.0, 0.0);
    for tone in tones {
        let w = TAU * tone.frequency;
        let (s, c) = (w * t + tone.phase).sin_cos();
        out.0 += tone.amplitude * s;
        out.1 += tone.amplitude * w * c;
        out.2 -= tone.amplitude * w * w * s;
    }
    out
}

/// The peak `max |u(t)|` of the tones over `[a, b]`: a grid of 32 points per
/// period of the highest tone, then Newton's method on `u′ = 0` from every grid maximum within
/// a percent of the largest (the continuous maximum lies within a grid step of one of them).
pub fn peak(tones: &[Tone], (a, b): (f64, f64)) -> f64 {
    let fmax = tones.iter().map(|t| t.frequency).fold(0.0, f64::max);
    let points = ((b - a) * fmax * POINTS_PER_PERIOD).ceil() as usize;
    let points = points.clamp(64, MAX_POINTS);
    let h = (b - a) / points as f64;
    let values: Vec<f64> = (0..=points)
        .map(|m| value3(tones, a + h * m as f64).0.abs())
        .collect();
    let grid_max = values.iter().copied().fold(0.0, f64::max);
    let mut best = grid_max;
    for (m, &v) in values.iter().enumerate() {
        let left = if m > 0 { values[m - 1] } else { 0.0 };
        let right = values.get(m + 1).copied().unwrap_or(0.0);
        if v < 0.99 * grid_max || v < left || v < right {
            continue;
        }
        let t0 = a + h * m as f64;
        let mut t = t0;
        for _ in 0..8 {
            let (_, d1, d2) = value3(tones, t);
            if d2 == 0.0 {
                break;
            }
            // A step beyond the grid cell would leave this maximum's basin.
            t = (t - d1 / d2).clamp((t0 - h).max(a), (t0 + h).min(b));
        }
        best = best.max(value3(tones, t).0.abs());
    }
    best
}

/// The root mean square `√(Σ aᵢ²/2)` of tones at distinct nonzero frequencies.
pub fn rms(tones: &[Tone]) -> f64 {
    tones
        .iter()
        .map(|t| t.amplitude * t.amplitude / 2.0)
        .sum::<f64>()
        .sqrt()
}

/// Schroeder's phases for tones at harmonics `k` (increasing) with power shares `share`
/// (summing to 1): `φⱼ = −2π Σ_{l<j} share_l (kⱼ − k_l)`, the phases of a chirp that spends
/// each tone's share of the period at it, wrapped to `(−π, π]`.
pub fn schroeder_phases(k: &[u64], share: &[f64]) -> Vec<f64> {
    (0..k.len())
        .map(|j| {
            let s: f64 = (0..j).map(|l| share[l] * (k[j] - k[l]) as f64).sum();
            wrap(-TAU * s)
        })
        .collect()
}

/// A phase wrapped to `(−π, π]`.
fn wrap(phase: f64) -> f64 {
    let p = phase.rem_euclid(TAU);
    if p > std::f64::consts::PI {
        p - TAU
    } else {
        p
    }
}

/// Tones at harmonics `k` of `f0` with amplitudes `amplitudes` and phases `phases`.
pub fn harmonic_tones(f0: f64, k: &[u64], amplitudes: &[f64], phases: &[f64]) -> Vec<Tone> {
    k.iter()
        .zip(amplitudes)
        .zip(phases)
        .map(|((&k, &amplitude), &phase)| Tone {
            frequency: k as f64 * f0,
            amplitude,
            phase,
        })
        .collect()
}

/// Phases of the harmonics `k` with `amplitudes` that lower the crest factor: Schroeder's,
/// then 60 iterations of the clipping algorithm on one period sampled at `M` points
/// (`M > 2 max k`, so the tones are exact on the grid), keeping the best phases by the grid's
/// peak. Deterministic.
pub fn low_crest_phases(k: &[u64], amplitudes: &[f64]) -> Vec<f64> {
    let total: f64 = amplitudes.iter().map(|a| a * a).sum();
    if k.len() < 2 || !(total > 0.0) {
        return vec![0.0; k.len()];
    }
    let share: Vec<f64> = amplitudes.iter().map(|a| a * a / total).collect();
    let kmax = k.iter().copied().max().unwrap_or(1) as usize;
    let m = (kmax * POINTS_PER_PERIOD as usize).clamp(64, MAX_POINTS);
    // sin and cos of 2π k_j m / M, for the synthesis and the projection.
    let basis: Vec<Vec<(f64, f64)>> = k
        .iter()
        .map(|&kj| {
            (0..m)
                .map(|i| (TAU * ((kj as usize * i) % m) as f64 / m as f64).sin_cos())
                .collect()
        })
        .collect();
    let synth = |phases: &[f64]| -> Vec<f64> {
        let mut u = vec![0.0; m];
        for (j, b) in basis.iter().enumerate() {
            let (sp, cp) = phases[j].sin_cos();
            let a = amplitudes[j];
            for (ui, &(s, c)) in u.iter_mut().zip(b) {
                // sin(θ + φ) = sin θ cos φ + cos θ sin φ
                *ui += a * (s * cp + c * sp);
            }
        }
        u
    };
    let grid_peak = |u: &[f64]| u.iter().fold(0.0_f64, |p, x| p.max(x.abs()));
    let mut phases = schroeder_phases(k, &share);
    let mut best = (grid_peak(&synth(&phases)), phases.clone());
    for _ in 0..CLIP_ITERATIONS {
        let u = synth(&phases);
        let level = 0.9 * grid_peak(&u);
        // The clipped signal's coefficient at each tone: X = Σ u e^{−iθ} / M = a e^{iφ}/(2i),
        // so φ = arg(i X).
        phases = basis
            .iter()
            .map(|b| {
                let (mut re, mut im) = (0.0, 0.0);
                for (x, &(s, c)) in u.iter().zip(b) {
                    let x = x.clamp(-level, level);
                    re += x * c;
                    im -= x * s;
                }
                re.atan2(-im)
            })
            .collect();
        let p = grid_peak(&synth(&phases));
        if p < best.0 {
            best = (p, phases.clone());
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Schroeder's phases on a flat spectrum are far below zero phases' crest (√(2K)), and
    /// the clipping improves on Schroeder's.
    #[test]
    fn clipping_lowers_schroeder_s_crest_factor() {
        let k: Vec<u64> = (1..=16).collect();
        let a = vec![1.0; 16];
        let crest = |ph: &[f64]| {
            let t = harmonic_tones(1.0, &k, &a, ph);
            peak(&t, (0.0, 1.0)) / rms(&t)
        };
        let zero = crest(&[0.0; 16]);
        let schroeder = crest(&schroeder_phases(&k, &[1.0 / 16.0; 16]));
        let clipped = crest(&low_crest_phases(&k, &a));
        assert!(schroeder < 0.5 * zero, "{schroeder} vs {zero}");
        assert!(clipped < schroeder, "{clipped} vs {schroeder}");
    }

    /// The peak of one tone is its amplitude, found between grid points.
    #[test]
    fn the_peak_of_a_tone_is_its_amplitude() {
        let t = [Tone {
            frequency: 0.37,
            amplitude: 2.5,
            phase: 0.3,
        }];
        assert!((peak(&t, (0.0, 10.0)) - 2.5).abs() < 1e-12);
    }
}
