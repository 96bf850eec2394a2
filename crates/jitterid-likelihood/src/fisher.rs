//! Fisher information and Cramér–Rao bounds for jittered samples with white measurement noise.
//!
//! * [`gaussian_fisher`]: the Slepian–Bangs formula for independent Gaussian samples with
//!   mean `m_k(θ)` and variance `λ_k(θ)`,
//!   `I = Σ_k [∇m_k ∇m_kᵀ / λ_k + ½ ∇λ_k ∇λ_kᵀ / λ_k²]`. It is the information of the Gaussian
//!   approximation that [`QuasiMl`](super::QuasiMl) maximises, not a bound for the true,
//!   non-Gaussian data.
//! * [`exact_fisher`]: the information of the exact model,
//!   `I = Σ_k ∫ ∇log p(y; θ) ∇log p(y; θ)ᵀ p(y; θ) dy`, by numerical integration over `y`
//!   (composite 16-point Gauss–Legendre on `[min s − 10σ_v, max s + 10σ_v]` over the jitter's
//!   reach, 16 nodes per `8σ_v`) with the exact per-sample likelihood of
//!   [`ExactMl`](super::ExactMl): scores analytic in the signal's parameters and `σ_v`, central
//!   differences in the jitter's. Its inverse is the Cramér–Rao bound. What of each sample's
//!   likelihood does not depend on `y` (the signal and its gradient at the quadrature nodes
//!   over the jitter, the rule itself) is computed once per sample, not once per node in `y`
//!   (`exact::cached`: the same information to about `1e-12` relative, five to six times
//!   faster on the Table 2 setup).
//!
//! The parameters are the likelihood's ([`likelihood_param_names`](super::likelihood_param_names)):
//! the structure's free ones, then `σ_v` if the structure does not fix it.

use super::exact::{
    signal_table, ExactMl, JitterPrep, SampleCache, SampleModel, Scratch, SignalEval,
};
use super::moments::second_moments;
use super::param::{likelihood_param_names, Layout};
use super::MlError;
use faer::Mat;
use jitterid_estimate::support::inverse_gram;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_jitter::kernels::gauss::gl16;
use jitterid_jitter::JitterModel;
use jitterid_optim::finite_diff::{fd_step, LIKELIHOOD_FD_STEP};
use jitterid_signal::{SampleGrid, Signal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// A Fisher information matrix in named parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FisherInformation {
    /// Parameter names.
    pub names: Vec<String>,
    /// The matrix `I[i][j]`.
    pub matrix: Vec<Vec<f64>>,
    /// For [`exact_fisher`]: the largest `|∫ p(y) dy − 1|` over the samples, a check of the
    /// integration over `y`.
    pub max_mass_error: Option<f64>,
}

impl FisherInformation {
    /// The Cramér–Rao bound `I⁻¹`, if `I` is positive definite.
    pub fn crb(&self) -> Option<Vec<Vec<f64>>> {
        let p = self.names.len();
        spd_inverse(&Mat::from_fn(p, p, |i, j| self.matrix[i][j]))
    }

    /// Square roots of the bound's diagonal.
    pub fn crb_std(&self) -> Option<Vec<f64>> {
        let c = self.crb()?;
        Some((0..c.len()).map(|i| c[i][i].sqrt()).collect())
    }

    /// The bound's standard deviation of the parameter called `name`.
    pub fn crb_std_of(&self, name: &str) -> Option<f64> {
        let i = self.names.iter().position(|n| n == name)?;
        Some(self.crb_std()?[i])
    }
}

/// `√(gᵀ C g)`: the delta-method standard deviation of a function with gradient `g` of an
/// estimate with covariance `C`.
///
/// # Errors
///
/// [`MlError::InvalidArgument`] naming `covariance` (with its number of rows) if it does not
/// have one row per gradient entry, or the first row (by index) of another length.
pub fn delta_method_std(covariance: &[Vec<f64>], gradient: &[f64]) -> Result<f64, MlError> {
    let n = gradient.len();
    if covariance.len() != n {
        return Err(MlError::InvalidArgument {
            name: "covariance",
            value: covariance.len() as f64,
            reason: "must have one row per gradient entry",
        });
    }
    if let Some(i) = covariance.iter().position(|row| row.len() != n) {
        return Err(MlError::InvalidArgument {
            name: "covariance row",
            value: i as f64,
            reason: "every row must have one entry per gradient entry",
        });
    }
    let mut v = 0.0;
    for (i, gi) in gradient.iter().enumerate() {
        for (j, gj) in gradient.iter().enumerate() {
            v += gi * covariance[i][j] * gj;
        }
    }
    Ok(v.max(0.0).sqrt())
}

fn white_only<N: NoiseModel>(noise: &N, what: &'static str) -> Result<(), MlError> {
    if noise.is_white() {
        Ok(())
    } else {
        Err(MlError::ColouredNoise { criterion: what })
    }
}

/// The Slepian–Bangs (Gaussian) Fisher information of the record's samples at `structure`,
/// with noise level `noise_std` (used when the structure does not fix it).
///
/// # Errors
///
/// Coloured noise; a vanishing variance `λ_k`; errors of [`second_moments`].
pub fn gaussian_fisher<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    noise_std: f64,
) -> Result<FisherInformation, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    white_only(&structure.noise, "gaussian-fisher")?;
    let m = second_moments(structure, grid, noise_std, true)?;
    let (Some(dm), Some(dl)) = (&m.mean_gradient, &m.variance_gradient) else {
        return Err(MlError::Unsupported("no gradient".into()));
    };
    let p = dm.len();
    let mut info = vec![vec![0.0; p]; p];
    for (k, &lambda) in m.variance.iter().enumerate() {
        if !(lambda > 0.0 && lambda.is_finite()) {
            return Err(MlError::VanishingVariance {
                index: k,
                variance: lambda,
            });
        }
        for i in 0..p {
            for j in 0..p {
                info[i][j] +=
                    dm[i][k] * dm[j][k] / lambda + 0.5 * dl[i][k] * dl[j][k] / (lambda * lambda);
            }
        }
    }
    Ok(FisherInformation {
        names: m.names,
        matrix: info,
        max_mass_error: None,
    })
}

/// Options of [`exact_fisher`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FisherOptions {
    /// The likelihood's quadrature.
    pub quadrature: ExactMl,
    /// Width, in `σ_v`, of one 16-point sub-interval of the integration over `y`. Default 8.
    pub y_step: f64,
    /// Margin, in `σ_v`, beyond the signal's range. Default 10.
    pub y_margin: f64,
}

impl Default for FisherOptions {
    fn default() -> Self {
        FisherOptions {
            quadrature: ExactMl {
                parallel: false,
                ..ExactMl::default()
            },
            y_step: 8.0,
            y_margin: 10.0,
        }
    }
}

/// The exact model's Fisher information of the record's samples at `structure` with
/// measurement-noise level `noise_std` (used when the structure does not fix it). See the
/// module docs. Samples are processed in parallel.
///
/// # Errors
///
/// Coloured noise, `σ_v = 0`, a reach wider than the record, invalid options, a jitter
/// parameter that admits no finite difference, a likelihood that underflows inside the
/// integration range.
pub fn exact_fisher<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    noise_std: f64,
    options: &FisherOptions,
) -> Result<FisherInformation, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    fisher_by(structure, grid, noise_std, options, Route::Cached)
}

/// How each sample's likelihood is evaluated at the nodes of the integration over `y`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Route {
    /// The `y`-independent parts once per sample ([`SampleCache`]): what [`exact_fisher`]
    /// does.
    Cached,
    /// [`SampleModel::log_p`] afresh at every `y`, the likelihood's own route: the reference
    /// the cached route is tested against.
    #[cfg_attr(not(test), allow(dead_code))]
    Fresh,
}

/// [`exact_fisher`] by `route`.
fn fisher_by<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    noise_std: f64,
    options: &FisherOptions,
    route: Route,
) -> Result<FisherInformation, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    white_only(&structure.noise, "exact-fisher")?;
    options.quadrature.validate()?;
    for (name, v) in [("y_step", options.y_step), ("y_margin", options.y_margin)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(MlError::InvalidArgument {
                name,
                value: v,
                reason: "must be finite and > 0",
            });
        }
    }
    let sigma = structure.noise_std.unwrap_or(noise_std);
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(MlError::NoNoise { value: sigma });
    }
    super::criterion::check_reach(&structure.jitter, grid)?;
    let (lo, hi) = structure.jitter.reach();
    let layout = Layout::of(structure);
    let names = likelihood_param_names(structure);
    let p = layout.len();
    let signal = &structure.signal;
    let rate = signal.rate();
    let ns_grad = if layout.ns > 0 {
        signal.num_params()
    } else {
        0
    };
    let table = signal_table(signal, grid, (lo, hi), ns_grad > 0);
    let mut breaks = signal.breakpoints();
    breaks.sort_by(f64::total_cmp);
    let prep = JitterPrep::new(&structure.jitter, rate);
    // Jitter parameter ± h (one-sided where a side is invalid).
    let theta_j = structure.jitter.params();
    let mut shifted = Vec::new();
    if layout.nj > 0 {
        for j in 0..layout.nj {
            let h = fd_step(LIKELIHOOD_FD_STEP, theta_j[j]);
            let mk = |d: f64| {
                let mut t = theta_j.clone();
                t[j] += d;
                structure
                    .jitter
                    .with_params(&t)
                    .ok()
                    .map(|jit| JitterPrep::new(&jit, rate))
            };
            let (up, dn) = (mk(h), mk(-h));
            let denom = match (&up, &dn) {
                (Some(_), Some(_)) => 2.0 * h,
                (Some(_), None) | (None, Some(_)) => h,
                (None, None) => {
                    return Err(MlError::Unsupported(format!(
                        "jitter parameter {j} = {} admits no finite difference",
                        theta_j[j]
                    )))
                }
            };
            shifted.push((up, dn, denom));
        }
    }
    let quad = options.quadrature;
    let model = |jp| SampleModel {
        opts: quad,
        signal: SignalEval {
            signal,
            table: &table,
            grad_channels: ns_grad,
        },
        jitter: jp,
        breaks: &breaks,
        sigma,
    };
    let base = model(&prep);
    let shifted: Vec<(Option<SampleModel<'_, S>>, Option<SampleModel<'_, S>>, f64)> = shifted
        .iter()
        .map(|(up, dn, d)| (up.as_ref().map(model), dn.as_ref().map(model), *d))
        .collect();
    let (gx, gw) = gl16();
    let too_large = || MlError::QuadratureTooLarge {
        limit: super::exact::MAX_SAMPLE_NODES,
        noise_std: sigma,
    };
    // `log p` of one model at `y`, through the sample's cache when the route has one.
    let eval = |sm: &SampleModel<'_, S>,
                cache: Option<&mut SampleCache>,
                t: f64,
                y: f64,
                grad: Option<&mut [f64]>,
                scratch: &mut Scratch| {
        match cache {
            Some(c) => sm.log_p_cached(c, y, grad, scratch),
            None => sm.log_p(t, y, grad, scratch),
        }
        .map_err(|_| too_large())
    };
    let per_sample = |k: usize| -> Result<(Vec<f64>, f64), MlError> {
        let t = grid.time(k);
        let mut scratch = Scratch::default();
        let cached = route == Route::Cached;
        let mut base_cache = cached.then(|| SampleCache::new(&base, t, true));
        // The shifted models' caches, `(up, down)` per jitter parameter.
        let mut shifted_caches: Vec<(Option<SampleCache>, Option<SampleCache>)> = shifted
            .iter()
            .map(|(up, dn, _)| {
                let c = |sm: &Option<SampleModel<'_, S>>| {
                    sm.as_ref()
                        .filter(|_| cached)
                        .map(|sm| SampleCache::new(sm, t, false))
                };
                (c(up), c(dn))
            })
            .collect();
        let (smin, smax) = base.signal_range(t);
        let ya = smin - options.y_margin * sigma;
        let yb = smax + options.y_margin * sigma;
        let m = ((yb - ya) / (options.y_step * sigma)).ceil().max(1.0) as usize;
        let width = (yb - ya) / m as f64;
        let mut info = vec![0.0; p * p];
        let mut mass = 0.0;
        let mut g = vec![0.0; ns_grad + 1];
        let mut score = vec![0.0; p];
        for i in 0..m {
            let mid = ya + (i as f64 + 0.5) * width;
            for (x, w) in gx.iter().zip(gw) {
                let y = mid + 0.5 * width * x;
                let lp = eval(&base, base_cache.as_mut(), t, y, Some(&mut g), &mut scratch)?;
                if !lp.is_finite() {
                    return Err(MlError::LikelihoodUnderflow {
                        index: k,
                        y,
                        log_p: lp,
                    });
                }
                let dens = lp.exp();
                if dens == 0.0 {
                    continue;
                }
                score[..layout.ns].copy_from_slice(&g[..layout.ns]);
                for (j, ((up, dn, denom), (cu, cd))) in
                    shifted.iter().zip(shifted_caches.iter_mut()).enumerate()
                {
                    let mut f = |sm: &Option<SampleModel<'_, S>>,
                                 cache: &mut Option<SampleCache>|
                     -> Result<Option<f64>, MlError> {
                        sm.as_ref()
                            .map(|sm| eval(sm, cache.as_mut(), t, y, None, &mut scratch))
                            .transpose()
                    };
                    let lu = f(up, cu)?.unwrap_or(lp);
                    let ld = f(dn, cd)?.unwrap_or(lp);
                    score[layout.ns + j] = (lu - ld) / denom;
                }
                if let Some(si) = layout.sigma_index() {
                    score[si] = g[ns_grad];
                }
                let wd = 0.5 * width * w * dens;
                mass += wd;
                for a in 0..p {
                    for b in 0..p {
                        info[a * p + b] += wd * score[a] * score[b];
                    }
                }
            }
        }
        Ok((info, (mass - 1.0).abs()))
    };
    let budget = jitterid_numeric::budget::current();
    let parts: Vec<Result<(Vec<f64>, f64), MlError>> = (0..grid.len())
        .into_par_iter()
        .map(|k| jitterid_numeric::budget::run_with(budget.clone(), || per_sample(k)))
        .collect();
    let mut matrix = vec![vec![0.0; p]; p];
    let mut max_err: f64 = 0.0;
    for part in parts {
        let (info, err) = part?;
        max_err = max_err.max(err);
        for a in 0..p {
            for b in 0..p {
                matrix[a][b] += info[a * p + b];
            }
        }
    }
    Ok(FisherInformation {
        names,
        matrix,
        max_mass_error: Some(max_err),
    })
}

/// The inverse of a symmetric matrix (a Hessian or a Fisher matrix), if it is positive
/// definite, well enough conditioned to invert ([`inverse_gram`]) and the result finite with
/// a positive diagonal.
pub(crate) fn spd_inverse(m: &Mat<f64>) -> Option<Vec<Vec<f64>>> {
    let p = m.nrows();
    let inv = inverse_gram(m)?;
    let out: Vec<Vec<f64>> = (0..p)
        .map(|i| (0..p).map(|j| inv[(i, j)]).collect())
        .collect();
    out.iter()
        .flatten()
        .all(|v| v.is_finite())
        .then_some(out)
        .filter(|o| (0..p).all(|i| o[i][i] > 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid_jitter::{Gaussian, TwoPoint, UniformSum};
    use jitterid_signal::{LtiResponse, RandomBinary, Root, Zpk};
    use rand::rngs::StdRng;
    use rand::SeedableRng;

    /// `exact_fisher` (the cached route) against the route through `log_p` at every `y`, the
    /// likelihood's own: every entry within `1e-9` of `√(I_aa I_bb)` (they agree to about
    /// `1e-12`; see `exact::cached`), the same integration mass.
    fn same_information<J: JitterModel + Clone>(
        structure: &ModelStructure<LtiResponse<Zpk>, J>,
        grid: &SampleGrid,
    ) {
        let o = FisherOptions::default();
        let cached = fisher_by(structure, grid, 0.01, &o, Route::Cached).unwrap();
        let fresh = fisher_by(structure, grid, 0.01, &o, Route::Fresh).unwrap();
        assert_eq!(cached.names, fresh.names);
        let (a, b) = (&cached.matrix, &fresh.matrix);
        let p = a.len();
        let mut worst: f64 = 0.0;
        for i in 0..p {
            for j in 0..p {
                let scale = (b[i][i] * b[j][j]).sqrt();
                worst = worst.max((a[i][j] - b[i][j]).abs() / scale);
                assert!(
                    (a[i][j] - b[i][j]).abs() <= 1e-9 * scale,
                    "{:?} [{i}][{j}]: {} vs {}",
                    structure.jitter,
                    a[i][j],
                    b[i][j]
                );
            }
        }
        eprintln!(
            "{:?}: largest difference {worst:e} of √(I_aa I_bb)",
            structure.jitter
        );
        let (ma, mb) = (
            cached.max_mass_error.unwrap(),
            fresh.max_mass_error.unwrap(),
        );
        assert!((ma - mb).abs() <= 1e-12, "mass errors {ma} vs {mb}");
    }

    /// The Table 2 system (flat stretches, step tails, kinks within the reach: both shortcuts
    /// and the general rule) and the Table 1 system with its jitter and noise estimated (the
    /// shifted models' caches, the σ score), under jitters with pieces, a Gaussian and atoms.
    #[test]
    fn cached_route_equals_the_route_through_log_p() {
        let mut rng = StdRng::seed_from_u64(29);
        let n = 120;
        let grid = SampleGrid::new(0.0, 1.0, n).unwrap();
        let u = RandomBinary::new(8.0, 0.0, 1.0)
            .unwrap()
            .generate(0.0, n as f64 + 1.0, &mut rng)
            .unwrap();
        let table2 = Zpk::new(
            0.2,
            vec![Root::Real(-0.5)],
            vec![Root::Pair { re: -0.25, im: 0.3 }],
        )
        .unwrap();
        let signal = LtiResponse::new(table2, u);
        let a = 0.5 / 3f64.sqrt();
        let s = ModelStructure::oe(signal.clone(), UniformSum::new(2, a).unwrap())
            .with_noise_std(0.01)
            .unwrap();
        same_information(&s, &grid);
        let s = ModelStructure::oe(signal, TwoPoint::new(0.3).unwrap())
            .with_noise_std(0.01)
            .unwrap();
        same_information(&s, &grid);
        let table1 = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).unwrap();
        let u = RandomBinary::paper()
            .generate(0.0, n as f64 + 1.0, &mut rng)
            .unwrap();
        let signal = LtiResponse::new(table1, u);
        let s = ModelStructure::oe(signal.clone(), UniformSum::new(3, 0.6).unwrap())
            .with_estimated(true, true, true);
        same_information(&s, &grid);
        let s = ModelStructure::oe(signal, Gaussian::new(0.17).unwrap())
            .with_estimated(true, true, false)
            .with_noise_std(0.01)
            .unwrap();
        same_information(&s, &grid);
    }
}
