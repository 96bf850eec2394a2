//! Contract checks that every [`JitterModel`] must pass.
//!
//! Run [`check_contract`] in a test of any new family (see `docs/extending.md`):
//!
//! ```
//! use jitterid_jitter::{testing::check_contract, UniformSum};
//! check_contract(&UniformSum::new(2, 0.2887).unwrap(), 1).unwrap();
//! ```
//!
//! The checks fall in two groups. [`check_closed_forms`] is deterministic: it holds the closed
//! forms (`cf`, `cf_gradient`, `mgf`, `mean`, `variance`) against each other and against
//! quadrature over `pdf`, `atoms` and `pieces`, with tolerances set by floating-point
//! rounding. [`check_sampler`] holds `sample` against the closed forms with Monte Carlo
//! tolerances derived from the number of draws. [`check_contract`] runs both.
//!
//! Frequencies and steps are scaled by the model's own spread `s` (its standard deviation, or
//! the size of its reach if that is zero), so the same checks work for `σ = 1e-9` and `σ = 5`.
//!
//! A family that overrides the provided [`mgf`](JitterModel::mgf),
//! [`cf_gradient`](JitterModel::cf_gradient) or [`sample`](JitterModel::sample) (all shipped
//! ones do) can also run [`check_overrides`], which holds them against the trait's defaults
//! through [`ProvidedDefaults`], and [`check_distribution`], a Kolmogorov–Smirnov test of the
//! sampler.
//!
//! Why one file of about 790 lines (an eighth of them its own tests): the contract is one list of
//! promises, and its checks share the private quadrature reference against which every
//! provided method is held.

use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// Number of draws of the Monte Carlo checks.
pub const MC_DRAWS: usize = 20_000;

/// Width of the Monte Carlo acceptance band, in standard errors. A correct model lands
/// outside with probability about `6e-7` per comparison (normal two-sided tail at 5).
pub const MC_SIGMAS: f64 = 5.0;

/// Rounding tolerance for quantities that closed forms and quadrature give to near machine
/// precision (mass, mean, variance, `M(-i2πf)` against `γ(f)`).
const EXACT_TOL: f64 = 1e-12;

/// Tolerance of quadrature against `γ(f)` at moderate frequency, where the integrand
/// oscillates over many nodes.
const RULE_CF_TOL: f64 = 1e-10;

/// Relative finite-difference step for `cf_gradient`.
const FD_STEP: f64 = 1e-6;

/// Tolerance of `cf_gradient` against central differences, relative to the natural size
/// `|∂γ/∂θ| + |γ|/θ` of a derivative. With step `δ = 1e-6 θ` the rounding error of the
/// difference is `≈ ε|γ|/δ ≈ 2e-10 |γ|/θ` and the truncation error `δ²|γ'''|/6` is
/// `≈ 1e-12 (2πfs)³|γ|/θ` for the frequencies used (`2πfs ≤ 3`); `1e-6` sits far above both
/// and far below any error a wrong formula makes.
const FD_TOL: f64 = 1e-6;

/// Moderate frequencies, as `2πf·s`: where `γ` varies most.
const MODERATE: [f64; 3] = [0.3, 1.0, 3.0];

/// Frequencies for the quadrature check, as `2πf·s`, up to many oscillations over the spread.
const RULE_FREQS: [f64; 5] = [0.3, 1.0, 3.0, 10.0, 30.0];

/// Frequencies, as `2πf·s`, for the bounds `|γ| ≤ 1` and `γ(-f) = conj γ(f)`.
const RELATIVE_FREQS: [f64; 11] = [1e-9, 1e-3, 0.1, 0.3, 1.0, 3.0, 10.0, 1e2, 1e4, 1e8, 1e12];

/// Absolute frequencies (Hz) for the same bounds, down to the edge of overflow.
const ABSOLUTE_FREQS: [f64; 7] = [1e-3, 1.0, 1e3, 1e9, 1e15, 1e300, f64::MAX];

/// Runs [`check_closed_forms`] and [`check_sampler`] (with `seed`) and reports every failure
/// of either, one per line.
pub fn check_contract<J: JitterModel + Clone>(model: &J, seed: u64) -> Result<(), String> {
    let mut fails = Vec::new();
    closed_forms(model, &mut fails);
    sampler(model, seed, &mut fails);
    report(model, fails)
}

/// The deterministic part of the contract:
///
/// * parameter names, values and count agree; `with_params(params())` rebuilds the model
///   (same `Debug` output); a parameter vector of the wrong length is rejected with
///   [`JitterError::WrongParamCount`]; a NaN or infinite parameter is rejected;
/// * `γ(0) = 1`; `γ` is finite and its gradient not NaN, `|γ| ≤ 1 + 1e-12` and
///   `γ(-f) = conj γ(f)` over frequencies from `1e-9/s` to `f64::MAX`;
/// * `M(0) = 1`, and where `M` is defined, `M(-i2πf) = γ(f)` and `M(z)` equals the quadrature
///   of `e^{zτ}` for a few complex `z` with `|Re z| ≤ 0.05/s` (a larger real part would weigh
///   the tails that the pieces may leave out);
/// * pieces are sorted, non-empty and disjoint; atoms have masses in `(0, 1]`; the density is
///   finite and non-negative;
/// * the rule `model.rule(&[], 0.0)` has mass 1, mean `mean()` and variance `variance()`
///   within `1e-12` (relative to the spread), also when cut at extra breakpoints, and so has
///   the rule built from `pdf`, `pieces` and `atoms` alone (which a family that overrides
///   `rule` must keep consistent: other crates integrate the density directly);
/// * the rule at rate `2π|f|` reproduces `γ(f)` within `1e-10` for `2πfs` up to 30: this is
///   the check that the pieces are fine enough;
/// * `cf_gradient` has one entry per parameter and matches central differences of `cf`
///   through `with_params`.
pub fn check_closed_forms<J: JitterModel + Clone>(model: &J) -> Result<(), String> {
    let mut fails = Vec::new();
    closed_forms(model, &mut fails);
    report(model, fails)
}

/// The Monte Carlo part of the contract, with [`MC_DRAWS`] draws from
/// `StdRng::seed_from_u64(seed)`: draws are finite and inside [`reach`](JitterModel::reach);
/// their mean, variance and empirical `E[e^{-i2πfτ}]` agree with `mean()`, `variance()` and
/// `cf(f)` within [`MC_SIGMAS`] standard errors.
pub fn check_sampler<J: JitterModel + ?Sized>(model: &J, seed: u64) -> Result<(), String> {
    let mut fails = Vec::new();
    sampler(model, seed, &mut fails);
    report(model, fails)
}

fn report<J: JitterModel + ?Sized>(model: &J, fails: Vec<String>) -> Result<(), String> {
    if fails.is_empty() {
        return Ok(());
    }
    let mut msg = format!(
        "jitter model {:?} breaks {} contract check(s):",
        model,
        fails.len()
    );
    for f in fails {
        let _ = write!(msg, "\n  - {f}");
    }
    Err(msg)
}

/// The spread `s` that sets frequency and step scales: the standard deviation, or for a
/// degenerate law the size of its reach, or 1.
fn spread<J: JitterModel + ?Sized>(model: &J) -> f64 {
    let sd = model.std_dev();
    if sd.is_finite() && sd > 0.0 {
        return sd;
    }
    let (lo, hi) = model.reach();
    let r = lo.abs().max(hi.abs());
    if r.is_finite() && r > 0.0 {
        r
    } else {
        1.0
    }
}

/// Frequency (Hz) at which `2πf·s = c`.
fn freq(c: f64, s: f64) -> f64 {
    c / (2.0 * PI * s)
}

/// `E[e^{zτ}]` by a quadrature rule.
fn rule_expect_exp(rule: &crate::QuadratureRule, z: Complex64) -> Complex64 {
    let re = rule.expect(|t| (z * t).exp().re);
    let im = rule.expect(|t| (z * t).exp().im);
    Complex64::new(re, im)
}

fn closed_forms<J: JitterModel + Clone>(model: &J, fails: &mut Vec<String>) {
    let s = spread(model);
    check_params(model, fails);
    check_cf_bounds(model, s, fails);
    check_mgf(model, s, fails);
    check_structure(model, fails);
    check_rule(model, s, fails);
    check_gradient(model, s, fails);
    check_even(model, s, fails);
}

/// `even_params`: one entry per parameter, and each parameter it names is a positive width
/// that `γ` depends on through its square: `(∂γ/∂θ)/θ` tends to a limit as `θ → 0` (it is
/// `2G'(θ²)` for `γ = G(θ²)`), where a parameter that enters linearly gives `c/θ`, which
/// doubles when `θ` halves.
fn check_even<J: JitterModel + Clone>(model: &J, s: f64, fails: &mut Vec<String>) {
    let even = model.even_params();
    let p = model.params();
    if even.len() != p.len() {
        fails.push(format!(
            "even_params() has {} entries for {} parameters",
            even.len(),
            p.len()
        ));
        return;
    }
    for (i, _) in even.iter().enumerate().filter(|(_, &e)| e) {
        if !(p[i] > 0.0) {
            fails.push(format!(
                "even parameter {i} is {} (not a positive width)",
                p[i]
            ));
            continue;
        }
        // (∂γ/∂θ)/θ by central differences through `with_params`, at θ scaled by `c`.
        let slope = |c: f64, f: f64| -> Option<Complex64> {
            let at = |theta: f64| {
                let mut q = p.clone();
                q[i] = theta;
                model.with_params(&q).ok().map(|m| m.cf(f))
            };
            let (theta, h) = (c * p[i], 1e-3 * c * p[i]);
            Some((at(theta + h)? - at(theta - h)?) / (2.0 * h * theta))
        };
        for f in [0.3, 1.0, 3.0].map(|x| x / (std::f64::consts::TAU * s)) {
            match (slope(1e-2, f), slope(2e-2, f)) {
                (Some(a), Some(b)) if (a - b).norm() <= 0.05 * a.norm().max(b.norm()) + 1e-9 => {}
                (Some(a), Some(b)) => fails.push(format!(
                    "parameter {i} is declared even but (∂γ/∂θ)/θ at f = {f:e} changes from {b} to {a} as θ halves"
                )),
                _ => fails.push(format!(
                    "parameter {i} is declared even but with_params rejects small values of it"
                )),
            }
        }
    }
}

fn check_params<J: JitterModel + Clone>(model: &J, fails: &mut Vec<String>) {
    let p = model.params();
    let names = model.param_names();
    if names.len() != p.len() || model.num_params() != p.len() {
        fails.push(format!(
            "{} parameter names, {} parameters, num_params() = {}",
            names.len(),
            p.len(),
            model.num_params()
        ));
    }
    if p.iter().any(|v| !v.is_finite()) {
        fails.push(format!("non-finite parameters {p:?}"));
    }
    match model.with_params(&p) {
        Ok(m) if format!("{m:?}") == format!("{model:?}") => {}
        Ok(m) => fails.push(format!("with_params(params()) gave {m:?}")),
        Err(e) => fails.push(format!("with_params(params()) failed: {e}")),
    }
    let mut longer = p.clone();
    longer.push(1.0);
    let mut wrong = vec![longer];
    if !p.is_empty() {
        wrong.push(p[..p.len() - 1].to_vec());
    }
    for w in wrong {
        if !matches!(
            model.with_params(&w),
            Err(JitterError::WrongParamCount { .. })
        ) {
            fails.push(format!(
                "with_params accepted {} parameter(s) instead of {} (or gave another error)",
                w.len(),
                p.len()
            ));
        }
    }
    for j in 0..p.len() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut q = p.clone();
            q[j] = bad;
            if model.with_params(&q).is_ok() {
                fails.push(format!(
                    "with_params accepted {} = {bad}",
                    names.get(j).map_or("?", String::as_str)
                ));
            }
        }
    }
}

fn check_cf_bounds<J: JitterModel + ?Sized>(model: &J, s: f64, fails: &mut Vec<String>) {
    let g0 = model.cf(0.0);
    if (g0 - 1.0).norm() > 1e-15 {
        fails.push(format!("γ(0) = {g0}, not 1"));
    }
    let freqs = RELATIVE_FREQS
        .iter()
        .map(|&c| freq(c, s))
        .chain(ABSOLUTE_FREQS);
    for f in freqs {
        let (g, gm) = (model.cf(f), model.cf(-f));
        if !(g.re.is_finite() && g.im.is_finite()) {
            fails.push(format!("γ({f:e}) = {g} is not finite"));
            continue;
        }
        if g.norm() > 1.0 + 1e-12 {
            fails.push(format!("|γ({f:e})| = {} > 1", g.norm()));
        }
        // Rounding only: both are the same closed form at ±f.
        if (gm - g.conj()).norm() > 1e-15 {
            fails.push(format!(
                "γ(-f) = {gm} but conj γ(f) = {} at f = {f:e}",
                g.conj()
            ));
        }
        // A derivative may legitimately overflow (∂γ/∂c = -i2πfγ for a location c at
        // f = f64::MAX), but it must never be NaN.
        let grad = model.cf_gradient(f);
        if grad.iter().any(|d| d.re.is_nan() || d.im.is_nan()) {
            fails.push(format!("cf_gradient({f:e}) = {grad:?} is NaN"));
        }
    }
}

fn check_mgf<J: JitterModel + ?Sized>(model: &J, s: f64, fails: &mut Vec<String>) {
    match model.mgf(Complex64::new(0.0, 0.0)) {
        Some(m) if (m - 1.0).norm() <= 1e-15 => {}
        other => fails.push(format!("M(0) = {other:?}, not 1")),
    }
    for c in RULE_FREQS {
        for f in [freq(c, s), -freq(c, s)] {
            if let Some(m) = model.mgf(Complex64::new(0.0, -2.0 * PI * f)) {
                let g = model.cf(f);
                if (m - g).norm() > EXACT_TOL {
                    fails.push(format!("M(-i2πf) = {m} but γ(f) = {g} at f = {f:e}"));
                }
            }
        }
    }
    // Off the imaginary axis, against quadrature of e^{zτ} (relative: |M| may be large).
    // The pieces only promise that the mass outside them is below TAIL_MASS; e^{zτ} grows
    // in one tail, so Re z is kept small: for an exponential tail e^{-τ/b} cut where
    // e^{-c} < 1e-17, the part of E[e^{zτ}] left out is e^{-c(1 - b Re z)}, still below
    // 1e-15 for b Re z ≤ 0.1 (here b Re z ≤ 0.05√2).
    for z in [
        Complex64::new(0.05, 0.0),
        Complex64::new(-0.05, 0.0),
        Complex64::new(-0.03, 0.7),
        Complex64::new(0.02, -2.0),
    ] {
        let z = z / s;
        if let Some(m) = model.mgf(z) {
            let e = rule_expect_exp(&model.rule(&[], z.norm()), z);
            if (m - e).norm() > RULE_CF_TOL * m.norm().max(1.0) {
                fails.push(format!("M({z}) = {m} but quadrature gives {e}"));
            }
        }
    }
}

fn check_structure<J: JitterModel + ?Sized>(model: &J, fails: &mut Vec<String>) {
    let pieces = model.pieces();
    for (k, &(lo, hi)) in pieces.iter().enumerate() {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            fails.push(format!("piece {k} = [{lo}, {hi}] is empty or not finite"));
        }
        if k > 0 && pieces[k - 1].1 > lo {
            fails.push(format!("pieces {} and {k} overlap or are unsorted", k - 1));
        }
    }
    let mut atom_mass = 0.0;
    for a in model.atoms() {
        if !(a.position.is_finite() && a.mass > 0.0 && a.mass <= 1.0) {
            fails.push(format!("bad atom {a:?}"));
        }
        atom_mass += a.mass;
    }
    if atom_mass > 1.0 + EXACT_TOL {
        fails.push(format!("atoms carry mass {atom_mass} > 1"));
    }
    if pieces.is_empty() && model.atoms().is_empty() {
        fails.push("no pieces and no atoms".into());
    }
    // The density on a grid over and beyond the reach.
    let (lo, hi) = model.reach();
    let w = (hi - lo).max(1e-300);
    for k in 0..=200 {
        let t = lo - 0.1 * w + 1.2 * w * f64::from(k) / 200.0;
        let p = model.pdf(t);
        if !(p.is_finite() && p >= 0.0) {
            fails.push(format!("pdf({t}) = {p}"));
            break;
        }
    }
}

fn check_rule<J: JitterModel + ?Sized>(model: &J, s: f64, fails: &mut Vec<String>) {
    let (mean, var) = (model.mean(), model.variance());
    if !(mean.is_finite() && var.is_finite() && var >= 0.0) {
        fails.push(format!(
            "mean {mean} or variance {var} not finite and valid"
        ));
        return;
    }
    let sd = var.sqrt();
    // Nodes are stored as τ, so an offset mean costs about ε|mean| in τ - mean.
    let mean_tol = EXACT_TOL * (mean.abs() + sd);
    let var_tol = EXACT_TOL * (var + mean.abs() * sd);
    let (lo, hi) = model.reach();
    let breaks_sets: [Vec<f64>; 2] = [Vec::new(), vec![mean, lo + 0.3 * (hi - lo), hi + 1.0]];
    // The family's own rule, and the rule built from its density, pieces and atoms alone (the
    // route of callers that integrate the density themselves): a family that overrides `rule`
    // must keep the two consistent.
    let rules = breaks_sets
        .iter()
        .map(|b| (b, "rule", model.rule(b, 0.0)))
        .chain(
            breaks_sets
                .iter()
                .map(|b| (b, "density rule", crate::rule::build_rule(model, b, 0.0))),
        );
    for (breaks, which, rule) in rules {
        let bad =
            rule.nodes.iter().zip(&rule.weights).any(|(&t, &w)| {
                !(t.is_finite() && t >= lo && t <= hi && w >= 0.0 && w.is_finite())
            });
        if bad {
            fails.push(format!(
                "{which}(breaks = {breaks:?}) has a node outside [{lo}, {hi}] or a negative weight"
            ));
        }
        // Mass of the density over the pieces plus the atoms.
        let mass = rule.mass();
        if (mass - 1.0).abs() > EXACT_TOL {
            fails.push(format!(
                "{which}: continuous mass plus atoms = {mass} (breaks {breaks:?}), not 1"
            ));
        }
        let m = rule.expect(|t| t);
        if (m - mean).abs() > mean_tol {
            fails.push(format!(
                "{which} mean {m} but mean() = {mean} (breaks {breaks:?})"
            ));
        }
        let v = rule.expect(|t| (t - mean) * (t - mean));
        if (v - var).abs() > var_tol {
            fails.push(format!(
                "{which} variance {v} but variance() = {var} (breaks {breaks:?})"
            ));
        }
    }
    for c in RULE_FREQS {
        let f = freq(c, s);
        let rule = model.rule(&[], 2.0 * PI * f);
        let e = rule_expect_exp(&rule, Complex64::new(0.0, -2.0 * PI * f));
        let g = model.cf(f);
        if (e - g).norm() > RULE_CF_TOL {
            fails.push(format!(
                "quadrature gives E[e^(-i2πfτ)] = {e} but γ = {g} at 2πf·s = {c}"
            ));
        }
    }
}

fn check_gradient<J: JitterModel + Clone>(model: &J, s: f64, fails: &mut Vec<String>) {
    let p = model.params();
    let names = model.param_names();
    for c in MODERATE {
        let f = freq(c, s);
        let g = model.cf(f);
        let grad = model.cf_gradient(f);
        if grad.len() != p.len() {
            fails.push(format!(
                "cf_gradient gives {} entries for {} parameters",
                grad.len(),
                p.len()
            ));
            return;
        }
        for j in 0..p.len() {
            // A location parameter may be 0: scale its step by the spread instead.
            let scale = p[j].abs().max(s);
            let h = FD_STEP * scale;
            let (mut up, mut down) = (p.clone(), p.clone());
            up[j] += h;
            down[j] -= h;
            let (Ok(mu), Ok(md)) = (model.with_params(&up), model.with_params(&down)) else {
                fails.push(format!(
                    "with_params rejected {} = {} ± {h:e}",
                    names.get(j).map_or("?", String::as_str),
                    p[j]
                ));
                continue;
            };
            let fd = (mu.cf(f) - md.cf(f)) / (up[j] - down[j]);
            let tol = FD_TOL * (grad[j].norm() + g.norm() / scale);
            if (fd - grad[j]).norm() > tol {
                fails.push(format!(
                    "∂γ/∂{} = {} but central difference gives {fd} at 2πf·s = {c}",
                    names.get(j).map_or("?", String::as_str),
                    grad[j]
                ));
            }
        }
    }
}

fn sampler<J: JitterModel + ?Sized>(model: &J, seed: u64, fails: &mut Vec<String>) {
    let mut rng = StdRng::seed_from_u64(seed);
    let draws: Vec<f64> = (0..MC_DRAWS).map(|_| model.sample(&mut rng)).collect();
    let n = MC_DRAWS as f64;
    let s = spread(model);
    let (mean, var) = (model.mean(), model.variance());
    let (lo, hi) = model.reach();
    // Outside the reach with probability < TAIL_MASS per draw: never, for a correct model.
    // The slack only absorbs rounding of a sum of terms that each stay inside.
    let slack = 1e-12 * (s + lo.abs().max(hi.abs()));
    if let Some(t) = draws
        .iter()
        .find(|t| !(t.is_finite() && **t >= lo - slack && **t <= hi + slack))
    {
        fails.push(format!("draw {t} is outside the reach [{lo}, {hi}]"));
    }
    // Sample mean: standard error √(var/n) from the exact variance, plus rounding.
    let m = draws.iter().sum::<f64>() / n;
    let tol = MC_SIGMAS * (var / n).sqrt() + EXACT_TOL * (mean.abs() + s);
    if (m - mean).abs() > tol {
        fails.push(format!(
            "sample mean {m} but mean() = {mean} (allowed ±{tol:e})"
        ));
    }
    // Variance about the exact mean, v̂ = mean((τ-μ)²), is unbiased with
    // Var v̂ = (μ₄ - σ⁴)/n; μ₄ and σ⁴ are estimated from the same draws.
    let v = draws.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / n;
    let m4 = draws.iter().map(|t| (t - mean).powi(4)).sum::<f64>() / n;
    let se = ((m4 - v * v).max(0.0) / n).sqrt();
    let tol = MC_SIGMAS * se + EXACT_TOL * (var + mean.abs() * s);
    if (v - var).abs() > tol {
        fails.push(format!(
            "sample variance {v} but variance() = {var} (allowed ±{tol:e})"
        ));
    }
    // Empirical characteristic function: each component is a mean of n bounded terms whose
    // standard error, from their sample variance, is at most √(1/n) ≈ 0.007.
    for c in MODERATE {
        let f = freq(c, s);
        let w = 2.0 * PI * f;
        let g = model.cf(f);
        let (re_mean, re_se) = mean_se(draws.iter().map(|t| (w * t).cos()));
        let (im_mean, im_se) = mean_se(draws.iter().map(|t| -(w * t).sin()));
        let (re_tol, im_tol) = (MC_SIGMAS * re_se + 1e-12, MC_SIGMAS * im_se + 1e-12);
        if (re_mean - g.re).abs() > re_tol || (im_mean - g.im).abs() > im_tol {
            fails.push(format!(
                "empirical E[e^(-i2πfτ)] = {re_mean} + {im_mean}i but γ = {g} at 2πf·s = {c} \
                 (allowed ±{re_tol:e}, ±{im_tol:e})"
            ));
        }
    }
}

/// Sample mean and its standard error.
fn mean_se(values: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let n = values.clone().count() as f64;
    let mean = values.clone().sum::<f64>() / n;
    let var = values.map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// A family that forwards every method of `J` except the three with generic defaults,
/// [`mgf`](JitterModel::mgf), [`cf_gradient`](JitterModel::cf_gradient) and
/// [`sample`](JitterModel::sample): its values for those are the trait's provided ones, built
/// from `J`'s required core (and `J`'s own `rule`, `reach` and `atoms`).
///
/// [`check_overrides`] holds a family's exact overrides against it; `check_contract` on it
/// checks the defaults themselves against the contract.
#[derive(Debug, Clone, PartialEq)]
pub struct ProvidedDefaults<J>(pub J);

impl<J: JitterModel> JitterModel for ProvidedDefaults<J> {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn param_names(&self) -> Vec<String> {
        self.0.param_names()
    }
    fn params(&self) -> Vec<f64> {
        self.0.params()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        self.0.with_params(params).map(ProvidedDefaults)
    }
    fn cf(&self, f: f64) -> Complex64 {
        self.0.cf(f)
    }
    fn pdf(&self, tau: f64) -> f64 {
        self.0.pdf(tau)
    }
    fn atoms(&self) -> Vec<crate::Atom> {
        self.0.atoms()
    }
    fn pieces(&self) -> Vec<(f64, f64)> {
        self.0.pieces()
    }
    fn mean(&self) -> f64 {
        self.0.mean()
    }
    fn variance(&self) -> f64 {
        self.0.variance()
    }
    fn num_params(&self) -> usize {
        self.0.num_params()
    }
    fn std_dev(&self) -> f64 {
        self.0.std_dev()
    }
    fn reach(&self) -> (f64, f64) {
        self.0.reach()
    }
    fn rule(&self, breaks: &[f64], rate: f64) -> crate::QuadratureRule {
        self.0.rule(breaks, rate)
    }
    fn rule_from(&self, from: f64, breaks: &[f64], rate: f64) -> crate::QuadratureRule {
        self.0.rule_from(from, breaks, rate)
    }
}

/// Acceptance threshold of `√n · D_n` for the Kolmogorov–Smirnov statistic `D_n`: a correct
/// sampler exceeds it with probability `2e^{-2x²} ≈ 6e-7`, the false-alarm rate of the
/// [`MC_SIGMAS`] bands (for a law with atoms the test is conservative).
pub const KS_THRESHOLD: f64 = 2.745;

/// Points at which [`check_distribution`] compares the distribution functions: the empirical
/// quantiles of order `j/KS_POINTS`.
pub const KS_POINTS: usize = 200;

/// Kolmogorov–Smirnov test of [`MC_DRAWS`] draws of `model.sample` from
/// `StdRng::seed_from_u64(seed)` against the distribution function computed independently of
/// the sampler, `P(τ < t) = 1 − mass of rule_from(t)` (the family's own expectation rule,
/// plus the atoms at `t` for `P(τ ≤ t)`). Both sides are compared at [`KS_POINTS`] empirical
/// quantiles, a subset of the points of the full statistic, so `√n · D` over them exceeds
/// [`KS_THRESHOLD`] with at most the full test's probability for a correct sampler.
pub fn check_distribution<J: JitterModel + ?Sized>(model: &J, seed: u64) -> Result<(), String> {
    let mut rng = StdRng::seed_from_u64(seed);
    let draws: Vec<f64> = (0..MC_DRAWS).map(|_| model.sample(&mut rng)).collect();
    let mut fails = Vec::new();
    distribution(model, draws, &mut fails);
    report(model, fails)
}

fn distribution<J: JitterModel + ?Sized>(model: &J, mut draws: Vec<f64>, fails: &mut Vec<String>) {
    if draws.iter().any(|t| !t.is_finite()) {
        fails.push("a draw is not finite".into());
        return;
    }
    draws.sort_by(f64::total_cmp);
    let n = draws.len();
    let atoms = model.atoms();
    let mut d = 0.0f64;
    for j in 1..=KS_POINTS {
        let t = draws[(j * n / KS_POINTS).saturating_sub(1)];
        // P(τ < t) and P(τ ≤ t), the atoms at t making the difference.
        let below = 1.0 - model.rule_from(t, &[], 0.0).mass();
        let at: f64 = atoms
            .iter()
            .filter(|a| a.position == t)
            .map(|a| a.mass)
            .sum();
        let lt = draws.partition_point(|&x| x < t) as f64 / n as f64;
        let le = draws.partition_point(|&x| x <= t) as f64 / n as f64;
        d = d.max((le - (below + at)).abs()).max((lt - below).abs());
    }
    let stat = (n as f64).sqrt() * d;
    if !(stat <= KS_THRESHOLD) {
        fails.push(format!(
            "Kolmogorov–Smirnov: √n·D = {stat:.3} > {KS_THRESHOLD} for {n} draws"
        ));
    }
}

/// Holds a family's overrides of the provided methods against the trait's defaults, computed
/// by the independent routes of [`ProvidedDefaults`]:
///
/// * `mgf` against the default (the family's quadrature rule) at `z = -i2πf` for `2πf·s` up to
///   30 and at the small real parts of [`check_closed_forms`], to `1e-10` relative;
/// * `cf_gradient` against the default central differences, to the tolerance of
///   [`check_closed_forms`]' own difference check;
/// * `sample` and the default inverse-transform sampler ([`InverseSampler`](crate::InverseSampler))
///   both pass the Kolmogorov–Smirnov test of [`check_distribution`] (seeds `seed` and
///   `seed + 1`).
pub fn check_overrides<J: JitterModel + Clone>(model: &J, seed: u64) -> Result<(), String> {
    let mut fails = Vec::new();
    let defaults = ProvidedDefaults(model.clone());
    let s = spread(model);
    let zs = RULE_FREQS
        .iter()
        .flat_map(|&c| [c, -c])
        .map(|c| Complex64::new(0.0, -c / s))
        .chain(
            [
                Complex64::new(0.05, 0.0),
                Complex64::new(-0.05, 0.0),
                Complex64::new(-0.03, 0.7),
                Complex64::new(0.02, -2.0),
            ]
            .map(|z| z / s),
        );
    for z in zs {
        if let (Some(m), Some(d)) = (model.mgf(z), defaults.mgf(z)) {
            if !((m - d).norm() <= RULE_CF_TOL * m.norm().max(1.0)) {
                fails.push(format!("mgf({z}) = {m} but the default gives {d}"));
            }
        }
    }
    let p = model.params();
    for c in MODERATE {
        let f = freq(c, s);
        let (g, exact, fd) = (model.cf(f), model.cf_gradient(f), defaults.cf_gradient(f));
        if exact.len() != fd.len() {
            fails.push(format!(
                "cf_gradient has {} entries, the default {}",
                exact.len(),
                fd.len()
            ));
            break;
        }
        for (j, (a, b)) in exact.iter().zip(&fd).enumerate() {
            let scale = p[j].abs().max(s);
            if !((a - b).norm() <= FD_TOL * (a.norm() + g.norm() / scale)) {
                fails.push(format!(
                    "∂γ/∂θ_{j} = {a} but the default central difference gives {b} at 2πf·s = {c}"
                ));
            }
        }
    }
    let mut rng = StdRng::seed_from_u64(seed);
    let draws = (0..MC_DRAWS).map(|_| model.sample(&mut rng)).collect();
    distribution(model, draws, &mut fails);
    // The default `sample` is one draw of an `InverseSampler` built afresh; building it once
    // gives the same draws without recomputing the pieces' masses for each.
    let mut rng = StdRng::seed_from_u64(seed.wrapping_add(1));
    let sampler = crate::InverseSampler::new(model);
    let draws = (0..MC_DRAWS).map(|_| sampler.draw(&mut rng)).collect();
    let mut default_fails = Vec::new();
    distribution(model, draws, &mut default_fails);
    fails.extend(
        default_fails
            .into_iter()
            .map(|f| format!("default sampler: {f}")),
    );
    report(model, fails)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Atom, Gaussian, UniformSum};
    use rand::RngCore;

    /// A deliberately broken family: right closed forms but the paper's misprinted
    /// `πfa` in `cf`, so the quadrature and sampler checks must catch it.
    #[derive(Debug, Clone)]
    struct Misprinted(UniformSum);

    impl JitterModel for Misprinted {
        fn name(&self) -> &'static str {
            "misprinted"
        }
        fn param_names(&self) -> Vec<String> {
            self.0.param_names()
        }
        fn params(&self) -> Vec<f64> {
            self.0.params()
        }
        fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
            self.0.with_params(params).map(Misprinted)
        }
        fn cf(&self, f: f64) -> Complex64 {
            self.0.cf(0.5 * f)
        }
        fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
            self.0.cf_gradient(0.5 * f)
        }
        fn mgf(&self, _z: Complex64) -> Option<Complex64> {
            None
        }
        fn pdf(&self, tau: f64) -> f64 {
            self.0.pdf(tau)
        }
        fn atoms(&self) -> Vec<Atom> {
            Vec::new()
        }
        fn pieces(&self) -> Vec<(f64, f64)> {
            self.0.pieces()
        }
        fn mean(&self) -> f64 {
            0.0
        }
        fn variance(&self) -> f64 {
            self.0.variance()
        }
        fn sample(&self, rng: &mut dyn RngCore) -> f64 {
            self.0.sample(rng)
        }
    }

    #[test]
    fn a_misprinted_characteristic_function_is_caught() {
        let m = Misprinted(UniformSum::new(2, 0.5).unwrap());
        let err = check_contract(&m, 7).unwrap_err();
        assert!(err.contains("quadrature gives E[e^(-i2πfτ)]"), "{err}");
        assert!(err.contains("empirical E[e^(-i2πfτ)]"), "{err}");
    }

    #[test]
    fn a_parameter_wrongly_declared_even_is_caught() {
        // The exponential delay's mean enters γ = 1/(1 + i2πf·mean) linearly at 0.
        #[derive(Debug, Clone)]
        struct ClaimsEven(crate::ExponentialDelay);
        impl JitterModel for ClaimsEven {
            fn name(&self) -> &'static str {
                "claims-even"
            }
            fn param_names(&self) -> Vec<String> {
                self.0.param_names()
            }
            fn params(&self) -> Vec<f64> {
                self.0.params()
            }
            fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
                self.0.with_params(params).map(ClaimsEven)
            }
            fn cf(&self, f: f64) -> Complex64 {
                self.0.cf(f)
            }
            fn pdf(&self, tau: f64) -> f64 {
                self.0.pdf(tau)
            }
            fn pieces(&self) -> Vec<(f64, f64)> {
                self.0.pieces()
            }
            fn mean(&self) -> f64 {
                self.0.mean()
            }
            fn variance(&self) -> f64 {
                self.0.variance()
            }
            fn even_params(&self) -> Vec<bool> {
                vec![true]
            }
        }
        let m = ClaimsEven(crate::ExponentialDelay::new(0.3).unwrap());
        let err = check_closed_forms(&m).unwrap_err();
        assert!(err.contains("declared even"), "{err}");
        // The same family without the claim passes, and so do the shipped even widths.
        check_closed_forms(&m.0).unwrap();
        check_closed_forms(&Gaussian::new(0.2).unwrap()).unwrap();
        check_closed_forms(&UniformSum::new(2, 0.3).unwrap()).unwrap();
    }

    #[test]
    fn a_wrong_variance_is_caught() {
        #[derive(Debug, Clone)]
        struct Wide(Gaussian);
        impl JitterModel for Wide {
            fn name(&self) -> &'static str {
                "wide"
            }
            fn param_names(&self) -> Vec<String> {
                self.0.param_names()
            }
            fn params(&self) -> Vec<f64> {
                self.0.params()
            }
            fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
                self.0.with_params(params).map(Wide)
            }
            fn cf(&self, f: f64) -> Complex64 {
                self.0.cf(f)
            }
            fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
                self.0.cf_gradient(f)
            }
            fn mgf(&self, z: Complex64) -> Option<Complex64> {
                self.0.mgf(z)
            }
            fn pdf(&self, tau: f64) -> f64 {
                self.0.pdf(tau)
            }
            fn pieces(&self) -> Vec<(f64, f64)> {
                self.0.pieces()
            }
            fn mean(&self) -> f64 {
                0.0
            }
            fn variance(&self) -> f64 {
                1.001 * self.0.variance()
            }
            fn sample(&self, rng: &mut dyn RngCore) -> f64 {
                self.0.sample(rng)
            }
        }
        let err = check_closed_forms(&Wide(Gaussian::new(0.1).unwrap())).unwrap_err();
        assert!(err.contains("rule variance"), "{err}");
    }
}
