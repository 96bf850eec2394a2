//! The docs' tables of each trait's required and provided methods agree with the trait's
//! definition in source.
//!
//! For every trait listed in [`TRAITS`], the test reads the `pub trait` block of its source
//! file and sorts its methods into required (the signature ends in `;`) and provided (it has a
//! body), then compares them with
//!
//! * its row of the "Traits" table of `docs/architecture.md` (`| `Trait` | crate | required |
//!   provided |`, or `` `Trait<P>` `` for a generic trait): every backticked snake-case name in
//!   a cell is a method (a call such as `weight(k, n)` counts as `weight`; a capitalised name
//!   such as `LeastSquares` is a type), and the word "parameters" stands for `param_names`,
//!   `params` and `with_params`;
//! * the tables of the other pages marked by a comment `<!-- trait-table: Trait required -->`
//!   or `<!-- trait-table: Trait provided -->` on the line before them, whose first column
//!   lists the methods the same way.
//!
//! To cover another trait, add it to [`TRAITS`].

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Traits checked: name and source file, relative to the repository root.
const TRAITS: &[(&str, &str)] = &[
    ("JitterModel", "crates/jitterid-jitter/src/model.rs"),
    ("Signal", "crates/jitterid-signal/src/signal.rs"),
    ("Window", "crates/jitterid-window/src/window.rs"),
    ("Criterion", "crates/jitterid-estimate/src/criterion.rs"),
    ("Solver", "crates/jitterid-optim/src/lib.rs"),
    ("Objective", "crates/jitterid-optim/src/objective.rs"),
    ("LeastSquares", "crates/jitterid-optim/src/problem.rs"),
];

/// The pages whose marked tables are checked, besides `docs/architecture.md`'s row.
const PAGES: &[&str] = &["docs/extending.md", "docs/architecture.md"];

const PARAMETERS: [&str; 3] = ["param_names", "params", "with_params"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the tests package lives in the repository root")
        .to_path_buf()
}

fn read(relative: &str) -> String {
    std::fs::read_to_string(root().join(relative))
        .unwrap_or_else(|e| panic!("cannot read {relative}: {e}"))
}

/// Required and provided methods of `pub trait name` in `source`.
fn trait_methods(source: &str, name: &str) -> (BTreeSet<String>, BTreeSet<String>) {
    // Comments out (they may hold braces such as `e^{zτ}`), string and char literals blanked.
    let mut code = String::new();
    for line in source.lines() {
        let mut out = String::new();
        let mut chars = line.chars().peekable();
        let mut in_str = false;
        while let Some(c) = chars.next() {
            if in_str {
                if c == '\\' {
                    chars.next();
                } else if c == '"' {
                    in_str = false;
                    out.push('"');
                }
                continue;
            }
            if c == '/' && chars.peek() == Some(&'/') {
                break;
            }
            if c == '"' {
                in_str = true;
            }
            if c == '\'' {
                // A char literal such as '{' (a lifetime has no closing quote two chars on).
                let rest: String = chars.clone().take(2).collect();
                if rest.chars().nth(1) == Some('\'') {
                    chars.next();
                    chars.next();
                    out.push_str("' '");
                    continue;
                }
            }
            out.push(c);
        }
        code.push_str(&out);
        code.push('\n');
    }
    // `pub trait Name` followed by its generics, bounds or body (not `pub trait NameMore`).
    let head = format!("pub trait {name}");
    let start = code
        .match_indices(&head)
        .map(|(i, _)| i)
        .find(|&i| {
            code[i + head.len()..]
                .chars()
                .next()
                .is_some_and(|c| !(c.is_alphanumeric() || c == '_'))
        })
        .unwrap_or_else(|| panic!("no `pub trait {name}` in its source"));
    let body = start + code[start..].find('{').expect("a trait body");
    let bytes: Vec<char> = code[body..].chars().collect();
    let (mut required, mut provided) = (BTreeSet::new(), BTreeSet::new());
    let mut depth = 0usize;
    let mut pending: Option<String> = None;
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        match c {
            '{' => {
                if depth == 1 {
                    if let Some(m) = pending.take() {
                        provided.insert(m);
                    }
                }
                depth += 1;
            }
            '}' => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            ';' if depth == 1 => {
                if let Some(m) = pending.take() {
                    required.insert(m);
                }
            }
            'f' if depth == 1
                && pending.is_none()
                && bytes.get(i + 1) == Some(&'n')
                && bytes.get(i + 2).is_some_and(|c| c.is_whitespace())
                && (i == 0 || !(bytes[i - 1].is_alphanumeric() || bytes[i - 1] == '_')) =>
            {
                let ident: String = bytes[i + 2..]
                    .iter()
                    .skip_while(|c| c.is_whitespace())
                    .take_while(|c| c.is_alphanumeric() || **c == '_')
                    .collect();
                pending = Some(ident);
            }
            _ => {}
        }
        i += 1;
    }
    (required, provided)
}

/// Method names in a table cell: every backticked name (up to a `(`) in snake case (a name
/// with a capital, such as `P` or `LeastSquares`, is a type), and "parameters".
fn cell_methods(cell: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for (k, span) in cell.split('`').enumerate() {
        if k % 2 == 1 {
            let ident: String = span
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !ident.is_empty() && !ident.chars().any(|c| c.is_uppercase()) {
                names.insert(ident);
            }
        } else if span.contains("parameters") {
            names.extend(PARAMETERS.iter().map(|s| s.to_string()));
        }
    }
    names
}

fn cells(line: &str) -> Vec<&str> {
    let t = line.trim();
    t.trim_start_matches('|')
        .trim_end_matches('|')
        .split('|')
        .map(str::trim)
        .collect()
}

/// The architecture page's row for `name` (its first cell `` `Name` `` or, for a generic
/// trait, `` `Name<P>` ``): (required, provided).
fn architecture_row(page: &str, name: &str) -> (BTreeSet<String>, BTreeSet<String>) {
    let key = format!("`{name}`");
    let generic = format!("`{name}<");
    let row = page
        .lines()
        .find(|l| {
            l.trim_start().starts_with('|')
                && cells(l)
                    .first()
                    .is_some_and(|c| *c == key || (c.starts_with(&generic) && c.ends_with('`')))
        })
        .unwrap_or_else(|| panic!("docs/architecture.md has no Traits row for {name}"));
    let c = cells(row);
    assert!(c.len() >= 4, "the row of {name} has {} cells", c.len());
    (cell_methods(c[2]), cell_methods(c[3]))
}

/// The union of the first cells of the body rows of every table marked
/// `<!-- trait-table: name kind -->` in `page`, or `None` if none is marked.
fn marked_tables(page: &str, name: &str, kind: &str) -> Option<BTreeSet<String>> {
    let marker = format!("<!-- trait-table: {name} {kind} -->");
    let lines: Vec<&str> = page.lines().collect();
    let mut found = None;
    for (i, l) in lines.iter().enumerate() {
        if l.trim() != marker {
            continue;
        }
        let set = found.get_or_insert_with(BTreeSet::new);
        // Header, separator, then body rows until the table ends.
        for row in lines[i + 1..]
            .iter()
            .take_while(|l| l.trim_start().starts_with('|'))
            .skip(2)
        {
            set.extend(cell_methods(cells(row)[0]));
        }
    }
    found
}

fn compare(what: &str, doc: &BTreeSet<String>, source: &BTreeSet<String>, fails: &mut Vec<String>) {
    if doc != source {
        let missing: Vec<_> = source.difference(doc).collect();
        let extra: Vec<_> = doc.difference(source).collect();
        fails.push(format!(
            "{what}: the docs lack {missing:?} and list {extra:?} that the source does not"
        ));
    }
}

#[test]
fn trait_tables_match_the_trait_definitions() {
    let architecture = read("docs/architecture.md");
    let mut fails = Vec::new();
    for &(name, file) in TRAITS {
        let (required, provided) = trait_methods(&read(file), name);
        assert!(!required.is_empty(), "{name}: no required method parsed");
        let (r, p) = architecture_row(&architecture, name);
        compare(
            &format!("{name}, architecture.md, required"),
            &r,
            &required,
            &mut fails,
        );
        compare(
            &format!("{name}, architecture.md, provided"),
            &p,
            &provided,
            &mut fails,
        );
        for page in PAGES {
            let text = read(page);
            for (kind, source) in [("required", &required), ("provided", &provided)] {
                if let Some(doc) = marked_tables(&text, name, kind) {
                    compare(
                        &format!("{name}, {page}, {kind} table"),
                        &doc,
                        source,
                        &mut fails,
                    );
                }
            }
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

#[test]
fn the_parser_sorts_required_from_provided() {
    let source = r#"
        pub trait DemoMore { fn six(&self); }
        /// A doc comment with braces e^{zτ} and a fn word.
        pub trait Demo: Send {
            /// `γ(f)`
            fn one(&self) -> f64;
            fn two(&self, x: &[f64]) -> Result<Self, E>
            where
                Self: Sized;
            fn three(&self) -> String {
                format!("{}", '{')
            }
            fn four(&self) {}
        }
        pub trait Other { fn five(&self); }
        pub trait Generic<P: ?Sized> { fn seven(&self, p: &P); }
    "#;
    let (r, p) = trait_methods(source, "Demo");
    assert_eq!(r, ["one", "two"].map(String::from).into());
    assert_eq!(p, ["four", "three"].map(String::from).into());
    let (r, p) = trait_methods(source, "Generic");
    assert_eq!(r, ["seven"].map(String::from).into());
    assert!(p.is_empty());
    assert_eq!(
        cell_methods("— ; each implementation states what it needs of `P`; every `LeastSquares`"),
        BTreeSet::new()
    );
    let row = "| `Generic<P>` | crate | `seven(&P, start)` | — |";
    assert_eq!(
        architecture_row(row, "Generic"),
        (["seven"].map(String::from).into(), BTreeSet::new())
    );
    assert_eq!(
        cell_methods("`name`, `weight(k, n)`, parameters"),
        ["name", "param_names", "params", "with_params", "weight"]
            .map(String::from)
            .into()
    );
}
