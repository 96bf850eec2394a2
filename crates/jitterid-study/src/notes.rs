//! What a fit's report says beside its numbers: a status line that never contradicts itself,
//! and notes on what the record suggests the model misses.
//!
//! Two mistakes with measured data leave a fit that looks fine or fails for a reason its
//! termination does not name:
//!
//! - **An input recorded on the sampling clock.** The model drives the system with the input's
//!   switch times. An input logged as its level at each sample (a zero-order hold on the
//!   sampling clock) switches only on the grid; when the real input switched between samples,
//!   the model's response is early or late by up to `T` at every switch, and the jittered
//!   model absorbs that timing error into the jitter (a wider jitter, a biased system) without
//!   a failed test. The record cannot tell the two apart; the note says when every switch lies
//!   on the grid, so the user can check how the input was recorded.
//! - **An output offset.** The model's expected samples have no constant term: a DC offset in
//!   `y` puts a bias into every residual, which the flatness check then reports as a residual
//!   spectrum that is not flat (its power sits in the lowest band). A t-test of the residuals'
//!   mean against their standard deviation names it, and the note names the key that estimates
//!   the offset with the system (`[output] estimate_offset = true`).

use crate::fit::{Fit, Structure};
use jitterid::estimate::NoiseModel;
use jitterid::signal::{Input, SampleGrid, Signal};
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Level of the offset test: a record without an offset is flagged in this fraction of fits.
pub const OFFSET_LEVEL: f64 = 1e-3;

/// Fewest switches inside the record for the grid note: one or two switches on the grid happen
/// by chance (an input that starts with the record), many do not.
pub const MIN_GRID_SWITCHES: usize = 3;

/// An output offset the fitted model lacks, significant at [`OFFSET_LEVEL`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Offset {
    /// The offset a refit with a constant output term would find (to first order): the
    /// residuals' mean along the constant's direction that the fitted parameters cannot take.
    pub estimate: f64,
    /// The residuals' standard deviation `s` (on `N − p − 1` degrees of freedom).
    pub std: f64,
    /// The t statistic of the residuals' mean.
    pub t: f64,
    /// Two-sided p-value of `t` under Student's law with `N − p − 1` degrees of freedom.
    pub p_value: f64,
}

/// The notes of one fit.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Notes {
    /// How many switches of the input inside the record all lie on the sampling grid (`None`
    /// when some do not, or there are fewer than [`MIN_GRID_SWITCHES`]).
    pub switches_on_grid: Option<usize>,
    /// A significant residual mean.
    pub offset: Option<Offset>,
}

impl Notes {
    /// The notes of the fit `f` of the samples `y` on `grid`, driven by `inputs`.
    pub fn of(f: &Fit, grid: &SampleGrid, y: &[f64], inputs: &[Input]) -> Self {
        Self {
            switches_on_grid: inputs.iter().find_map(|u| switches_on_grid(u, grid)),
            offset: residual_offset(&f.fitted, grid, y),
        }
    }

    /// One line per note, as a report prints them.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(k) = self.switches_on_grid {
            out.push(format!(
                "note: all {k} switches of the input inside the record lie on the sampling grid t0 + kT: the input was probably recorded as a zero-order hold on the sampling clock; if it really switched between samples, the fit absorbs that timing error into the jitter (wider jitter, biased system): give the input's own switch times"
            ));
        }
        if let Some(o) = &self.offset {
            out.push(format!(
                "note: the output probably has an offset the model lacks, about {:.4e} (residual mean test t = {:.2}, p = {:.1e}, residual std {:.4e}): estimate it with the system ([output] estimate_offset = true, or --set output.estimate_offset=true), or subtract it (or the output's level at rest) from y and fit again",
                o.estimate, o.t, o.p_value, o.std
            ));
        }
        out
    }

    /// Why the fit `f`, which did not converge, probably failed, when these notes say: the
    /// line a report prints under its status.
    pub fn likely_cause(&self, f: &Fit) -> Option<String> {
        if f.converged {
            return None;
        }
        if let Some(o) = &self.offset {
            Some(format!(
                "likely cause: an output offset of about {:.4e} (see the note)",
                o.estimate
            ))
        } else {
            self.switches_on_grid.map(|_| {
                "likely cause: an input recorded on the sampling clock (see the note)".into()
            })
        }
    }
}

/// The head of a fit's status line: `converged (…)`, `stopped: converged, but …` for a search
/// that converged but whose result failed a check (the residual spectrum is not flat), or
/// `NOT converged (…)`. A line never says both "not converged" and "converged".
pub fn status(f: &Fit) -> String {
    if f.converged {
        return format!("converged ({})", f.termination);
    }
    // The checks after a converged search describe themselves starting with "converged, but":
    // the search converged, the result is not kept as converged.
    if f.termination.starts_with("converged, but") {
        return format!("stopped: {}", f.termination);
    }
    format!("NOT converged ({})", f.termination)
}

/// The number of the input's switches inside the record when there are at least
/// [`MIN_GRID_SWITCHES`] and every one lies on the grid (within `10⁻⁶ T`, the tolerance of a
/// data file's `t` column).
pub fn switches_on_grid(input: &Input, grid: &SampleGrid) -> Option<usize> {
    let Input::Piecewise(p) = input else {
        return None;
    };
    let (t0, dt) = (grid.start(), grid.interval());
    let end = t0 + grid.len() as f64 * dt;
    let inside: Vec<f64> = p
        .steps()
        .into_iter()
        .map(|(t, _)| t)
        .filter(|&t| t > t0 && t < end)
        .collect();
    let on_grid = |t: f64| {
        let k = (t - t0) / dt;
        (k - k.round()).abs() <= 1e-6
    };
    (inside.len() >= MIN_GRID_SWITCHES && inside.iter().all(|&t| on_grid(t)))
        .then_some(inside.len())
}

/// The residuals' mean under `fitted`, when it differs from zero at [`OFFSET_LEVEL`].
///
/// A fit of a model without a constant term to a record with an offset `c` takes part of `c`
/// into its parameters (the static gain, a zero), so the plain mean of the residuals
/// understates it: 0.05 on a Table 2 record leaves a mean of 0.006. The test is therefore the
/// score test of an omitted constant: with `e` the constant `1` projected off the gradients
/// `∂m_k/∂θ` of the fitted parameters, `t = eᵀr / (s ‖e‖)` for the residuals `r = y − m` of
/// standard deviation `s`, and `eᵀr / ‖e‖²` the offset a refit with a constant would find to
/// first order. With no parameter gradient (nothing fitted) it is the plain t-test of the
/// residuals' mean. The test's law holds for independent residuals: with a coloured noise
/// model (their correlation would make a chance mean look significant) it is not run.
pub fn residual_offset(fitted: &Structure, grid: &SampleGrid, y: &[f64]) -> Option<Offset> {
    let n = y.len();
    if grid.len() != n || !fitted.noise.is_white() {
        return None;
    }
    let m = fitted.signal.expected_values(grid, &fitted.jitter);
    let r: Vec<f64> = y.iter().zip(&m).map(|(y, m)| y - m).collect();
    // Orthonormal directions of the fitted parameters (modified Gram–Schmidt; a direction
    // already spanned is dropped).
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for mut g in crate::residual_tests::mean_gradients(fitted, grid, y) {
        let norm0 = dot(&g, &g).sqrt();
        for q in &basis {
            let c = dot(&g, q);
            g.iter_mut().zip(q).for_each(|(x, q)| *x -= c * q);
        }
        let norm = dot(&g, &g).sqrt();
        if norm > 1e-9 * norm0 && norm.is_finite() {
            g.iter_mut().for_each(|x| *x /= norm);
            basis.push(g);
        }
    }
    let p = basis.len();
    let dof = n.checked_sub(p + 1).filter(|d| *d >= 2)?;
    let mut e = vec![1.0; n];
    for q in &basis {
        let c = q.iter().sum::<f64>();
        e.iter_mut().zip(q).for_each(|(x, q)| *x -= c * q);
    }
    let ee = dot(&e, &e);
    // The constant lies in the fitted directions (an integrator, an estimated offset): the
    // fit can take any offset itself.
    if !(ee > 1e-9 * n as f64) {
        return None;
    }
    let mean = r.iter().sum::<f64>() / n as f64;
    let std = (r.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / dof as f64).sqrt();
    let er = dot(&e, &r);
    if !(std > 0.0 && er.is_finite()) {
        return None;
    }
    let t = er / (std * ee.sqrt());
    let law = StudentsT::new(0.0, 1.0, dof as f64).ok()?;
    let p_value = 2.0 * law.sf(t.abs());
    (p_value < OFFSET_LEVEL).then_some(Offset {
        estimate: er / ee,
        std,
        t,
        p_value,
    })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid::signal::PiecewiseConstant;

    fn grid() -> SampleGrid {
        SampleGrid::new(0.0, 0.5, 40).unwrap()
    }

    #[test]
    fn switches_on_the_grid_are_noted_and_between_samples_are_not() {
        let on = PiecewiseConstant::new(vec![0.0, 2.0, 5.5, 9.0, 30.0], vec![1.0, -1.0, 1.0, 0.5])
            .unwrap();
        assert_eq!(switches_on_grid(&Input::Piecewise(on), &grid()), Some(3));
        let off = PiecewiseConstant::new(vec![0.0, 2.0, 5.3, 9.0, 30.0], vec![1.0, -1.0, 1.0, 0.5])
            .unwrap();
        assert_eq!(switches_on_grid(&Input::Piecewise(off), &grid()), None);
        // Two switches on the grid happen by chance: no note.
        let few = PiecewiseConstant::new(vec![0.0, 2.0, 5.5, 30.0], vec![1.0, -1.0, 1.0]).unwrap();
        assert_eq!(switches_on_grid(&Input::Piecewise(few), &grid()), None);
    }
}
