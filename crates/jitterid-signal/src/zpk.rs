//! `G(s) = k · Π (s − z_i) / Π (s − p_i)`: the zero–pole–gain parameterisation of a
//! [`Rational`], with its roots as parameters ([`Root`]).

use crate::error::{finite, SignalError};
use crate::poly;
use crate::rational::{Rational, RationalModel};
use crate::root::{group_repeated, Root};

/// `G(s) = k · Π (s − z_i) / Π (s − p_i)` with real roots, complex pairs and quadratic factors.
///
/// Parameters: the gain, then each zero, then each pole; a real root is one parameter, a pair
/// two (real part, then imaginary part), a quadratic factor two (`a1`, `a0`). A real root given
/// twice (a double pole `(s + 0.5)²` written as two poles `-0.5`) is one quadratic factor from
/// construction on, so that the estimate may pass through the coincidence into a complex pair,
/// with a covariance there (see [`Root::Quadratic`]). The paper's eq. (17),
/// `G(s) = k0 (s + z) / ((s − pr − i·pi)(s − pr + i·pi))`, is
/// `Zpk::new(k0, vec![Root::Real(-z)], vec![Root::Pair { re: pr, im: pi }])`.
///
/// Serializes as `{gain, zeros, poles}`; deserializes through [`Zpk::new`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "ZpkFields", into = "ZpkFields")]
pub struct Zpk {
    gain: f64,
    zeros: Vec<Root>,
    poles: Vec<Root>,
    /// Per pole: held at the origin (an integrator, not a parameter).
    held: Vec<bool>,
    rational: Rational,
}

/// `Π` of the roots' factors, and its derivatives with respect to the parameters of the roots
/// not `held` (a missing entry of `held` is false).
fn expand(roots: &[Root], held: &[bool]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let factors: Vec<_> = roots.iter().map(Root::factor).collect();
    let mut prod = vec![1.0];
    for (f, _) in &factors {
        prod = poly::mul(&prod, f);
    }
    let mut d = Vec::new();
    for (i, (_, dfs)) in factors.iter().enumerate() {
        if held.get(i).copied().unwrap_or(false) {
            continue;
        }
        for df in dfs {
            let mut p = vec![1.0];
            for (l, (f, _)) in factors.iter().enumerate() {
                p = poly::mul(&p, if l == i { df } else { f });
            }
            d.push(p);
        }
    }
    (prod, d)
}

impl Zpk {
    /// Validates finite values, pairs with `im > 0`, at most as many zeros as poles, at least
    /// one pole, poles with real part `≤ 0` (repeated poles and integrators are accepted). Each
    /// nonzero real root that occurs twice in `zeros` or in `poles` becomes one
    /// [`Root::Quadratic`] at the first one's place (the second leaves the list).
    pub fn new(gain: f64, zeros: Vec<Root>, poles: Vec<Root>) -> Result<Self, SignalError> {
        Self::build(
            gain,
            group_repeated(zeros),
            group_repeated(poles),
            false,
            &[],
        )
    }

    /// The same model with `n` of its real poles at exactly 0 (the first `n` in the list)
    /// structural: held there in every `with_params` and not parameters. Refused
    /// ([`SignalError::Integrators`]) when the list has fewer than `n` poles at 0.
    pub fn with_integrators(&self, n: usize) -> Result<Self, SignalError> {
        let held = crate::integrators::held_poles(&self.poles, n).ok_or_else(|| {
            SignalError::Integrators {
                integrators: n,
                at_origin: crate::integrators::at_origin(&self.poles),
                poles: self.poles.iter().map(Root::count).sum(),
            }
        })?;
        Self::build(
            self.gain,
            self.zeros.clone(),
            self.poles.clone(),
            self.rational.unstable,
            &held,
        )
    }

    /// The number of poles held at the origin ([`with_integrators`](Self::with_integrators)).
    pub fn integrators(&self) -> usize {
        self.held.iter().filter(|&&h| h).count()
    }

    /// As [`new`](Self::new), but poles right of the imaginary axis are accepted, here and in
    /// every `with_params` of the model (an estimate may cross the axis).
    pub fn new_allowing_unstable(
        gain: f64,
        zeros: Vec<Root>,
        poles: Vec<Root>,
    ) -> Result<Self, SignalError> {
        Self::build(
            gain,
            group_repeated(zeros),
            group_repeated(poles),
            true,
            &[],
        )
    }

    /// `held[i]`: pole `i` is an integrator held at 0 (checked by the callers; missing
    /// entries are false).
    fn build(
        gain: f64,
        zeros: Vec<Root>,
        poles: Vec<Root>,
        unstable: bool,
        held: &[bool],
    ) -> Result<Self, SignalError> {
        finite("gain", gain)?;
        zeros.iter().try_for_each(|z| z.validate("zero"))?;
        poles.iter().try_for_each(|p| p.validate("pole"))?;
        let nz: usize = zeros.iter().map(Root::count).sum();
        let np: usize = poles.iter().map(Root::count).sum();
        if np == 0 {
            return Err(SignalError::TooFew {
                name: "poles",
                min: 1,
                value: 0,
            });
        }
        if nz > np {
            return Err(SignalError::Improper {
                zeros: nz,
                poles: np,
            });
        }
        // Before the expansion, whose sensitivities take `np²` numbers.
        jitterid_numeric::limits::check(jitterid_numeric::limits::Limit::Poles, np)?;
        let (zn, dzn) = expand(&zeros, &[]);
        let (den, dden_p) = expand(&poles, held);
        let num: Vec<f64> = zn.iter().map(|c| gain * c).collect();
        let mut d_num = vec![zn.clone()];
        let mut d_den = vec![vec![0.0; den.len()]];
        for dz in &dzn {
            d_num.push(dz.iter().map(|c| gain * c).collect());
            d_den.push(vec![0.0; den.len()]);
        }
        for dp in dden_p {
            d_num.push(vec![0.0; num.len()]);
            d_den.push(dp);
        }
        let pole_values = poles.iter().flat_map(Root::values).collect();
        let rational = Rational::with_poles(num, den, pole_values, d_num, d_den, unstable)?;
        let held = (0..poles.len())
            .map(|i| held.get(i).copied().unwrap_or(false))
            .collect();
        Ok(Self {
            gain,
            zeros,
            poles,
            held,
            rational,
        })
    }

    /// The gain `k`.
    pub fn gain(&self) -> f64 {
        self.gain
    }

    /// The zeros.
    pub fn zeros(&self) -> &[Root] {
        &self.zeros
    }

    /// The poles (a repeated real pole given at construction is one [`Root::Quadratic`]).
    pub fn poles(&self) -> &[Root] {
        &self.poles
    }
}

/// The parameter names of the roots not `held` (by their index in the whole list).
fn root_names(prefix: &str, roots: &[Root], held: &[bool], out: &mut Vec<String>) {
    for (i, r) in roots.iter().enumerate() {
        if held.get(i).copied().unwrap_or(false) {
            continue;
        }
        match r {
            Root::Real(_) => out.push(format!("{prefix}{i}")),
            Root::Pair { .. } => {
                out.push(format!("{prefix}{i}.re"));
                out.push(format!("{prefix}{i}.im"));
            }
            Root::Quadratic { .. } => {
                out.push(format!("{prefix}{i}.a1"));
                out.push(format!("{prefix}{i}.a0"));
            }
        }
    }
}

fn push_root_params(roots: &[Root], held: &[bool], out: &mut Vec<f64>) {
    for (i, r) in roots.iter().enumerate() {
        if held.get(i).copied().unwrap_or(false) {
            continue;
        }
        match *r {
            Root::Real(x) => out.push(x),
            Root::Pair { re, im } => out.extend([re, im]),
            Root::Quadratic { a1, a0 } => out.extend([a1, a0]),
        }
    }
}

/// Roots shaped as `template`, the `held` ones copied, the others read from `params`.
fn roots_from(
    template: &[Root],
    held: &[bool],
    params: &mut impl Iterator<Item = f64>,
) -> Vec<Root> {
    template
        .iter()
        .enumerate()
        .map(|(i, r)| match r {
            _ if held.get(i).copied().unwrap_or(false) => *r,
            Root::Real(_) => Root::Real(params.next().unwrap_or(f64::NAN)),
            Root::Pair { .. } => Root::Pair {
                re: params.next().unwrap_or(f64::NAN),
                im: params.next().unwrap_or(f64::NAN),
            },
            Root::Quadratic { .. } => Root::Quadratic {
                a1: params.next().unwrap_or(f64::NAN),
                a0: params.next().unwrap_or(f64::NAN),
            },
        })
        .collect()
}

impl RationalModel for Zpk {
    fn param_names(&self) -> Vec<String> {
        let mut names = vec!["gain".to_string()];
        root_names("zero", &self.zeros, &[], &mut names);
        root_names("pole", &self.poles, &self.held, &mut names);
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p = vec![self.gain];
        push_root_params(&self.zeros, &[], &mut p);
        push_root_params(&self.poles, &self.held, &mut p);
        p
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        let expected = self.rational.d_num.len();
        if params.len() != expected {
            return Err(SignalError::WrongParamCount {
                expected,
                got: params.len(),
            });
        }
        let mut it = params[1..].iter().copied();
        let zeros = roots_from(&self.zeros, &[], &mut it);
        let poles = roots_from(&self.poles, &self.held, &mut it);
        Self::build(params[0], zeros, poles, self.rational.unstable, &self.held)
    }

    fn rational(&self) -> &Rational {
        &self.rational
    }
}

/// The serialized form of a [`Zpk`].
#[derive(serde::Serialize, serde::Deserialize)]
struct ZpkFields {
    gain: f64,
    zeros: Vec<Root>,
    poles: Vec<Root>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    unstable: bool,
    #[serde(default, skip_serializing_if = "crate::integrators::is_zero")]
    integrators: usize,
}

impl TryFrom<ZpkFields> for Zpk {
    type Error = SignalError;
    fn try_from(z: ZpkFields) -> Result<Self, SignalError> {
        let g = Self::build(
            z.gain,
            group_repeated(z.zeros),
            group_repeated(z.poles),
            z.unstable,
            &[],
        )?;
        if z.integrators == 0 {
            Ok(g)
        } else {
            g.with_integrators(z.integrators)
        }
    }
}

impl From<Zpk> for ZpkFields {
    fn from(z: Zpk) -> Self {
        Self {
            integrators: z.integrators(),
            unstable: z.rational.unstable,
            gain: z.gain,
            zeros: z.zeros,
            poles: z.poles,
        }
    }
}
