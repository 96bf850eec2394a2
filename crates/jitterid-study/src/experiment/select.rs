//! `[select]`: the grid of model orders and jitter families that `jitterid select` fits.

use super::diagnostics::Source;
use super::raw::RawSelect;
use crate::error::StudyResult;
use jitterid::estimate::selection::{SelectionError, SelectionGrid};
use toml::Spanned;

const S: &str = "select";

fn range(cx: &Source, key: &str, v: &Spanned<Vec<i64>>) -> StudyResult<(usize, usize)> {
    match v.get_ref().as_slice() {
        &[lo, hi] if lo >= 0 && hi >= 0 => Ok((lo as usize, hi as usize)),
        other => Err(cx.err(
            S,
            key,
            &v.span(),
            format!("expected [min, max] of two integers >= 0, found {other:?}"),
        )),
    }
}

/// The selection grid of `[select]` (defaults: 1–2 poles, 0–1 zeros, families `none` and
/// `gaussian`), checked against the registry and the record length `len`.
pub(super) fn parse_select(cx: &Source, r: &RawSelect, len: usize) -> StudyResult<SelectionGrid> {
    let poles = match &r.poles {
        Some(v) => range(cx, "poles", v)?,
        None => (1, 2),
    };
    let zeros = match &r.zeros {
        Some(v) => range(cx, "zeros", v)?,
        None => (0, 1),
    };
    let families = match &r.families {
        Some(v) => v.get_ref().clone(),
        None => vec!["none".into(), "gaussian".into()],
    };
    let grid = SelectionGrid {
        poles,
        zeros,
        families,
    };
    match grid.candidates(&cx.registries.jitter, len) {
        Ok(_) => Ok(grid),
        Err(SelectionError::InvalidKey { key, message }) => {
            let span = match key {
                "poles" => r.poles.as_ref().map(Spanned::span),
                "zeros" => r.zeros.as_ref().map(Spanned::span),
                _ => r.families.as_ref().map(Spanned::span),
            };
            Err(match span {
                Some(s) => cx.err(S, key, &s, message),
                None => cx.err_section(S, key, message),
            })
        }
        Err(e) => Err(crate::study_err!("{}: [select] {e}", cx.file)),
    }
}
