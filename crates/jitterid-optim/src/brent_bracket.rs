//! Brent's iterations started from a bracket whose three values are known.
//!
//! argmin's [`BrentOpt`](argmin::solver::brent::BrentOpt) takes only the ends of a bracket: it
//! evaluates its own first point (the golden-section point of the interval) and, with one
//! point, needs two golden-section steps before a parabola can be fitted. After the bracket's
//! growth the three points `a, b, c` with `f(b) ≤ f(a), f(c)` and their values are known, so
//! the first step here is already the parabola through them. The update rules, the safeguards
//! and the stopping test (`|x − m| ≤ 2 tol − (hi − lo)/2`, `tol = eps |x| + t`) are those of
//! `BrentOpt`; only the start differs, so the minimum is located to the same tolerance.

/// One point and its value.
pub(crate) type Point = (f64, f64);

/// The outcome of [`minimize_from_bracket`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BracketResult {
    /// The best point found and its value.
    pub(crate) best: Point,
    /// Evaluations of `f` made here (the bracket's are not counted).
    pub(crate) evaluations: u64,
    /// Whether the stopping test was met (else `max_iters` ran out).
    pub(crate) converged: bool,
}

/// The decrease from `x` to the vertex of the parabola through `x`, `w`, `v` (distinct points,
/// finite values), when the parabola is convex and its vertex lies in `[lo, hi]`.
fn parabola_decrease(
    (x, fx): Point,
    (w, fw): Point,
    (v, fv): Point,
    (lo, hi): (f64, f64),
) -> Option<f64> {
    if !(fx.is_finite() && fw.is_finite() && fv.is_finite()) || x == w || x == v || w == v {
        return None;
    }
    // Divided differences: slope f[x, w], f[x, v], curvature 2 f[x, w, v].
    let (sw, sv) = ((fw - fx) / (w - x), (fv - fx) / (v - x));
    let c = 2.0 * (sw - sv) / (w - v);
    if !(c > 0.0) {
        return None;
    }
    // f(u) = fx + g (u − x) + c (u − x)²/2 with g = f[x, w] − c (w − x)/2.
    let g = sw - 0.5 * c * (w - x);
    let step = -g / c;
    let vertex = x + step;
    (vertex >= lo && vertex <= hi).then_some(0.5 * c * step * step)
}

/// Minimises `f` inside the bracket whose interior point is `best` and whose ends are `ends`
/// (`best.1 ≤` both ends' values), to the tolerance `eps |x| + t`, in at most `max_iters`
/// evaluations. `report(evaluations, best value)` is called after every evaluation.
///
/// With `cost_tol > 0` it also stops, before evaluating, when the parabola through the three
/// best points is convex, has its vertex inside the bracket, and predicts a decrease of the
/// best value by at most `cost_tol` (see [`Brent::cost_tolerance`](super::Brent)); on the
/// bracket's own three points only when their values span at most `100 cost_tol`.
pub(crate) fn minimize_from_bracket(
    mut f: impl FnMut(f64) -> f64,
    best: Point,
    ends: [Point; 2],
    (eps, t, cost_tol): (f64, f64, f64),
    max_iters: u64,
    mut report: impl FnMut(u64, f64),
) -> BracketResult {
    // Golden-section fraction, as in `BrentOpt`.
    let golden = (3.0 - 5f64.sqrt()) / 2.0;
    let (mut lo, mut hi) = (ends[0].0.min(ends[1].0), ends[0].0.max(ends[1].0));
    let (mut x, mut fx) = best;
    // `w` the second best point, `v` the third.
    let (mut w, mut fw, mut v, mut fv) = if ends[0].1 <= ends[1].1 {
        (ends[0].0, ends[0].1, ends[1].0, ends[1].1)
    } else {
        (ends[1].0, ends[1].1, ends[0].0, ends[0].1)
    };
    // The steps "before last": the bracket's width, so that a parabolic step is tried at once.
    let mut e = hi - lo;
    let mut d = e;
    let mut evaluations = 0;
    loop {
        let tol = eps * x.abs() + t;
        let m = 0.5 * (lo + hi);
        if (x - m).abs() <= 2.0 * tol - 0.5 * (hi - lo) {
            return BracketResult {
                best: (x, fx),
                evaluations,
                converged: true,
            };
        }
        if evaluations >= max_iters {
            return BracketResult {
                best: (x, fx),
                evaluations,
                converged: false,
            };
        }
        let p = (x - v) * (x - v) * (fx - fw) - (x - w) * (x - w) * (fx - fv);
        let q = 2.0 * ((x - w) * (fx - fv) - (x - v) * (fx - fw));
        // On the bracket alone only if its values span at most 100 cost_tol: its points may be
        // too far apart for the parabola to predict the minimum's value, but a model error of
        // a tenth of that span still leaves the value within 10 cost_tol.
        if cost_tol > 0.0 && (evaluations > 0 || fw.max(fv) - fx <= 100.0 * cost_tol) {
            if let Some(drop) = parabola_decrease((x, fx), (w, fw), (v, fv), (lo, hi)) {
                if drop <= cost_tol {
                    return BracketResult {
                        best: (x, fx),
                        evaluations,
                        converged: true,
                    };
                }
            }
        }
        let (p, q) = if q >= 0.0 { (p, q) } else { (-p, -q) };
        // Infinite values (invalid trial points) give no parabola: a golden-section step.
        let parabola_usable = p.is_finite() && q.is_finite();
        d = if !parabola_usable
            || e.abs() <= tol
            || p < q * (lo - x)
            || p > q * (hi - x)
            || 2.0 * p.abs() >= q * e.abs()
        {
            e = if x < m { hi } else { lo } - x;
            golden * e
        } else {
            e = d;
            let step = p / q;
            if x + step - lo < 2.0 * tol || hi - x - step < 2.0 * tol {
                (m - x).signum() * tol
            } else {
                step
            }
        };
        let u = x + if d.abs() >= tol { d } else { d.signum() * tol };
        let fu = f(u);
        evaluations += 1;
        if fu <= fx {
            if u < x {
                hi = x;
            } else {
                lo = x;
            }
            (v, fv) = (w, fw);
            (w, fw) = (x, fx);
            (x, fx) = (u, fu);
        } else {
            if u < x {
                lo = u;
            } else {
                hi = u;
            }
            if fu <= fw || w == x {
                (v, fv) = (w, fw);
                (w, fw) = (u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
        report(evaluations, fx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use argmin::core::{CostFunction, Error, Executor};
    use argmin::solver::brent::BrentOpt;

    /// argmin's test function `e^{−x} − e^{5 − x/2}`, skewed about its minimum.
    fn skewed(x: f64) -> f64 {
        (-x).exp() - (5.0 - x / 2.0).exp()
    }

    struct Skewed;
    impl CostFunction for Skewed {
        type Param = f64;
        type Output = f64;
        fn cost(&self, x: &f64) -> Result<f64, Error> {
            Ok(skewed(*x))
        }
    }

    /// `f'(x) = −e^{−x} + ½ e^{5 − x/2} = 0` ⇔ `e^{−x/2} = ½ e^{5}` ⇔ `x = −2 (5 − ln 2)`.
    fn skewed_minimum() -> f64 {
        -2.0 * (5.0 - std::f64::consts::LN_2)
    }

    #[test]
    fn finds_the_minimum_to_the_tolerance_in_fewer_evaluations_than_brentopt() {
        let (lo, mid, hi) = (-10.0, -8.0, 10.0);
        let tol = (f64::EPSILON.sqrt(), 1e-8, 0.0);
        let mut calls = 0;
        let r = minimize_from_bracket(
            |x| {
                calls += 1;
                skewed(x)
            },
            (mid, skewed(mid)),
            [(lo, skewed(lo)), (hi, skewed(hi))],
            tol,
            100,
            |_, _| {},
        );
        assert!(r.converged);
        assert_eq!(r.evaluations, calls);
        let x_star = skewed_minimum();
        // The stopping test leaves the minimiser within 2 tol of the bracket's final midpoint,
        // which contains x*: |x − x*| ≤ 4 tol (+ the rounding of the flat minimum).
        let bound = 4.0 * (tol.0 * x_star.abs() + tol.1);
        assert!((r.best.0 - x_star).abs() <= bound, "{:?}", r.best);
        // argmin's Brent on the same bracket, counted the same way.
        let res = Executor::new(Skewed, BrentOpt::new(lo, hi).set_tolerance(tol.0, tol.1))
            .configure(|s| s.max_iters(100))
            .run()
            .unwrap();
        let argmin_evals = res.state.iter + 1;
        let argmin_x = res.state.best_param.unwrap();
        assert!((argmin_x - x_star).abs() <= bound);
        assert!(
            r.evaluations < argmin_evals,
            "{} vs {argmin_evals}",
            r.evaluations
        );
    }

    struct Quadratic;
    impl CostFunction for Quadratic {
        type Param = f64;
        type Output = f64;
        fn cost(&self, x: &f64) -> Result<f64, Error> {
            Ok(3.0 * (x - 0.37).powi(2) + 1.0)
        }
    }

    #[test]
    fn a_quadratic_starts_with_its_minimum() {
        // The parabola through the bracket is the function: the first step lands on the
        // minimum; the rest only closes the bracket to the stopping test.
        let f = |x: f64| Quadratic.cost(&x).unwrap();
        let tol = (f64::EPSILON.sqrt(), 1e-8, 0.0);
        let mut first = None;
        let mut calls = 0;
        let r = minimize_from_bracket(
            |x| {
                calls += 1;
                first.get_or_insert(x);
                f(x)
            },
            (0.3, f(0.3)),
            [(0.1, f(0.1)), (0.9, f(0.9))],
            tol,
            100,
            |_, _| {},
        );
        assert!(r.converged);
        assert!((first.unwrap() - 0.37).abs() < 1e-12, "{first:?}");
        assert!(
            (r.best.0 - 0.37).abs() <= 4.0 * (tol.0 * 0.37 + tol.1),
            "{:?}",
            r.best
        );
        let res = Executor::new(
            Quadratic,
            BrentOpt::new(0.1, 0.9).set_tolerance(tol.0, tol.1),
        )
        .configure(|s| s.max_iters(100))
        .run()
        .unwrap();
        assert!(
            calls < res.state.iter + 1,
            "{calls} vs {}",
            res.state.iter + 1
        );
    }

    #[test]
    fn infinite_values_fall_back_to_golden_section_steps() {
        // Invalid trial points (infinite cost) beyond 1: the parabola is unusable until the
        // infinite end has left the three points.
        let f = |x: f64| {
            if x > 1.0 {
                f64::INFINITY
            } else {
                (x - 0.8).powi(2)
            }
        };
        let r = minimize_from_bracket(
            f,
            (0.5, f(0.5)),
            [(0.0, f(0.0)), (1.5, f64::INFINITY)],
            (f64::EPSILON.sqrt(), 1e-10, 0.0),
            100,
            |_, _| {},
        );
        assert!(r.converged);
        assert!((r.best.0 - 0.8).abs() < 1e-7, "{:?}", r.best);
    }

    #[test]
    fn stops_at_the_iteration_limit_without_converging() {
        let f = |x: f64| (x - 0.8).powi(2);
        let mut reports = 0;
        let r = minimize_from_bracket(
            f,
            (0.5, f(0.5)),
            [(0.0, f(0.0)), (1.5, f(1.5))],
            (f64::EPSILON.sqrt(), 1e-12, 0.0),
            2,
            |_, _| reports += 1,
        );
        assert!(!r.converged);
        assert_eq!((r.evaluations, reports), (2, 2));
        assert!(r.best.1 <= f(0.5));
    }

    #[test]
    fn the_parabola_predicts_a_quadratic_exactly_and_only_inside_the_bracket() {
        let f = |x: f64| 3.0 * (x - 0.37).powi(2) + 1.0;
        let pt = |x: f64| (x, f(x));
        let d = parabola_decrease(pt(0.5), pt(0.2), pt(0.9), (0.0, 1.0)).unwrap();
        assert!((d - (f(0.5) - 1.0)).abs() <= 1e-14, "{d}");
        // The vertex 0.37 outside [0.4, 1]: no prediction.
        assert_eq!(
            parabola_decrease(pt(0.5), pt(0.45), pt(0.9), (0.4, 1.0)),
            None
        );
        // Concave, repeated or infinite points: none.
        let g = |x: f64| -f(x);
        assert_eq!(
            parabola_decrease((0.5, g(0.5)), (0.2, g(0.2)), (0.9, g(0.9)), (0.0, 1.0)),
            None
        );
        assert_eq!(
            parabola_decrease(pt(0.5), pt(0.5), pt(0.9), (0.0, 1.0)),
            None
        );
        assert_eq!(
            parabola_decrease(pt(0.5), (0.2, f64::INFINITY), pt(0.9), (0.0, 1.0)),
            None
        );
    }

    #[test]
    fn a_cost_tolerance_stops_earlier_with_the_value_within_it() {
        // The skewed function from a wide bracket: with a cost tolerance the search stops when
        // the parabola through its three best points predicts at most that decrease, which,
        // this close to the minimum, bounds the true remaining decrease within a factor 2.
        let (lo, mid, hi) = (-10.0, -8.0, 10.0);
        let x_star = skewed_minimum();
        let f_star = skewed(x_star);
        let run = |cost_tol: f64| {
            minimize_from_bracket(
                skewed,
                (mid, skewed(mid)),
                [(lo, skewed(lo)), (hi, skewed(hi))],
                (f64::EPSILON.sqrt(), 1e-8, cost_tol),
                100,
                |_, _| {},
            )
        };
        let full = run(0.0);
        for cost_tol in [1e-2, 1e-3, 1e-4] {
            let loose = run(cost_tol);
            assert!(loose.converged);
            assert!(
                loose.evaluations < full.evaluations,
                "{cost_tol}: {} vs {}",
                loose.evaluations,
                full.evaluations
            );
            let gap = loose.best.1 - f_star;
            assert!((0.0..=2.0 * cost_tol).contains(&gap), "{cost_tol}: {gap}");
        }
    }
}
