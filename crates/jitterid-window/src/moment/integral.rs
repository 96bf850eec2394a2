//! Route (a): the first moment as the literal frequency-domain integral of eq. (14b).
//!
//! The method (folding, trapezoidal rule, tail estimate) and its measured accuracy are described
//! in the docs of the parent module, [`crate::moment`].

use crate::direct::CompensatedSum;
use crate::{FrequencySet, Window, WindowError};
use jitterid_jitter::JitterModel;
use jitterid_numeric::phase::{cis_cycles, frac_prod};
use jitterid_signal::{SampleGrid, Spectrum};
use num_complex::Complex64;

/// Aliases per side summed before the first tail estimate.
const INITIAL_ALIASES: usize = 32;
/// Fraction of the target the alias tail may use.
const TAIL_SHARE: f64 = 0.25;
/// Rounding allowance, in units of `ε` times the absolute integral.
const ROUNDING_FACTOR: f64 = 64.0;
/// Safety factor on the numerically computed `‖K‖_{L¹}`.
const KERNEL_NORM_MARGIN: f64 = 1.1;
/// Smallest decay rate `p` (of `|G| ~ |ψ|^{-p}`) for which the tail is summed.
const MIN_DECAY: f64 = 1.25;

/// Accuracy target and limits of [`first_moment_integral`].
///
/// Deserializes through the same validation as [`first_moment_integral`] applies, so options
/// read from a file are valid.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "OptionFields")]
pub struct IntegralOptions {
    /// Relative target, relative to `max_f |μ_Y(f)|` over the requested set. Default `1e-10`.
    /// Finite and `≥ 0`; `rel_tol` and `abs_tol` must not both be zero.
    pub rel_tol: f64,
    /// Absolute target, added to the relative one. Default `0`. Finite and `≥ 0`.
    pub abs_tol: f64,
    /// Largest alias cut-off `M` (aliases summed on each side of the central period).
    /// Default 4096. At least 8 are needed for a tail estimate unless the spectrum vanishes.
    pub max_aliases: usize,
    /// Largest number of doublings of the quadrature nodes beyond the first `4·max(N, 8)`
    /// intervals per period. Default 6.
    pub max_refinements: usize,
}

impl Default for IntegralOptions {
    fn default() -> Self {
        Self {
            rel_tol: 1e-10,
            abs_tol: 0.0,
            max_aliases: 4096,
            max_refinements: 6,
        }
    }
}

impl IntegralOptions {
    fn validate(&self) -> Result<(), WindowError> {
        for (name, value) in [("rel_tol", self.rel_tol), ("abs_tol", self.abs_tol)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(WindowError::InvalidOption { name, value });
            }
        }
        if self.rel_tol == 0.0 && self.abs_tol == 0.0 {
            return Err(WindowError::InvalidOption {
                name: "rel_tol",
                value: 0.0,
            });
        }
        if self.max_aliases == 0 {
            return Err(WindowError::InvalidOption {
                name: "max_aliases",
                value: 0.0,
            });
        }
        Ok(())
    }
}

/// The serialized form of [`IntegralOptions`], validated on the way in.
#[derive(serde::Deserialize)]
struct OptionFields {
    rel_tol: f64,
    abs_tol: f64,
    max_aliases: usize,
    max_refinements: usize,
}

impl TryFrom<OptionFields> for IntegralOptions {
    type Error = WindowError;
    fn try_from(o: OptionFields) -> Result<Self, WindowError> {
        let options = IntegralOptions {
            rel_tol: o.rel_tol,
            abs_tol: o.abs_tol,
            max_aliases: o.max_aliases,
            max_refinements: o.max_refinements,
        };
        options.validate().map(|()| options)
    }
}

/// The result of [`first_moment_integral`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IntegralMoment {
    /// `μ_Y(f)` at each requested frequency, in the set's order.
    pub values: Vec<Complex64>,
    /// Estimated bound on `|error|` of each value.
    pub error_bounds: Vec<f64>,
    /// The alias cut-off `M` reached.
    pub aliases: usize,
    /// Quadrature intervals per period reached.
    pub intervals: usize,
    /// The alias-tail part of every bound.
    pub tail_bound: f64,
}

/// One quadrature node of the folded period: `ψ_q`, `A(ψ_q) = Σ_m G(ψ_q + mP)` and
/// `Σ_m |G(ψ_q + mP)|`.
#[derive(Debug, Clone, Copy)]
struct Node {
    /// Position in periods, `q/Q − 1/2`.
    u: f64,
    sum: Complex64,
    abs: f64,
}

/// The folded integrand on the trapezoidal nodes of one period.
struct Folded<'a, S: ?Sized> {
    signal: &'a S,
    jitter: &'a dyn JitterModel,
    t0: f64,
    period: f64,
    intervals: usize,
    nodes: Vec<Node>,
    aliases: usize,
    /// `max_q |G(ψ_q + mP)|` for `m = 0, 1, …` (index `m`) and `m = 0, −1, …` (index `−m`).
    max_pos: Vec<f64>,
    max_neg: Vec<f64>,
}

impl<S: Spectrum + ?Sized> Folded<'_, S> {
    /// `G(ψ) = S_c(ψ) γ(-ψ) e^{i2πψ t0}`.
    fn integrand(&self, psi: f64) -> Complex64 {
        self.signal.density(psi) * self.jitter.cf(-psi) * cis_cycles(frac_prod(psi, self.t0))
    }

    /// Adds the aliases `±m` for `m` in `ms` to the nodes `start, start + step, …`.
    fn accumulate(
        &mut self,
        ms: std::ops::RangeInclusive<usize>,
        start: usize,
        step: usize,
    ) -> Result<(), WindowError> {
        let last = *ms.end();
        if self.max_pos.len() <= last {
            self.max_pos.resize(last + 1, 0.0);
            self.max_neg.resize(last + 1, 0.0);
        }
        for m in ms {
            let shifts: &[f64] = if m == 0 {
                &[0.0]
            } else {
                &[m as f64, -(m as f64)]
            };
            for &shift in shifts {
                let mut peak = 0.0_f64;
                for q in (start..self.nodes.len()).step_by(step) {
                    let psi = self.period * (self.nodes[q].u + shift);
                    let g = self.integrand(psi);
                    let a = g.norm();
                    if !a.is_finite() {
                        return Err(WindowError::NonFiniteSpectrum {
                            frequency: psi,
                            value: a,
                        });
                    }
                    let node = &mut self.nodes[q];
                    node.sum += g;
                    node.abs += a;
                    peak = peak.max(a);
                }
                let slot = if shift < 0.0 {
                    &mut self.max_neg[m]
                } else {
                    &mut self.max_pos[m]
                };
                *slot = slot.max(peak);
            }
        }
        Ok(())
    }

    /// Raises the alias cut-off to `m`.
    fn extend_aliases(&mut self, m: usize) -> Result<(), WindowError> {
        if m > self.aliases {
            self.accumulate(self.aliases + 1..=m, 0, 1)?;
            self.aliases = m;
        }
        Ok(())
    }

    /// Doubles the intervals per period: the old nodes become the even ones, the new odd ones
    /// get every alias up to the current cut-off.
    fn refine(&mut self) -> Result<(), WindowError> {
        let q2 = 2 * self.intervals;
        let mut nodes = Vec::with_capacity(q2 + 1);
        for (q, old) in self.nodes.iter().enumerate() {
            nodes.push(*old);
            if q < self.intervals {
                nodes.push(Node {
                    u: (2 * q + 1) as f64 / q2 as f64 - 0.5,
                    sum: Complex64::new(0.0, 0.0),
                    abs: 0.0,
                });
            }
        }
        self.nodes = nodes;
        self.intervals = q2;
        self.accumulate(0..=self.aliases, 1, 2)
    }

    /// Estimated `Σ_{|m|>M} sup_P |G(·+mP)|`.
    fn tail_sum(&self) -> f64 {
        let m = self.aliases;
        tail_side(&self.max_pos[..=m]) + tail_side(&self.max_neg[..=m])
    }
}

/// Estimated `Σ_{m>M} e_m` from `e_1..e_M` (`e[0]` is ignored), assuming the decay over the
/// last three octaves continues.
fn tail_side(e: &[f64]) -> f64 {
    let m = e.len().saturating_sub(1);
    let octave = |lo: usize, hi: usize| e[lo + 1..=hi].iter().fold(0.0_f64, |a, &b| a.max(b));
    if m < 8 {
        return if e.iter().skip(1).all(|&x| x == 0.0) {
            0.0
        } else {
            f64::INFINITY
        };
    }
    let last = octave(m / 2, m);
    if last == 0.0 {
        return 0.0;
    }
    let mid = octave(m / 4, m / 2);
    let first = octave(m / 8, m / 4);
    let p = (mid / last).log2().min((first / mid).log2());
    if p.is_nan() || p <= MIN_DECAY {
        return f64::INFINITY;
    }
    let q = (1.0 - p).exp2();
    last * (m as f64 / 2.0) * q / (1.0 - q)
}

/// `∫_P |K(ψ)| dψ`, by the periodic trapezoidal rule with 16 nodes per lobe.
fn kernel_l1<W: Window + ?Sized>(grid: &SampleGrid, window: &W) -> f64 {
    let period = 1.0 / grid.interval();
    let count = 16 * grid.len().max(8);
    let h = period / count as f64;
    (0..count)
        .map(|q| window.kernel(grid, q as f64 * h).norm())
        .sum::<f64>()
        * h
}

/// Per-frequency evaluation of the current rule.
struct Evaluation {
    values: Vec<Complex64>,
    quadrature: Vec<f64>,
    rounding: Vec<f64>,
}

fn evaluate<S: Spectrum + ?Sized, W: Window + ?Sized>(
    folded: &Folded<'_, S>,
    grid: &SampleGrid,
    window: &W,
    freqs: &FrequencySet,
    lines: &[(f64, Complex64)],
) -> Evaluation {
    let q_max = folded.intervals;
    let h = folded.period / q_max as f64;
    let mut out = Evaluation {
        values: Vec::with_capacity(freqs.len()),
        quadrature: Vec::with_capacity(freqs.len()),
        rounding: Vec::with_capacity(freqs.len()),
    };
    for &f in freqs.frequencies() {
        let mut fine = CompensatedSum::default();
        let mut coarse = CompensatedSum::default();
        let mut absolute = 0.0;
        for (q, node) in folded.nodes.iter().enumerate() {
            let k = window.kernel(grid, f - folded.period * node.u);
            let end = q == 0 || q == q_max;
            let w = if end { 0.5 * h } else { h };
            let term = node.sum * k;
            fine.add(term * w);
            if q % 2 == 0 {
                coarse.add(term * (2.0 * w));
            }
            absolute += w * node.abs * k.norm();
        }
        let mut line_sum = CompensatedSum::default();
        for &(fl, a) in lines {
            let term = a * window.kernel(grid, f - fl);
            absolute += term.norm();
            line_sum.add(term);
        }
        let fine = fine.value();
        out.values.push(fine + line_sum.value());
        out.quadrature.push((fine - coarse.value()).norm());
        out.rounding.push(ROUNDING_FACTOR * f64::EPSILON * absolute);
    }
    out
}

/// `μ_Y(f)` at every frequency of the set by the literal eq. (14b) (route a, the reference):
/// `∫ S_c(ψ) γ(-ψ) e^{i2πψ t0} K(f-ψ) dψ + Σ_l c_l γ(-f_l) e^{i2πf_l t0} K(f-f_l)`, with an error
/// bound per frequency.
///
/// Uses only the signal's [`density`](Spectrum::density) and [`lines`](Spectrum::lines), the
/// jitter's [`cf`](JitterModel::cf) and the window's [`kernel`](Window::kernel). The infinite
/// range is folded onto one period `1/T` by summing aliases, cut where an extrapolated tail
/// estimate meets a quarter of the target; the folded periodic integrand is integrated by the
/// trapezoidal rule, refined until two nested rules agree. The [module docs](crate::moment)
/// give the details and the measured accuracy (about `2e-14` relative to `max|μ_Y|` against
/// [`first_moment`](crate::first_moment)).
///
/// Cost: `(Q+1)(2M+1)` evaluations of `S_c γ` (`Q ≥ 4N` nodes per period, `M` aliases per side)
/// plus `(Q+1)·F` kernel evaluations for `F` frequencies.
///
/// Errors: invalid options; a non-finite `S_c γ` or line
/// ([`WindowError::NonFiniteSpectrum`]); the target not reached within `max_aliases` and
/// `max_refinements` ([`WindowError::NotConverged`], naming the worst frequency and its bound).
pub fn first_moment_integral<S, W>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    window: &W,
    freqs: &FrequencySet,
    options: &IntegralOptions,
) -> Result<IntegralMoment, WindowError>
where
    S: Spectrum + ?Sized,
    W: Window + ?Sized,
{
    options.validate()?;
    let t0 = grid.start();
    let period = 1.0 / grid.interval();

    // The line part, in closed form: a_l = c_l γ(-f_l) e^{i2πf_l t0}.
    let mut lines = Vec::new();
    for line in signal.lines() {
        let a = line.coefficient
            * jitter.cf(-line.frequency)
            * cis_cycles(frac_prod(line.frequency, t0));
        if !(line.frequency.is_finite() && a.re.is_finite() && a.im.is_finite()) {
            return Err(WindowError::NonFiniteSpectrum {
                frequency: line.frequency,
                value: a.norm(),
            });
        }
        lines.push((line.frequency, a));
    }

    let intervals = 4 * grid.len().max(8);
    let mut folded = Folded {
        signal,
        jitter,
        t0,
        period,
        intervals,
        nodes: (0..=intervals)
            .map(|q| Node {
                u: q as f64 / intervals as f64 - 0.5,
                sum: Complex64::new(0.0, 0.0),
                abs: 0.0,
            })
            .collect(),
        aliases: 0,
        max_pos: Vec::new(),
        max_neg: Vec::new(),
    };
    folded.accumulate(0..=0, 0, 1)?;
    folded.extend_aliases(INITIAL_ALIASES.min(options.max_aliases))?;
    let kernel_norm = KERNEL_NORM_MARGIN * kernel_l1(grid, window);
    let mut refinements = 0;

    loop {
        let tail = kernel_norm * folded.tail_sum();
        let eval = evaluate(&folded, grid, window, freqs, &lines);
        let scale = eval.values.iter().fold(0.0_f64, |a, v| a.max(v.norm()));
        let target = options.abs_tol + options.rel_tol * scale;
        let bounds: Vec<f64> = eval
            .quadrature
            .iter()
            .zip(&eval.rounding)
            .map(|(q, r)| q + r + tail)
            .collect();
        // The frequency furthest over its target (all share one target).
        let (worst, worst_bound) =
            bounds
                .iter()
                .copied()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |acc, (i, b)| {
                    if b > acc.1 || b.is_nan() {
                        (i, b)
                    } else {
                        acc
                    }
                });
        if worst_bound <= target {
            return Ok(IntegralMoment {
                values: eval.values,
                error_bounds: bounds,
                aliases: folded.aliases,
                intervals: folded.intervals,
                tail_bound: tail,
            });
        }
        let quad = eval.quadrature[worst];
        let round = eval.rounding[worst];
        let can_alias = folded.aliases < options.max_aliases;
        let can_refine = refinements < options.max_refinements;
        if tail > TAIL_SHARE * target && can_alias {
            let next = (2 * folded.aliases)
                .max(INITIAL_ALIASES)
                .min(options.max_aliases);
            folded.extend_aliases(next)?;
        } else if quad >= round && quad > 0.0 && can_refine {
            folded.refine()?;
            refinements += 1;
        } else if tail > 0.0 && tail >= quad && can_alias {
            let next = (2 * folded.aliases).min(options.max_aliases);
            folded.extend_aliases(next)?;
        } else {
            return Err(WindowError::NotConverged {
                frequency: freqs.frequencies().get(worst).copied().unwrap_or(f64::NAN),
                error_bound: worst_bound,
                target,
                aliases: folded.aliases,
                nodes: folded.intervals,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_of_a_power_law() {
        // e_m = m^-4: the tail beyond M = 64 is about ∫_64^∞ x^-4 dx = 1.27e-6.
        let e: Vec<f64> = (0..=64)
            .map(|m| if m == 0 { 0.0 } else { (m as f64).powi(-4) })
            .collect();
        let t = tail_side(&e);
        let exact: f64 = (65..100_000).map(|m| (m as f64).powi(-4)).sum();
        assert!(t >= exact && t < 20.0 * exact, "{t} vs {exact}");
        // 1/m decay is not summable.
        let e: Vec<f64> = (0..=64).map(|m| 1.0 / (m.max(1) as f64)).collect();
        assert_eq!(tail_side(&e), f64::INFINITY);
        // Nothing left.
        assert_eq!(tail_side(&[0.0; 40]), 0.0);
        assert_eq!(tail_side(&[1.0, 0.0, 0.0]), 0.0);
        assert_eq!(tail_side(&[1.0, 1.0, 0.0]), f64::INFINITY);
    }

    #[test]
    fn options_are_validated() {
        let bad = IntegralOptions {
            rel_tol: -1.0,
            ..IntegralOptions::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(WindowError::InvalidOption {
                name: "rel_tol",
                ..
            })
        ));
        let bad = IntegralOptions {
            abs_tol: f64::NAN,
            ..IntegralOptions::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(WindowError::InvalidOption {
                name: "abs_tol",
                ..
            })
        ));
        assert!(IntegralOptions::default().validate().is_ok());
    }
}
