//! The residuals the correlation tests of `validate` see, and the directions of the fitted
//! parameters removed from them.
//!
//! The residuals are standardised by `√λ_k` (white noise) or whitened by the fitted residual
//! spectrum (a coloured noise model, [`whiten::whitened`]). A fitted parameter's error leaves
//! its trace `W Δθ` in them, `W` the same map applied to the gradients of the expected samples:
//! an estimator's inefficiency, not a wrong structure, yet visible to the tests as colour
//! (BCLS fits of the true structure failed the whiteness test in 4 of 20 records). The tests
//! therefore see the residuals projected off the span of `W` and of the constant
//! ([`validation::residual_projection`]), the residuals of the efficient weighted fit whatever
//! the estimator, whose null distributions are known.

use crate::error::StudyResult;
use crate::fit::Structure;
use crate::study_err;
use crate::whiten;
use jitterid::estimate::validation;
use jitterid::estimate::NoiseModel;
use jitterid::signal::SampleGrid;

/// What the correlation tests see of one record under a model.
#[derive(Debug, Clone)]
pub struct Tested {
    /// The standardised (or whitened) residuals, projected off `basis`.
    pub residuals: Vec<f64>,
    /// An orthonormal basis of the removed directions: the constant and the fitted
    /// parameters' gradients.
    pub basis: Vec<Vec<f64>>,
    /// How many parameter directions were removed (the basis less the constant).
    pub removed: usize,
    /// Estimated parameters of the noise model, which reduce the whiteness test's degrees of
    /// freedom.
    pub noise_params: usize,
}

/// The linear map from raw residuals to the tests' scale: division by `√λ_k` for white noise;
/// for a coloured noise model, whitening by its shape plus the jitter's floor
/// `ρ = λ̄/σ_e²` at this record's model.
fn scaler<'a>(
    s: &'a Structure,
    grid: &'a SampleGrid,
    noise_std: f64,
    variance: &'a [f64],
) -> impl Fn(&[f64]) -> Option<Vec<f64>> + 'a {
    // `None` when the shape has its floor already, or the jitter adds no variance.
    let floor = if s.noise.is_white() {
        0.0
    } else {
        s.jitter_floor_start(grid, Some(noise_std)).unwrap_or(0.0)
    };
    move |x: &[f64]| {
        if s.noise.is_white() {
            Some(x.iter().zip(variance).map(|(v, l)| v / l.sqrt()).collect())
        } else {
            whiten::whitened(x, grid.interval(), |f| {
                s.noise.shape(f, grid.interval()) + floor
            })
        }
    }
}

/// The gradients of the expected samples with respect to the free parameters that move them
/// (the system's and the jitter's; the noise model's do not), by central differences, one
/// side where the other leaves the parameters' domain. A parameter whose expected samples
/// cannot be evaluated on either side is left out: nothing is removed for it.
pub(crate) fn mean_gradients(s: &Structure, grid: &SampleGrid, y: &[f64]) -> Vec<Vec<f64>> {
    let theta = s.params();
    let (ns, nj, _) = s.blocks();
    let mean_at = |j: usize, h: f64| -> Option<Vec<f64>> {
        let mut p = theta.clone();
        p[j] += h;
        let moved = s.with_params(&p).ok()?;
        validation::compare(&moved, grid, y)
            .ok()
            .map(|c| c.expected)
    };
    (0..ns + nj)
        .filter_map(|j| {
            // Relative steps: the expected samples are smooth in the parameters, and 1e-6 keeps
            // both the truncation (h²) and the rounding (ε/h) error near 1e-12.
            let h = 1e-6 * theta[j].abs().max(1.0);
            let diff = |a: Vec<f64>, b: Vec<f64>, step: f64| -> Vec<f64> {
                a.iter().zip(&b).map(|(x, y)| (x - y) / step).collect()
            };
            match (mean_at(j, h), mean_at(j, -h)) {
                (Some(a), Some(b)) => Some(diff(a, b, 2.0 * h)),
                (Some(a), None) => Some(diff(a, mean_at(j, 0.0)?, h)),
                (None, Some(b)) => Some(diff(mean_at(j, 0.0)?, b, h)),
                (None, None) => None,
            }
        })
        .collect()
}

/// The residuals the tests see of `y` on `grid` under `s` with noise level `noise_std`: raw
/// residuals `raw = y − m` and the exact sample variances `variance` (`λ_k`).
pub fn tested_residuals(
    s: &Structure,
    grid: &SampleGrid,
    noise_std: f64,
    y: &[f64],
    raw: &[f64],
    variance: &[f64],
    name: &str,
) -> StudyResult<Tested> {
    let scale = scaler(s, grid, noise_std, variance);
    let not_positive =
        || study_err!("{name}: validation: the noise model's spectrum is not positive and finite");
    let e = scale(raw).ok_or_else(not_positive)?;
    let columns: Vec<Vec<f64>> = mean_gradients(s, grid, y)
        .iter()
        .map(|g| scale(g))
        .collect::<Option<_>>()
        .ok_or_else(not_positive)?;
    let basis = validation::residual_projection(&columns, y.len());
    Ok(Tested {
        residuals: validation::project_out(&e, &basis),
        removed: basis.len().saturating_sub(1),
        basis,
        noise_params: s.blocks().2,
    })
}
