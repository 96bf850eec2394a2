//! The fitted system's Bode diagram (dB and degrees) and unit-step response with their ±2σ
//! bands, as `fit --plot` and `validate --plot` draw them from the study layer's points (the
//! points of `validate --bode`), with curves of other models and the data to compare.

use super::samples_series;
use crate::svg::{figure, Panel, Series, BLUE, GREY};
use jitterid::estimate::validation::{BodePoint, StepPoint};
use jitterid::num_complex::Complex64;

/// Another model's curve drawn beside the fitted one, without a band.
pub(super) struct Compared<P> {
    /// Legend label.
    pub label: String,
    /// Colour.
    pub color: &'static str,
    /// Dashed or solid.
    pub dashed: bool,
    /// Its points, on the fitted curve's abscissae.
    pub points: Vec<P>,
}

impl<P> Compared<P> {
    fn series(&self, xy: impl Fn(&P) -> (f64, f64)) -> Series {
        let pts = self.points.iter().map(xy).collect();
        if self.dashed {
            Series::dashed(&self.label, self.color, pts)
        } else {
            Series::line(&self.label, self.color, pts)
        }
    }
}

/// A central curve and, when every point has both edges, its band.
fn with_band(
    label: &str,
    centre: Vec<(f64, f64)>,
    band: Option<Vec<(f64, f64, f64)>>,
) -> Vec<Series> {
    let mut v = Vec::new();
    if let Some(b) = band {
        v.push(Series::band("±2σ band (parameter covariance)", BLUE, &b));
    }
    v.push(Series::line(label, BLUE, centre));
    v
}

/// The edges `(x, lo, hi)` of a band, `None` when a point has none (no covariance).
fn band_edges(
    points: impl Iterator<Item = (f64, Option<f64>, Option<f64>)>,
) -> Option<Vec<(f64, f64, f64)>> {
    points.map(|(x, lo, hi)| Some((x, lo?, hi?))).collect()
}

/// The note on a figure whose bands are missing.
fn band_note(has_band: bool, title: &str) -> String {
    if has_band {
        title.to_string()
    } else {
        format!("{title} — no covariance, so no bands")
    }
}

/// `arg z` in degrees, shifted by whole turns to lie within 180° of `near` (a noisy data
/// point's phase is only known modulo 360°; shown beside the model's unwrapped phase).
fn phase_near(z: Complex64, near: f64) -> f64 {
    let p = z.arg().to_degrees();
    p + 360.0 * ((near - p) / 360.0).round()
}

/// The fitted phase at `f`, interpolated in `log f` between the fitted points (held at the
/// ends).
fn phase_at(points: &[BodePoint], f: f64) -> f64 {
    let i = points.partition_point(|p| p.f_hz < f);
    match (i.checked_sub(1).and_then(|j| points.get(j)), points.get(i)) {
        (Some(a), Some(b)) if b.f_hz > a.f_hz && f > 0.0 => {
            let w = (f / a.f_hz).ln() / (b.f_hz / a.f_hz).ln();
            a.phase_deg + w * (b.phase_deg - a.phase_deg)
        }
        (Some(a), _) => a.phase_deg,
        (None, Some(b)) => b.phase_deg,
        (None, None) => 0.0,
    }
}

/// Magnitude (dB) and phase (degrees) of the fitted system with their ±2σ bands, over the
/// data's empirical transfer function `Y/U` (points `(f, Y(f)/U(f))`, if any) and beside the
/// `compared` models.
pub(super) fn bode_figure(
    fitted: (&str, &[BodePoint]),
    compared: &[Compared<BodePoint>],
    data: &[(f64, Complex64)],
    heading: &str,
    title: &str,
) -> String {
    let (label, points) = fitted;
    let mag_band = band_edges(
        points
            .iter()
            .map(|p| (p.f_hz, p.magnitude_db_lo, p.magnitude_db_hi)),
    );
    let ph_band = band_edges(
        points
            .iter()
            .map(|p| (p.f_hz, p.phase_deg_lo, p.phase_deg_hi)),
    );
    let has_band = mag_band.is_some();
    let mut mag = Vec::new();
    let mut ph = Vec::new();
    if !data.is_empty() {
        let db = data.iter().map(|(f, z)| (*f, 20.0 * z.norm().log10()));
        let deg = data
            .iter()
            .map(|(f, z)| (*f, phase_near(*z, phase_at(points, *f))));
        mag.push(samples_series("data Y/U", GREY, db.collect()).with_opacity(0.45));
        ph.push(samples_series("data Y/U", GREY, deg.collect()).with_opacity(0.45));
    }
    for c in compared {
        mag.push(c.series(|p| (p.f_hz, p.magnitude_db)));
        ph.push(c.series(|p| (p.f_hz, p.phase_deg)));
    }
    mag.extend(with_band(
        label,
        points.iter().map(|p| (p.f_hz, p.magnitude_db)).collect(),
        mag_band,
    ));
    ph.extend(with_band(
        label,
        points.iter().map(|p| (p.f_hz, p.phase_deg)).collect(),
        ph_band,
    ));
    let panel = |title: &str, ylabel: &str, series| Panel {
        title: title.into(),
        xlabel: "frequency (Hz)".into(),
        ylabel: ylabel.into(),
        xlog: true,
        series,
        ..Default::default()
    };
    figure(
        heading,
        &band_note(has_band, title),
        &[
            panel("magnitude 20 log10|G(i2πf)|", "magnitude (dB)", mag),
            panel("phase", "phase (degrees)", ph),
        ],
        1,
    )
}

/// The unit-step response of the fitted system with its ±2σ band, beside the `compared`
/// models.
pub(super) fn step_figure(
    fitted: (&str, &[StepPoint]),
    compared: &[Compared<StepPoint>],
    heading: &str,
    title: &str,
) -> String {
    let (label, points) = fitted;
    let band = band_edges(points.iter().map(|p| (p.t, p.lo, p.hi)));
    let has_band = band.is_some();
    let mut series: Vec<Series> = compared
        .iter()
        .map(|c| c.series(|p| (p.t, p.value)))
        .collect();
    series.extend(with_band(
        label,
        points.iter().map(|p| (p.t, p.value)).collect(),
        band,
    ));
    figure(
        heading,
        &band_note(has_band, title),
        &[Panel {
            title: "response to a unit step at t = 0".into(),
            xlabel: "time after the step (s)".into(),
            ylabel: "output".into(),
            series,
            ..Default::default()
        }],
        1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(f_hz: f64, phase_deg: f64) -> BodePoint {
        BodePoint {
            f_hz,
            omega_rad_s: std::f64::consts::TAU * f_hz,
            magnitude_db: 0.0,
            phase_deg,
            magnitude_db_lo: None,
            magnitude_db_hi: None,
            phase_deg_lo: None,
            phase_deg_hi: None,
        }
    }

    /// A data point's phase is put within half a turn of the fitted phase, which is
    /// interpolated in log f and held beyond the ends.
    #[test]
    fn data_phase_follows_the_unwrapped_model() {
        let pts = [point(0.01, -10.0), point(0.1, -300.0)];
        assert_eq!(phase_at(&pts, 0.001), -10.0);
        assert_eq!(phase_at(&pts, 1.0), -300.0);
        assert!((phase_at(&pts, 0.1f64.powf(1.5)) + 155.0).abs() < 1e-9);
        // arg = +90°, near −300°: −270°.
        let z = Complex64::new(0.0, 1.0);
        assert!((phase_near(z, -300.0) + 270.0).abs() < 1e-9);
        assert!((phase_near(z, 0.0) - 90.0).abs() < 1e-9);
    }
}
