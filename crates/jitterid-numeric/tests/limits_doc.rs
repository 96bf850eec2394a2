//! The limits table of `docs/experiments.md` states the limits the library checks: every
//! limit has its row, with its bound.

use jitterid_numeric::limits::Limit;

/// The bound a row of the table states: digits with thin spaces, or `1 GiB`.
fn stated(cell: &str) -> Option<u64> {
    let cell = cell.trim();
    if cell == "1 GiB" {
        return Some(1 << 30);
    }
    cell.replace(' ', "").parse().ok()
}

#[test]
fn the_documented_limits_are_the_checked_ones() {
    let doc = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/experiments.md"
    ))
    .unwrap();
    for limit in Limit::ALL {
        let row = doc
            .lines()
            .filter_map(|l| {
                let cells: Vec<&str> = l.split('|').map(str::trim).collect();
                (cells.len() >= 4
                    && cells[1] == limit.unit()
                    && cells[3].starts_with(limit.of_what()))
                .then(|| cells[2].to_string())
            })
            .next()
            .unwrap_or_else(|| panic!("docs/experiments.md has no row for {limit:?}"));
        assert_eq!(
            stated(&row),
            Some(limit.max()),
            "{limit:?}: the table says {row}"
        );
    }
}
