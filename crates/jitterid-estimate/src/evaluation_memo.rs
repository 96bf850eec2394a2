//! The last evaluation of a fit problem, kept so that the same point is not evaluated twice.
//!
//! Levenberg–Marquardt asks for the residuals at a trial point and, once the step is accepted,
//! for the normal equations at the same point; [`fit`](crate::fit) asks for the
//! residuals at the start (to check them) just before the solver does, and again at the
//! solution. The time-domain sensitivities `∂m_k/∂θ` come out of the same pass over the
//! jitter's expectations as `m_k` itself, so the residual evaluation keeps them for the normal
//! equations that follow. Only short records are memoised: on a long one the copies would
//! raise the peak memory by the size of the record, and the evaluation costs far more than
//! the few repeated ones saved.

use std::sync::Mutex;

/// Records of at most this many samples are memoised (a few hundred KiB of residuals and
/// sensitivities at most).
pub(crate) const MEMO_MAX_SAMPLES: usize = 1 << 13;

/// One evaluated point, with the model built there (`M`).
#[derive(Debug)]
struct Entry<M> {
    theta: Vec<f64>,
    residuals: Vec<f64>,
    sensitivities: Option<Vec<Vec<f64>>>,
    model: Option<M>,
}

/// The last evaluated point of a problem (bitwise-equal parameters hit), shared between
/// threads behind a lock.
#[derive(Debug)]
pub(crate) struct EvaluationMemo<M>(Mutex<Option<Entry<M>>>);

impl<M> Default for EvaluationMemo<M> {
    fn default() -> Self {
        EvaluationMemo(Mutex::new(None))
    }
}

/// Bitwise equality, so that a hit returns exactly what the evaluation would.
fn same_point(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

impl<M> EvaluationMemo<M> {
    fn with<T>(&self, f: impl FnOnce(&mut Option<Entry<M>>) -> T) -> T {
        let mut guard = match self.0.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        f(&mut guard)
    }

    /// Keeps the residuals (and, when computed with them, the sensitivities) at `theta`, and
    /// the model built there.
    pub(crate) fn store(
        &self,
        theta: &[f64],
        residuals: &[f64],
        sensitivities: Option<Vec<Vec<f64>>>,
        model: M,
    ) {
        self.with(|e| {
            *e = Some(Entry {
                theta: theta.to_vec(),
                residuals: residuals.to_vec(),
                sensitivities,
                model: Some(model),
            });
        });
    }

    /// The model built at `theta`, handed over (a second call gets `None`), if that was the
    /// last point evaluated.
    pub(crate) fn take_model(&self, theta: &[f64]) -> Option<M> {
        self.with(|e| {
            e.as_mut()
                .filter(|e| same_point(&e.theta, theta))
                .and_then(|e| e.model.take())
        })
    }

    /// The residuals at `theta`, if that was the last point evaluated.
    pub(crate) fn residuals(&self, theta: &[f64]) -> Option<Vec<f64>> {
        self.with(|e| {
            e.as_ref()
                .filter(|e| same_point(&e.theta, theta))
                .map(|e| e.residuals.clone())
        })
    }

    /// The sensitivities at `theta`, if they were computed with the last point's residuals.
    pub(crate) fn sensitivities(&self, theta: &[f64]) -> Option<Vec<Vec<f64>>> {
        self.with(|e| {
            e.as_ref()
                .filter(|e| same_point(&e.theta, theta))
                .and_then(|e| e.sensitivities.clone())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_only_the_same_point() {
        let memo = EvaluationMemo::default();
        assert_eq!(memo.residuals(&[1.0]), None);
        memo.store(&[1.0, 2.0], &[3.0], Some(vec![vec![4.0]]), "model");
        assert_eq!(memo.residuals(&[1.0, 2.0]), Some(vec![3.0]));
        assert_eq!(memo.sensitivities(&[1.0, 2.0]), Some(vec![vec![4.0]]));
        assert_eq!(memo.take_model(&[1.0]), None);
        assert_eq!(memo.take_model(&[1.0, 2.0]), Some("model"));
        assert_eq!(memo.take_model(&[1.0, 2.0]), None);
        assert_eq!(memo.residuals(&[1.0, 2.0 + f64::EPSILON * 2.0]), None);
        assert_eq!(memo.residuals(&[1.0]), None);
        // -0.0 and 0.0 are different points for the memo (bitwise).
        memo.store(&[0.0], &[5.0], None, "other");
        assert_eq!(memo.residuals(&[-0.0]), None);
        assert_eq!(memo.sensitivities(&[0.0]), None);
    }
}
