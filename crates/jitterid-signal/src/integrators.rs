//! Structural integrators: poles held exactly at the origin by a parameterisation
//! ([`TransferFunction::with_integrators`](crate::TransferFunction::with_integrators),
//! [`Zpk::with_integrators`](crate::Zpk::with_integrators)).
//!
//! Why held and not estimated: a pole estimated near 0 is, on a finite record, as often just
//! right of the axis as left of it, and a search that must stay stable stalls against the axis;
//! a user who knows the plant integrates states it, and the pole is then exactly 0 in every
//! model the search visits (the realisation evaluates it without the modal form's `r/p`).

use crate::{poly, Root};
use num_complex::Complex64;

/// The roots of `den` whose last `n` coefficients are 0: those of the leading part, then `n`
/// exact zeros (a root finder would return them as a few `ε`, on either side of the axis).
pub(crate) fn roots_with_origin(den: &[f64], n: usize) -> Option<Vec<Complex64>> {
    let keep = den.len().checked_sub(n)?;
    let mut roots = poly::roots(&den[..keep])?;
    roots.extend(std::iter::repeat_n(Complex64::new(0.0, 0.0), n));
    Some(roots)
}

/// For serde's `skip_serializing_if`.
pub(crate) fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Which of `poles` are held: the first `n` real poles at exactly 0, `None` when there are
/// fewer than `n` of them.
pub(crate) fn held_poles(poles: &[Root], n: usize) -> Option<Vec<bool>> {
    let mut left = n;
    let held: Vec<bool> = poles
        .iter()
        .map(|p| {
            let hold = left > 0 && *p == Root::Real(0.0);
            left -= usize::from(hold);
            hold
        })
        .collect();
    (left == 0).then_some(held)
}

/// The number of real poles at exactly 0 in `poles`.
pub(crate) fn at_origin(poles: &[Root]) -> usize {
    poles.iter().filter(|&&p| p == Root::Real(0.0)).count()
}
