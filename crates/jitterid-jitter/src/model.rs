pub(crate) use crate::kernels::complex::{cexp, phasor};
use crate::kernels::gauss::integrate;
use crate::rule::{build_rule, build_rule_from, QuadratureRule};
use crate::JitterError;
use num_complex::Complex64;
use rand::{Rng, RngCore};
use std::fmt;

/// A point mass of a jitter distribution: `P(τ = position) = mass`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Atom {
    /// Where the mass sits, in seconds.
    pub position: f64,
    /// The probability carried, in `(0, 1]`.
    pub mass: f64,
}

/// Probability mass that a family may leave outside its [`pieces`](JitterModel::pieces) when its
/// support is unbounded.
pub const TAIL_MASS: f64 = 1e-17;

/// A family of sampling-jitter distributions `p(τ; θ)`, with `τ` in seconds.
///
/// The required methods are what every family must give: its parameters
/// ([`param_names`](Self::param_names), [`params`](Self::params),
/// [`with_params`](Self::with_params)), its [`name`](Self::name), its characteristic function
/// [`cf`](Self::cf), its law ([`pdf`](Self::pdf) and [`pieces`](Self::pieces); [`atoms`](Self::atoms)
/// has the default "none") and its [`mean`](Self::mean) and [`variance`](Self::variance).
/// Everything else is provided from them: what only some estimators use
/// ([`mgf`](Self::mgf) by the family's own quadrature rule, [`cf_gradient`](Self::cf_gradient)
/// by central differences, [`sample`](Self::sample) by inverse-transform sampling) and what
/// the estimators need beyond the closed forms (reach, expectation rules). A family with a
/// closed form overrides the default; the shipped families override all three.
///
/// A family is a validated value: once built, no method can fail. The
/// [`testing::check_contract`](crate::testing::check_contract) helper checks a new family
/// against the properties every family must have, and
/// [`testing::check_overrides`](crate::testing::check_overrides) checks its overrides against
/// the provided defaults.
///
/// Conventions (see the crate docs): `γ(f) = E[e^{-i2πfτ}]`, `f` in Hz, and
/// `M(z) = E[e^{zτ}]`, so that `γ(f) = M(-i2πf)`.
pub trait JitterModel: fmt::Debug + Send + Sync + CfAtParams {
    /// Short name of the family, for messages and reports (for example `"uniform-sum"`).
    fn name(&self) -> &'static str;

    /// Names of the continuous parameters `θ`, in the order of [`params`](Self::params).
    fn param_names(&self) -> Vec<String>;

    /// The current continuous parameters `θ`.
    fn params(&self) -> Vec<f64>;

    /// The same family with parameters `θ` (structure such as the integer `n` of the uniform
    /// sum is kept). Validates like the constructor.
    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError>
    where
        Self: Sized;

    /// Characteristic function `γ(f) = E[e^{-i2πfτ}]`.
    fn cf(&self, f: f64) -> Complex64;

    /// `∂γ(f)/∂θ_j` for every parameter, in the order of [`params`](Self::params) (length
    /// [`num_params`](Self::num_params)).
    ///
    /// Provided: central differences of [`cf`](Self::cf) through
    /// [`with_params`](Self::with_params), with the step `h_j =`
    /// [`CF_GRADIENT_STEP`]` · |θ_j|` (`· σ` for `θ_j = 0`, `σ` the standard deviation, or 1
    /// if that is 0), accurate to about `1e-10` of the derivative's natural size
    /// `|∂γ/∂θ_j| + |γ|/|θ_j|`; the step is halved while `with_params` rejects `θ_j ± h_j`, and
    /// the difference is one-sided if that does not help (0 if no step is accepted). Costs
    /// `2p` rebuilds and `cf` evaluations; a family with a closed form overrides it.
    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        cf_gradient_by_differences(self, f)
    }

    /// Moment-generating function `M(z) = E[e^{zτ}]` at a complex `z`, or `None` where the
    /// expectation diverges.
    ///
    /// Provided: `Σ w_i e^{zτ_i} / Σ w_i` over the family's own quadrature rule
    /// [`rule(&[], |z|)`](Self::rule), always `Some` (a real `z` gives an exactly real value,
    /// an overflow `+∞`, never NaN). That is exact to rounding for a law whose support lies
    /// inside its [`pieces`](Self::pieces) and [`atoms`](Self::atoms) (bounded support). For
    /// an unbounded support it is the MGF of the law cut to its pieces: accurate while
    /// `e^{Re z·τ}` does not outgrow the tail mass left outside them (`|Re z|` small against
    /// the tails' decay rates), and finite where the true `M` diverges; a family with an
    /// unbounded tail therefore overrides it with its closed form (the shipped Gaussian,
    /// Laplace and exponential-delay families, and the combinators through their terms, do).
    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        Some(mgf_by_rule(self, z))
    }

    /// Density of the absolutely continuous part of the distribution (zero for a family made
    /// of atoms only).
    fn pdf(&self, tau: f64) -> f64;

    /// Point masses of the distribution, if any.
    fn atoms(&self) -> Vec<Atom> {
        Vec::new()
    }

    /// Intervals, sorted and non-overlapping, that carry the continuous part: the density is
    /// analytic inside each one, varies little enough over it for a 16-point Gauss–Legendre
    /// rule, and the mass outside all of them is below [`TAIL_MASS`]. Knots where the density
    /// is not smooth are interval ends.
    fn pieces(&self) -> Vec<(f64, f64)>;

    /// Mean `E[τ]`.
    fn mean(&self) -> f64;

    /// Variance `Var τ`.
    fn variance(&self) -> f64;

    /// One draw of `τ`.
    ///
    /// Provided: inverse-transform sampling on the [`pieces`](Self::pieces) and
    /// [`atoms`](Self::atoms). One uniform picks a piece or an atom with probability its mass
    /// (a piece's mass by the 16-point Gauss–Legendre rule the pieces are built for); a second
    /// is inverted through the piece's distribution function `∫_lo^t pdf`, by Newton steps
    /// kept inside a bisection bracket, to a few ulps. Exact up to that rounding and the
    /// [`TAIL_MASS`] the pieces leave out, but it costs tens of density evaluations per piece
    /// and per draw; a family with a direct sampler overrides it.
    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        sample_by_inversion(self, rng)
    }

    /// Number of continuous parameters.
    fn num_params(&self) -> usize {
        self.params().len()
    }

    /// For each parameter (in the order of [`params`](Self::params)), whether `γ` depends on
    /// it only through its square: the width of a law symmetric about 0, whose `γ(f)` is even
    /// in it and flat at 0. An estimator searches such a parameter in its square, where the
    /// first moment is smooth through 0 (in the width itself the moment's derivative vanishes
    /// at 0, and a search towards a small width crawls).
    ///
    /// Provided: `false` for every parameter (the search then moves it as it is); a family
    /// overrides it only where the claim holds, which `check_contract` tests.
    fn even_params(&self) -> Vec<bool> {
        vec![false; self.num_params()]
    }

    /// Standard deviation `√Var τ`.
    fn std_dev(&self) -> f64 {
        self.variance().sqrt()
    }

    /// The interval `[lo, hi]` outside which the distribution has mass below [`TAIL_MASS`]:
    /// a sample at `t` only sees `s` on `[t + lo, t + hi]`.
    fn reach(&self) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (a, b) in self.pieces() {
            lo = lo.min(a);
            hi = hi.max(b);
        }
        for atom in self.atoms() {
            lo = lo.min(atom.position);
            hi = hi.max(atom.position);
        }
        (lo, hi)
    }

    /// A quadrature rule for `E[h(τ)]` where `h` is analytic between the points `breaks`
    /// (in jitter time, relative to the requested sampling instant) and its fastest local rate
    /// is `rate` (1/s; the largest `|z|` of a factor `e^{zτ}` or `2πf` of an oscillation).
    fn rule(&self, breaks: &[f64], rate: f64) -> QuadratureRule {
        build_rule(self, breaks, rate)
    }

    /// The part of [`rule`](Self::rule) on `τ ≥ from`, for `E[h(τ) 1{τ ≥ from}]` (an atom
    /// exactly at `from` counts): half the nodes of cutting the full rule at `from`.
    fn rule_from(&self, from: f64, breaks: &[f64], rate: f64) -> QuadratureRule {
        build_rule_from(self, from, breaks, rate)
    }
}

/// Draws `n` jitter values.
///
/// # Errors
///
/// [`JitterError::Limit`] when `n` is beyond the library's limit on samples
/// ([`MAX_SAMPLES`](jitterid_numeric::limits::MAX_SAMPLES)) or the memory cannot be had: a
/// size that comes from a user is refused, not an abort.
pub fn sample_n<J: JitterModel + ?Sized>(
    jitter: &J,
    n: usize,
    rng: &mut dyn RngCore,
) -> Result<Vec<f64>, JitterError> {
    use jitterid_numeric::limits::{vec_with_capacity, Limit};
    let mut draws = vec_with_capacity(Limit::Samples, n)?;
    draws.extend((0..n).map(|_| jitter.sample(rng)));
    Ok(draws)
}

/// Relative step of the default [`cf_gradient`](JitterModel::cf_gradient): `ε^{1/3}`, which
/// balances the rounding error `ε|γ|/h` of a central difference against its truncation error
/// `h²|∂³γ|/6`, leaving about `ε^{2/3} ≈ 4e-11` of the derivative's natural size.
pub const CF_GRADIENT_STEP: f64 = 6.055_454_452_393_343e-6;

/// How many times the default [`cf_gradient`](JitterModel::cf_gradient) halves its step when
/// `with_params` rejects `θ_j ± h` (a parameter close to the edge of its domain).
const CF_GRADIENT_HALVINGS: u32 = 40;

/// The object-safe face of [`JitterModel::with_params`] that the provided
/// [`cf_gradient`](JitterModel::cf_gradient) needs: `γ(f)` of the same family at other
/// parameters. Implemented for every sized `JitterModel` (nothing to write), it lets the
/// default also serve a `dyn JitterModel`.
pub trait CfAtParams {
    /// `γ(f)` of `self.with_params(params)`.
    fn cf_at_params(&self, params: &[f64], f: f64) -> Result<Complex64, JitterError>;
}

impl<J: JitterModel> CfAtParams for J {
    fn cf_at_params(&self, params: &[f64], f: f64) -> Result<Complex64, JitterError> {
        self.with_params(params).map(|m| m.cf(f))
    }
}

/// The provided [`JitterModel::cf_gradient`]: central differences of `cf` through
/// `with_params`, step `h_j =` [`CF_GRADIENT_STEP`]` · |θ_j|` (`· s` for `θ_j = 0`, `s` the
/// standard deviation, or 1), halved while `θ_j ± h_j` is rejected, one-sided if it stays
/// rejected, 0 if no step is accepted.
pub(crate) fn cf_gradient_by_differences<J: JitterModel + ?Sized>(
    model: &J,
    f: f64,
) -> Vec<Complex64> {
    let p = model.params();
    let spread = match model.std_dev() {
        s if s.is_finite() && s > 0.0 => s,
        _ => 1.0,
    };
    (0..p.len())
        .map(|j| {
            let scale = if p[j] == 0.0 { spread } else { p[j].abs() };
            let at = |h: f64| {
                let mut q = p.clone();
                q[j] += h;
                let step = q[j] - p[j]; // the step actually taken, after rounding
                model.cf_at_params(&q, f).ok().map(|g| (g, step))
            };
            let mut h = CF_GRADIENT_STEP * scale;
            for _ in 0..=CF_GRADIENT_HALVINGS {
                if let (Some((up, hu)), Some((down, hd))) = (at(h), at(-h)) {
                    return (up - down) / (hu - hd);
                }
                h *= 0.5;
            }
            let h = CF_GRADIENT_STEP * scale;
            let g = model.cf(f);
            match (at(h), at(-h)) {
                (Some((up, hu)), _) => (up - g) / hu,
                (_, Some((down, hd))) => (g - down) / hd,
                _ => Complex64::new(0.0, 0.0),
            }
        })
        .collect()
}

/// The provided [`JitterModel::mgf`]: `Σ w_i e^{zτ_i} / Σ w_i` over the family's own rule
/// `rule(&[], |z|)` (divided by the rule's mass, so that `M(0) = 1` exactly and the rule's
/// rounding of the total mass does not scale every value), a real `z` giving an exactly real
/// result (an overflow is `+∞`, never NaN).
pub(crate) fn mgf_by_rule<J: JitterModel + ?Sized>(model: &J, z: Complex64) -> Complex64 {
    let rule = model.rule(&[], z.norm());
    let mass = rule.mass();
    if z.im == 0.0 {
        let m = rule.expect(|t| cexp(Complex64::new(z.re * t, 0.0)).re);
        return Complex64::new(m / mass, 0.0);
    }
    let re = rule.expect(|t| cexp(z * t).re);
    let im = rule.expect(|t| cexp(z * t).im);
    Complex64::new(re / mass, im / mass)
}

/// The provided [`JitterModel::sample`]: one draw of [`InverseSampler`].
pub(crate) fn sample_by_inversion<J: JitterModel + ?Sized>(
    model: &J,
    rng: &mut dyn RngCore,
) -> f64 {
    InverseSampler::new(model).draw(rng)
}

/// Inverse-transform sampling on a family's [`pieces`](JitterModel::pieces) and
/// [`atoms`](JitterModel::atoms), the route of the provided [`JitterModel::sample`] (which
/// builds one for each draw); built once, it draws many values at the cost of the inversion
/// alone.
///
/// One uniform picks a piece or an atom with probability its mass (a piece's mass by the
/// 16-point Gauss–Legendre rule the pieces are built for); a second is inverted through the
/// piece's distribution function `∫_lo^t pdf`, by Newton steps kept inside a bisection bracket.
#[derive(Debug)]
pub struct InverseSampler<'a, J: ?Sized> {
    model: &'a J,
    pieces: Vec<(f64, f64)>,
    atoms: Vec<Atom>,
    masses: Vec<f64>,
    total: f64,
}

impl<'a, J: JitterModel + ?Sized> InverseSampler<'a, J> {
    /// The sampler of `model`: its pieces' masses, computed once.
    pub fn new(model: &'a J) -> Self {
        let pieces = model.pieces();
        let atoms = model.atoms();
        let masses: Vec<f64> = pieces
            .iter()
            .map(|&(lo, hi)| integrate(lo, hi, 1, |t| model.pdf(t)))
            .chain(atoms.iter().map(|a| a.mass))
            .collect();
        let total = masses.iter().sum();
        InverseSampler {
            model,
            pieces,
            atoms,
            masses,
            total,
        }
    }

    /// One draw of `τ` (two uniforms from `rng`).
    pub fn draw(&self, rng: &mut dyn RngCore) -> f64 {
        let mut u = rng.random::<f64>() * self.total;
        // The category whose mass holds u; rounding may leave u just past the last one.
        let mut pick = self.masses.len().saturating_sub(1);
        for (k, &m) in self.masses.iter().enumerate() {
            if u < m {
                pick = k;
                break;
            }
            u -= m;
        }
        if pick >= self.pieces.len() {
            return self
                .atoms
                .get(pick - self.pieces.len())
                .map_or(f64::NAN, |a| a.position);
        }
        let (lo, hi) = self.pieces[pick];
        let target = rng.random::<f64>() * self.masses[pick];
        invert_piece(|t| self.model.pdf(t), lo, hi, self.masses[pick], target)
    }
}

/// The `t` in `[lo, hi]` with `∫_lo^t pdf = target`.
fn invert_piece(pdf: impl Fn(f64) -> f64, lo: f64, hi: f64, mass: f64, target: f64) -> f64 {
    let (mut a, mut b) = (lo, hi);
    // Start from the linear interpolation of the distribution function over the piece.
    let mut t = if mass > 0.0 {
        lo + (hi - lo) * (target / mass).clamp(0.0, 1.0)
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..200 {
        let g = integrate(lo, t, 1, &pdf) - target;
        if g > 0.0 {
            b = t;
        } else {
            a = t;
        }
        let d = pdf(t);
        let newton = t - g / d;
        let next = if d > 0.0 && newton > a && newton < b {
            newton
        } else {
            0.5 * (a + b)
        };
        // Converged once a step (or the bracket) is down to rounding of t or of the piece.
        let tiny = 4.0 * f64::EPSILON * t.abs().max(hi - lo);
        if (next - t).abs() <= tiny || b - a <= tiny {
            return next;
        }
        t = next;
    }
    t
}
