//! The representable range: the values for which samples, their moments and their squares
//! stay finite (and meaningful) in double precision. Each bound is relative to the sampling
//! grid where the physics is: a pole is "fast" or "slow" only against `T` and the record's
//! duration `NT`.

use jitterid::signal::{RationalModel, Root, SampleGrid};

/// Smallest sampling interval `T` (s): below it, `t0 + kT` loses the grid in rounding long
/// before the samples run out (and `1e-320` is a subnormal with no precision left).
pub const MIN_INTERVAL: f64 = 1e-15;
/// Largest sampling interval `T` (s).
pub const MAX_INTERVAL: f64 = 1e15;
/// Largest magnitude of a level (gain, amplitude, input level, noise level, and the system's
/// step response): a level times a level, and its square, stay far from overflow.
pub const MAX_LEVEL: f64 = 1e50;
/// Smallest magnitude of a gain or a signal amplitude: a system that gives no signal has
/// nothing to identify.
pub const MIN_GAIN: f64 = 1e-50;
/// Largest `|root|·T` of a pole or zero: a mode that decays within `10⁻⁶ T`.
pub const MAX_ROOT_T: f64 = 1e6;
/// Smallest `|pole|·NT`: slower modes are integrators over the record, and their response
/// `(1 − e^{pt})/p` loses every digit to cancellation.
pub const MIN_POLE_NT: f64 = 1e-6;
/// Smallest jitter time scale (width, standard deviation, mean delay), relative to `T`.
pub const MIN_WIDTH_T: f64 = 1e-9;
/// Largest jitter time scale or offset, relative to `T`.
pub const MAX_WIDTH_T: f64 = 1e3;
/// Largest `f·T` of a tone (input or sinusoid system).
pub const MAX_FREQUENCY_T: f64 = 1e6;

/// Whether a level is within [`MAX_LEVEL`]; the message says what is expected.
pub(super) fn level(x: f64) -> Result<f64, String> {
    if x.abs() <= MAX_LEVEL {
        Ok(x)
    } else {
        Err(format!(
            "expected a magnitude of at most {MAX_LEVEL:e}, found {x:e}"
        ))
    }
}

/// A gain or signal amplitude: nonzero, magnitude in `[MIN_GAIN, MAX_LEVEL]`.
pub(super) fn gain(x: f64) -> Result<f64, String> {
    if x == 0.0 {
        return Err("expected a nonzero value (a zero gain gives no signal to identify)".into());
    }
    if (MIN_GAIN..=MAX_LEVEL).contains(&x.abs()) {
        Ok(x)
    } else {
        Err(format!(
            "expected a magnitude in [{MIN_GAIN:e}, {MAX_LEVEL:e}], found {x:e}"
        ))
    }
}

/// A jitter time scale `x` (s) for the grid's `T`: in `[MIN_WIDTH_T·T, MAX_WIDTH_T·T]`.
pub(super) fn width(x: f64, grid: &SampleGrid) -> Result<f64, String> {
    let t = grid.interval();
    let (lo, hi) = (MIN_WIDTH_T * t, MAX_WIDTH_T * t);
    if (lo..=hi).contains(&x) {
        Ok(x)
    } else {
        Err(format!(
            "expected a time scale in [{lo:e}, {hi:e}] s ({MIN_WIDTH_T:e} to {MAX_WIDTH_T:e} sampling intervals), found {x:e}"
        ))
    }
}

/// A jitter offset (s): magnitude at most `MAX_WIDTH_T·T`.
pub(super) fn offset(x: f64, grid: &SampleGrid) -> Result<f64, String> {
    let hi = MAX_WIDTH_T * grid.interval();
    if x.abs() <= hi {
        Ok(x)
    } else {
        Err(format!(
            "expected an offset of magnitude at most {hi:e} s ({MAX_WIDTH_T:e} sampling intervals), found {x:e}"
        ))
    }
}

/// A tone's frequency (Hz): `f·T` at most [`MAX_FREQUENCY_T`].
pub(super) fn frequency(f: f64, grid: &SampleGrid) -> Result<f64, String> {
    let hi = MAX_FREQUENCY_T / grid.interval();
    if f <= hi {
        Ok(f)
    } else {
        Err(format!(
            "expected a frequency of at most {hi:e} Hz ({MAX_FREQUENCY_T:e}/T), found {f:e}"
        ))
    }
}

/// Zeros: `|z|·T` at most [`MAX_ROOT_T`] (a zero at 0 is exact and allowed).
pub(super) fn zeros(roots: &[Root], grid: &SampleGrid) -> Result<(), String> {
    let hi = MAX_ROOT_T / grid.interval();
    match roots.iter().position(|r| r.modulus() > hi) {
        Some(i) => Err(format!(
            "element {}: expected a magnitude of at most {hi:e} rad/s ({MAX_ROOT_T:e}/T), found {:e}",
            i + 1,
            roots[i].modulus()
        )),
        None => Ok(()),
    }
}

/// Poles: `|p|` in `[MIN_POLE_NT/(NT), MAX_ROOT_T/T]`.
pub(super) fn poles(
    moduli: impl IntoIterator<Item = f64>,
    grid: &SampleGrid,
) -> Result<(), String> {
    let hi = MAX_ROOT_T / grid.interval();
    let lo = MIN_POLE_NT / grid.duration();
    for (i, m) in moduli.into_iter().enumerate() {
        // A pole exactly at 0 is an exact integrator, left to the model's own check.
        if m != 0.0 && !(lo..=hi).contains(&m) {
            return Err(format!(
                "pole {}: expected a magnitude in [{lo:e}, {hi:e}] rad/s ({MIN_POLE_NT:e}/(NT) to {MAX_ROOT_T:e}/T), found {m:e}",
                i + 1
            ));
        }
    }
    Ok(())
}

/// The pole moduli of a zpk model's roots.
pub(super) fn root_moduli(roots: &[Root]) -> Vec<f64> {
    // A quadratic factor's two roots each (a pair's two have one modulus).
    roots
        .iter()
        .flat_map(|r| match r {
            Root::Quadratic { .. } => r.values().iter().map(|v| v.norm()).collect(),
            _ => vec![r.modulus()],
        })
        .collect()
}

/// A rational system's poles in range and its step response representable: every mode's
/// contribution `|r_i/p_i|` and the feed-through at most [`MAX_LEVEL`].
pub(super) fn response<M: RationalModel>(m: &M, grid: &SampleGrid) -> Result<(), String> {
    poles(m.rational().poles().iter().map(|p| p.norm()), grid)?;
    // Repeated poles and integrators have no modal form (their steps grow without bound
    // or have no separate modes): only the range of the poles applies.
    let Some(modal) = m.modal() else {
        return Ok(());
    };
    let worst = modal
        .residues
        .iter()
        .zip(&modal.poles)
        .map(|(r, p)| (r / p).norm())
        .chain([modal.direct.abs(), modal.dc_gain.abs()])
        .fold(0.0, f64::max);
    if worst.is_finite() && worst <= MAX_LEVEL {
        Ok(())
    } else {
        Err(format!(
            "the system's step response reaches {worst:e}, beyond the representable {MAX_LEVEL:e}"
        ))
    }
}

/// Largest input history, in records: an input that ran longer before `t0` left only its
/// settled state, which a shorter history reaches as well.
pub const MAX_HISTORY_RECORDS: f64 = 1e3;

/// An input delay `D` (s): in `[0, (N+1)T]`, so that some of the input reaches the record.
pub(super) fn delay(d: f64, grid: &SampleGrid) -> Result<f64, String> {
    let (a, b) = crate::inputs::input_span(grid);
    let hi = b - a;
    if (0.0..=hi).contains(&d) {
        Ok(d)
    } else {
        Err(format!(
            "expected a delay in [0, {hi}] s (at most the input's span (N+1)T), found {d:e}"
        ))
    }
}

/// An input history `H` (s): in `[0, MAX_HISTORY_RECORDS·(N+1)T]`.
pub(super) fn history(h: f64, grid: &SampleGrid) -> Result<f64, String> {
    let (a, b) = crate::inputs::input_span(grid);
    let hi = MAX_HISTORY_RECORDS * (b - a);
    if (0.0..=hi).contains(&h) {
        Ok(h)
    } else {
        Err(format!(
            "expected a history in [0, {hi:e}] s (at most {MAX_HISTORY_RECORDS:e} input spans (N+1)T), found {h:e}"
        ))
    }
}
