//! Merging the smooth pieces of several laws.
//!
//! A jitter family's pieces (`JitterModel::pieces` in `jitterid-jitter`) are sorted, disjoint intervals on which
//! its density is smooth. A law built from several families (a mixture, or a sum with a
//! discrete term) has a density that is smooth between the knots of all of them, so its
//! pieces are the union of theirs cut at every knot: [`merge_pieces`].

/// The union of `lists` of intervals, cut at every interval end of every list: sorted,
/// disjoint, non-empty intervals whose ends include every input end that lies inside the
/// union. Empty or non-finite input intervals are ignored.
///
/// ```
/// use jitterid_numeric::pieces::merge_pieces;
/// let merged = merge_pieces(&[vec![(0.0, 2.0)], vec![(1.0, 3.0), (5.0, 6.0)]]);
/// assert_eq!(merged, vec![(0.0, 1.0), (1.0, 2.0), (2.0, 3.0), (5.0, 6.0)]);
/// ```
pub fn merge_pieces(lists: &[Vec<(f64, f64)>]) -> Vec<(f64, f64)> {
    let valid = |&(a, b): &(f64, f64)| a.is_finite() && b.is_finite() && a < b;
    let mut knots: Vec<f64> = lists
        .iter()
        .flatten()
        .filter(|p| valid(p))
        .flat_map(|&(a, b)| [a, b])
        .collect();
    knots.sort_by(f64::total_cmp);
    knots.dedup();
    let covered = |t: f64| {
        lists
            .iter()
            .flatten()
            .any(|p| valid(p) && p.0 <= t && t <= p.1)
    };
    knots
        .windows(2)
        .map(|w| (w[0], w[1]))
        // An elementary interval lies inside or outside each input interval as a whole; its
        // midpoint tells which.
        .filter(|&(a, b)| covered(0.5 * (a + b)))
        .collect()
}

/// Every interval of `pieces` moved by `offset`.
pub fn shift_pieces(pieces: &[(f64, f64)], offset: f64) -> Vec<(f64, f64)> {
    pieces
        .iter()
        .map(|&(a, b)| (a + offset, b + offset))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merging_keeps_every_knot_and_drops_gaps() {
        let a = vec![(-2.0, -1.0), (-1.0, 1.0), (1.0, 2.0)];
        let b = vec![(-0.5, 0.5), (4.0, 5.0)];
        let m = merge_pieces(&[a, b]);
        assert_eq!(
            m,
            vec![
                (-2.0, -1.0),
                (-1.0, -0.5),
                (-0.5, 0.5),
                (0.5, 1.0),
                (1.0, 2.0),
                (4.0, 5.0)
            ]
        );
        // Independent check: the merged total length is the measure of the union.
        let len: f64 = m.iter().map(|(a, b)| b - a).sum();
        assert_eq!(len, 5.0);
    }

    #[test]
    fn degenerate_input_is_ignored() {
        let m = merge_pieces(&[vec![(1.0, 1.0), (f64::NAN, 2.0), (3.0, 2.0)], vec![]]);
        assert!(m.is_empty());
        assert_eq!(shift_pieces(&[(0.0, 1.0)], 2.0), vec![(2.0, 3.0)]);
    }
}
