//! `[select]`: the grid of model orders and jitter families that `jitterid select` fits.

use super::diagnostics::Source;
use super::raw::RawSelect;
use crate::error::StudyResult;
use jitterid::estimate::selection::{ChannelOrders, SelectionError, SelectionGrid, MAX_CANDIDATES};
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

/// Each input's candidate orders of a multi-input grid, in input order: the input's list in
/// `orders` when it has one, else every order of the `poles` × `zeros` ranges (zeros ≤ poles).
fn channel_orders(
    cx: &Source,
    r: &RawSelect,
    names: &[&str],
    (poles, zeros): ((usize, usize), (usize, usize)),
) -> StudyResult<Vec<ChannelOrders>> {
    let given = r.orders.as_ref();
    if let Some(o) = given {
        if let Some(unknown) = o.get_ref().keys().find(|k| !names.contains(&k.as_str())) {
            return Err(cx.err(
                S,
                "orders",
                &o.span(),
                format!("`{unknown}` is not an input; the inputs are {names:?}"),
            ));
        }
    }
    let ranges: Vec<(usize, usize)> = (poles.0..=poles.1)
        .flat_map(|p| (zeros.0..=zeros.1.min(p)).map(move |z| (p, z)))
        .collect();
    names
        .iter()
        .map(|name| {
            let orders = match given.and_then(|o| o.get_ref().get(*name)) {
                None => ranges.clone(),
                Some(list) => list
                    .iter()
                    .map(|pair| match pair.as_slice() {
                        &[p, z] if p >= 0 && z >= 0 => Ok((p as usize, z as usize)),
                        other => Err(cx.err(
                            S,
                            "orders",
                            &given.map(Spanned::span).unwrap_or_default(),
                            format!(
                                "input `{name}`: expected [poles, zeros] of two integers >= 0, found {other:?}"
                            ),
                        )),
                    })
                    .collect::<StudyResult<_>>()?,
            };
            Ok(ChannelOrders {
                input: name.to_string(),
                orders,
            })
        })
        .collect()
}

/// The selection grid of `[select]` (defaults: 1–2 poles, 0–1 zeros, families `none` and
/// `gaussian`), checked against the registry and the record length `len`, and for a system
/// with several inputs (`names`, in input order; empty for one input) each input's orders:
/// its list in `orders`, or the `poles` × `zeros` ranges (none for one input).
pub(super) fn parse_select(
    cx: &Source,
    r: &RawSelect,
    len: usize,
    names: &[&str],
) -> StudyResult<(SelectionGrid, Vec<ChannelOrders>)> {
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
    let channels = match (names, &r.orders) {
        ([], Some(o)) => {
            return Err(cx.err(
                S,
                "orders",
                &o.span(),
                "lists orders per input of a system with several inputs ([[input]]); one input's orders are `poles` and `zeros`",
            ))
        }
        ([], None) => Vec::new(),
        _ => channel_orders(cx, r, names, (poles, zeros))?,
    };
    let grid = SelectionGrid {
        poles,
        zeros,
        families,
    };
    let checked = if channels.is_empty() {
        grid.candidates(&cx.registries.jitter, len).map(|_| ())
    } else {
        grid.channel_candidates(&channels, &cx.registries.jitter, len)
            .map(|_| ())
    };
    let (key, message) = match checked {
        Ok(()) => return Ok((grid, channels)),
        Err(SelectionError::InvalidKey { key, message }) => (key, message),
        Err(SelectionError::TooManyCandidates { candidates }) => (
            "orders",
            format!(
                "{candidates} candidates (the product of each input's orders and the families), at most {MAX_CANDIDATES}: list fewer orders per input"
            ),
        ),
        Err(e) => return Err(crate::study_err!("{}: [select] {e}", cx.file)),
    };
    let span = match key {
        "poles" => r.poles.as_ref().map(Spanned::span),
        "zeros" => r.zeros.as_ref().map(Spanned::span),
        "orders" => r.orders.as_ref().map(Spanned::span),
        _ => r.families.as_ref().map(Spanned::span),
    };
    Err(match span {
        Some(s) => cx.err(S, key, &s, message),
        None => cx.err_section(S, key, message),
    })
}

/// The `[[system]]` keys a multi-input candidate (one `tf` per input, estimated, from rest)
/// cannot carry, with why.
const NOT_CARRIED: [(&str, &str); 4] = [
    ("delay", "an input delay"),
    ("initial", "a free response"),
    ("integrators", "structural integrators"),
    ("unstable", "unstable poles"),
];

/// Whether `select` can rank the multi-input system of `exp`: every channel a `zpk` or `tf`
/// model, estimated, without the keys of [`NOT_CARRIED`], the channels not one shared model.
pub(crate) fn channels_selectable(exp: &super::Experiment) -> StudyResult<()> {
    let refuse = |key: &str, why: String| {
        Err(crate::study_err!(
            "{}: [[system]] {key}: select over several inputs {why}; fit the system with its orders given (jitterid fit)",
            exp.file
        ))
    };
    let spec = &exp.system.kind;
    if spec.get("shared") == Some(&true.into()) {
        return refuse(
            "kind",
            "ranks one transfer function per input, not a grey-box model with a column per input"
                .into(),
        );
    }
    let list = |key: &str| spec.get(key).and_then(|v| v.as_array()).cloned();
    let (channels, estimated) = (list("channels").unwrap_or_default(), list("estimate"));
    for (i, c) in channels.iter().enumerate() {
        let kind = c.get("kind").and_then(|k| k.as_str()).unwrap_or("");
        if !matches!(kind, "tf" | "zpk") {
            return refuse(
                "kind",
                format!(
                    "ranks transfer functions (zpk or tf), not `{kind}` (input {})",
                    i + 1
                ),
            );
        }
        if estimated.as_ref().and_then(|e| e.get(i)) != Some(&true.into()) {
            return refuse(
                "estimate",
                format!(
                    "estimates every input's transfer function; input {}'s is fixed",
                    i + 1
                ),
            );
        }
        if c.get("level").is_some() {
            return Err(crate::study_err!(
                "{}: [[input]] level: select over several inputs fits candidates without an input level (input {}); fit the system with its orders given (jitterid fit), or select on the deviation u − u₀ written as the input",
                exp.file,
                i + 1
            ));
        }
        for (key, what) in NOT_CARRIED {
            // `unstable = false` and `integrators = 0` are the defaults written out.
            let set = c
                .get(key)
                .is_some_and(|v| v.as_bool() != Some(false) && v.as_u64() != Some(0));
            if set {
                return refuse(
                    key,
                    format!("fits candidates without {what} (input {})", i + 1),
                );
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::raw::{docs_table_keys, RawSelect};

    /// The `[select]` table of `docs/experiments.md` lists exactly the keys the reader takes, in
    /// order (its first column writes each key with its form, `poles = [min, max]`).
    #[test]
    fn the_docs_select_table_lists_the_reader_s_keys() {
        let keys: Vec<String> = docs_table_keys("### `[select]`")
            .iter()
            .map(|k| k.split(" =").next().unwrap_or_default().to_string())
            .collect();
        assert_eq!(keys, RawSelect::KEYS);
    }
}
