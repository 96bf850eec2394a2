//! Edits of an experiment file's TOML document before it is read: the command line's
//! `--set key=value` and the `[sampling]` keys a data file supplies.
//!
//! An edit changes the document, not the [`Experiment`](super::Experiment): the edited text is
//! then read exactly as a file would be, so an edited value meets the same validation as a
//! written one (the family's keys, the representable ranges, the method's needs). Messages
//! locate a key by its line; after an edit the lines of the edited text are mapped back to the
//! file's (an unchanged line keeps its number) or to the edit that wrote them (`exp.toml
//! (--set jitter.sigma=-1): [jitter] sigma: …`).

use crate::error::{StudyError, StudyResult};
use crate::study_err;
use std::path::Path;
use toml_edit::{DocumentMut, Item, Table, Value};

/// Keys of one section that exclude each other, `(section, key, other)`: an edit of `key`
/// removes `other` (a `[design]` budget is a duration or a number of samples).
const EXCLUSIVE: [(&str, &str, &str); 2] = [
    ("design", "duration", "samples"),
    ("design", "samples", "duration"),
];

/// One `key=value` edit: a dotted path into the document (`jitter.sigma`,
/// `jitter.terms.1.d` for the second `[[jitter.terms]]` table) and a TOML value.
#[derive(Debug, Clone)]
pub struct Override {
    path: Vec<String>,
    value: Value,
    /// Where the edit came from, as messages name it (`--set jitter.sigma=0.1`).
    origin: String,
}

impl Override {
    /// The edit of a `--set` argument `key=value`: `key` a dotted path, `value` a TOML value
    /// (`0.1`, `true`, `"gaussian"`, `[1, 2, 5]`), or a bare word taken as a string
    /// (`gaussian`), so that a shell's quoting is not needed for names.
    ///
    /// # Errors
    ///
    /// One line naming the argument: no `=`, an empty key or key segment, or a value that
    /// starts like a TOML string, array or table and is not one.
    pub fn parse(arg: &str) -> StudyResult<Self> {
        let origin = format!("--set {arg}");
        let (key, text) = arg.split_once('=').ok_or_else(|| {
            study_err!("{origin}: expected key=value (for example jitter.sigma=0.1)")
        })?;
        let path: Vec<String> = key.split('.').map(|s| s.trim().to_string()).collect();
        if let Some(i) = path.iter().position(String::is_empty) {
            return Err(study_err!(
                "{origin}: key `{}`: part {} is empty; expected a dotted path such as jitter.sigma",
                key.trim(),
                i + 1
            ));
        }
        let text = text.trim();
        let value = match text.parse::<Value>() {
            Ok(v) => v,
            // A bare word is a name (`jitter.family=gaussian`); anything that starts like a
            // quoted string, an array or an inline table and does not parse is a typing error.
            Err(_) if !text.is_empty() && !text.starts_with(['"', '\'', '[', '{']) => {
                Value::from(text)
            }
            Err(e) => {
                let why = e.to_string();
                let why = why.lines().last().unwrap_or("").trim();
                return Err(study_err!(
                    "{origin}: key `{}`: the value `{text}` is not a TOML value ({why})",
                    key.trim()
                ));
            }
        };
        Ok(Self {
            path,
            value,
            origin,
        })
    }

    /// An edit from a source other than the command line: `origin` names it in messages.
    pub(crate) fn from_source(path: &[&str], value: Value, origin: String) -> Self {
        Self {
            path: path.iter().map(|s| (*s).to_string()).collect(),
            value,
            origin,
        }
    }

    /// The dotted key, as given.
    pub fn key(&self) -> String {
        self.path.join(".")
    }

    /// Where the edit came from, as messages name it.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// Writes the value into `doc`, creating the tables on its path that are missing. A new
    /// value of a choice ([`CHOICES`]) removes the keys of the old choice that no edit in
    /// `all` sets, so that `--set jitter.family=gaussian --set jitter.sigma=0.1` replaces a
    /// uniform sum's `n` and `a`.
    fn apply(&self, doc: &mut DocumentMut, all: &[Override]) -> StudyResult<()> {
        let key = self.key();
        let mut table: &mut dyn toml_edit::TableLike = doc.as_table_mut();
        let (last, parents) = self
            .path
            .split_last()
            .ok_or_else(|| study_err!("{}: empty key", self.origin))?;
        let mut walked = String::new();
        let mut parts = parents.iter();
        while let Some(part) = parts.next() {
            if !walked.is_empty() {
                walked.push('.');
            }
            walked.push_str(part);
            let item = table.entry(part).or_insert(Item::Table(Table::new()));
            table = match item {
                Item::Table(t) => t,
                Item::Value(Value::InlineTable(t)) => t,
                Item::ArrayOfTables(a) => {
                    let len = a.len();
                    let index = parts.next().ok_or_else(|| {
                        study_err!(
                            "{}: key `{key}`: `{walked}` is an array of tables; give the table's index (`{walked}.0.…`)",
                            self.origin
                        )
                    })?;
                    let i: usize = index.parse().ok().filter(|&i| i < len).ok_or_else(|| {
                        study_err!(
                            "{}: key `{key}`: `{walked}` has {len} tables; expected an index in 0..{len}, found `{index}`",
                            self.origin
                        )
                    })?;
                    walked.push('.');
                    walked.push_str(index);
                    a.get_mut(i).ok_or_else(|| {
                        study_err!("{}: key `{key}`: no table {walked}", self.origin)
                    })?
                }
                _ => {
                    return Err(study_err!(
                        "{}: key `{key}`: `{walked}` is a value, not a table",
                        self.origin
                    ))
                }
            };
        }
        let mut value = self.value.clone();
        if let Some((_, _, shared)) = CHOICES
            .iter()
            .find(|(section, key, _)| self.path == [*section, *key])
        {
            let old = table.get(last).and_then(Item::as_str);
            if old.is_some() && old != value.as_str() {
                let section = &self.path[0];
                let owned: Vec<String> = table
                    .iter()
                    .map(|(k, _)| k.to_string())
                    .filter(|k| !shared.contains(&k.as_str()))
                    .filter(|k| !all.iter().any(|e| e.path == [section.as_str(), k.as_str()]))
                    .collect();
                for k in owned {
                    table.remove(&k);
                }
            }
        }
        // Keys that exclude each other: setting one replaces the other unless an edit sets it
        // too (then the reader refuses both, naming them).
        if let Some((section, _, other)) = EXCLUSIVE
            .iter()
            .find(|(section, key, _)| self.path == [*section, *key])
        {
            if !all.iter().any(|e| e.path == [*section, *other]) {
                table.remove(other);
            }
        }
        match table.get_mut(last) {
            Some(Item::Value(old)) => {
                // Keep the written spacing (and a trailing comment) around the new value.
                *value.decor_mut() = old.decor().clone();
                *old = value;
            }
            Some(Item::Table(_) | Item::ArrayOfTables(_)) => {
                return Err(study_err!(
                    "{}: key `{key}` is a table; set one of its keys (`{key}.…=…`)",
                    self.origin
                ))
            }
            _ => {
                table.insert(last, Item::Value(value));
            }
        }
        Ok(())
    }
}

/// The sections whose keys depend on a choice: the section, the key that chooses, and the keys
/// every choice shares (kept when the choice changes; the others belong to the old choice).
const CHOICES: &[(&str, &str, &[&str])] = &[
    (
        "jitter",
        "family",
        &["family", "offset", "estimate", "fit_family"],
    ),
    (
        "system",
        "kind",
        &[
            "kind",
            "estimate",
            "initial",
            "delay",
            "unstable",
            "integrators",
        ],
    ),
    ("input", "kind", &["kind"]),
];

/// Where a line of the edited text came from.
#[derive(Debug, Clone, PartialEq, Eq)]
enum LineOrigin {
    /// The file's line of this number.
    File(usize),
    /// Written by an edit (its origin, as messages name it).
    Edit(String),
}

/// An experiment's text after its edits, with the origin of every line.
#[derive(Debug, Clone)]
pub(super) struct Edited {
    /// The edited document.
    pub(super) text: String,
    lines: Vec<LineOrigin>,
}

/// `text` (of `file`) with `edits` applied in order, then, for a record in `data`, the
/// `[sampling]` keys the document still lacks taken from the record ([`super::sampling`]).
/// `None` when `text` is not a TOML document: reading it unedited reports why, as for any file.
///
/// # Errors
///
/// An edit's path leads through a value or names a table (one line naming the edit), or the
/// data file cannot give the missing `[sampling]` keys.
pub(super) fn apply(
    text: &str,
    edits: &[Override],
    data: Option<&Path>,
) -> StudyResult<Option<Edited>> {
    let Ok(mut doc) = text.parse::<DocumentMut>() else {
        return Ok(None);
    };
    for e in edits {
        e.apply(&mut doc, edits)?;
    }
    let mut all = edits.to_vec();
    if let Some(data) = data {
        let missing = missing_sampling(&doc);
        // `start` alone has a default (0): a data file that cannot give it leaves the
        // default, and reading the record later reports what is wrong with it, after the
        // experiment's own errors, as for a file that gives every key.
        let required = missing.iter().any(|k| *k != "start");
        if !missing.is_empty() {
            match super::sampling::from_data(data, &missing) {
                Ok(from_data) => {
                    for e in &from_data {
                        e.apply(&mut doc, &from_data)?;
                    }
                    all.extend(from_data);
                }
                Err(e) if required => return Err(e),
                Err(_) => {}
            }
        }
    }
    let edited = doc.to_string();
    let lines = align(text, &edited, &all);
    Ok(Some(Edited {
        text: edited,
        lines,
    }))
}

/// The `[sampling]` keys `doc` does not give (all of them without the section; none when
/// `sampling` is not a table, which reading the document reports).
fn missing_sampling(doc: &DocumentMut) -> Vec<&'static str> {
    const KEYS: [&str; 3] = ["samples", "start", "interval"];
    match doc.get("sampling") {
        None => KEYS.to_vec(),
        Some(item) => item.as_table_like().map_or_else(Vec::new, |t| {
            KEYS.into_iter().filter(|k| !t.contains_key(k)).collect()
        }),
    }
}

impl Edited {
    /// `e` (a message about the edited text of `file`) located in the file as written: a line
    /// the file has keeps its number, a line an edit wrote is named by the edit.
    pub(super) fn relocate(&self, file: &str, e: StudyError) -> StudyError {
        let kind = e.kind();
        let msg = e.message();
        let Some(rest) = msg.strip_prefix(file).and_then(|r| r.strip_prefix(':')) else {
            return e;
        };
        let digits = rest.chars().take_while(char::is_ascii_digit).count();
        let Ok(line) = rest[..digits].parse::<usize>() else {
            return e;
        };
        let tail = &rest[digits..];
        let located = match line.checked_sub(1).and_then(|i| self.lines.get(i)) {
            Some(LineOrigin::File(n)) => format!("{file}:{n}{tail}"),
            Some(LineOrigin::Edit(origin)) => format!("{file} ({origin}){tail}"),
            None => return e,
        };
        StudyError::new(located).with_kind(kind)
    }
}

/// How far ahead the alignment looks for the file's lines again after an edited stretch.
const LOOKAHEAD: usize = 64;

/// The origin of every line of `edited`: a line equal to the file's next unmatched line is
/// that line; otherwise the shortest edit (lines written, lines of the file dropped) after
/// which the two agree again is taken, and the lines it wrote are named by the edit whose key
/// they hold. Edits change a few lines in place or add a few, so the alignment is local.
fn align(original: &str, edited: &str, edits: &[Override]) -> Vec<LineOrigin> {
    let o: Vec<&str> = original.lines().collect();
    let e: Vec<&str> = edited.lines().collect();
    let mut out = Vec::with_capacity(e.len());
    let (mut i, mut j) = (0, 0);
    while i < e.len() {
        if j < o.len() && e[i] == o[j] {
            out.push(LineOrigin::File(j + 1));
            i += 1;
            j += 1;
            continue;
        }
        // The closest resynchronisation (a lines written, b lines of the file dropped).
        let mut best: Option<(usize, usize)> = None;
        'search: for sum in 1..2 * LOOKAHEAD {
            for a in 0..=sum.min(LOOKAHEAD) {
                let b = sum - a;
                if b > LOOKAHEAD {
                    continue;
                }
                let resync = match (e.get(i + a), o.get(j + b)) {
                    (Some(x), Some(y)) => x == y,
                    // Both ends reached together: the edit ran to the end.
                    (None, None) => true,
                    _ => false,
                };
                if resync {
                    best = Some((a, b));
                    break 'search;
                }
            }
        }
        let (a, b) = best.unwrap_or((e.len() - i, o.len().saturating_sub(j)));
        // At least the current line is written by an edit, since it matched nothing.
        for line in &e[i..i + a.max(1)] {
            out.push(LineOrigin::Edit(origin_of(line, edits)));
        }
        i += a.max(1);
        j += b;
    }
    out
}

/// The edit that wrote `line`: the one whose last key part the line defines, or whose first
/// part the line's table header names; all of them when none does.
fn origin_of(line: &str, edits: &[Override]) -> String {
    let defined = line.split_once('=').map(|(k, _)| k.trim());
    let header = line
        .trim()
        .strip_prefix('[')
        .and_then(|r| r.split(']').next())
        .map(str::trim);
    edits
        .iter()
        .find(|x| defined.is_some_and(|k| x.path.last().is_some_and(|l| l == k)))
        .or_else(|| {
            edits
                .iter()
                .find(|x| header.is_some_and(|h| x.key().starts_with(h)))
        })
        .map(|x| x.origin.clone())
        .unwrap_or_else(|| {
            edits
                .iter()
                .map(|x| x.origin.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "[sampling]\ninterval = 1.0\nsamples = 10\n\n[jitter]\nfamily = \"uniform-sum\"\na = 0.2\n\n[noise]\nstd = 0.01\n";

    fn edit(args: &[&str]) -> Edited {
        let edits: Vec<Override> = args.iter().map(|a| Override::parse(a).unwrap()).collect();
        apply(FILE, &edits, None).unwrap().unwrap()
    }

    #[test]
    fn a_replaced_value_keeps_every_line_number() {
        let e = edit(&["noise.std=0.5"]);
        assert!(e.text.contains("std = 0.5\n"), "{}", e.text);
        assert_eq!(e.text.lines().count(), FILE.lines().count());
        let err = e.relocate("e.toml", study_err!("e.toml:6: [jitter] family: x"));
        assert_eq!(err.message(), "e.toml:6: [jitter] family: x");
        let err = e.relocate("e.toml", study_err!("e.toml:10: [noise] std: bad"));
        assert_eq!(
            err.message(),
            "e.toml (--set noise.std=0.5): [noise] std: bad"
        );
    }

    #[test]
    fn an_added_key_is_named_by_its_edit_and_later_lines_keep_theirs() {
        let e = edit(&["jitter.estimate=true"]);
        let lines: Vec<&str> = e.text.lines().collect();
        let added = lines
            .iter()
            .position(|l| l.starts_with("estimate"))
            .unwrap()
            + 1;
        let err = e.relocate(
            "e.toml",
            study_err!("e.toml:{added}: [jitter] estimate: bad"),
        );
        assert_eq!(
            err.message(),
            "e.toml (--set jitter.estimate=true): [jitter] estimate: bad"
        );
        let std = lines.iter().position(|l| l.starts_with("std")).unwrap() + 1;
        assert_eq!(std, 11, "{}", e.text);
        let err = e.relocate("e.toml", study_err!("e.toml:{std}: [noise] std: bad"));
        assert_eq!(err.message(), "e.toml:10: [noise] std: bad");
        // A family replaced with its keys: the new key is named by its edit.
        let e = edit(&["jitter.family=gaussian", "jitter.sigma=0.1"]);
        let lines: Vec<&str> = e.text.lines().collect();
        let sigma = lines.iter().position(|l| l.starts_with("sigma")).unwrap() + 1;
        let err = e.relocate("e.toml", study_err!("e.toml:{sigma}: [jitter] sigma: bad"));
        assert_eq!(
            err.message(),
            "e.toml (--set jitter.sigma=0.1): [jitter] sigma: bad"
        );
    }

    #[test]
    fn a_new_family_drops_the_old_familys_keys_but_not_the_shared_ones() {
        let text = "[jitter]\nfamily = \"uniform-sum\"\nn = 2\na = 0.2\nestimate = true\nn_range = [0, 3]\n";
        let edits: Vec<Override> = ["jitter.sigma=0.1", "jitter.family=gaussian"]
            .iter()
            .map(|a| Override::parse(a).unwrap())
            .collect();
        let e = apply(text, &edits, None).unwrap().unwrap();
        let t: toml::Table = e.text.parse().unwrap();
        let j = t["jitter"].as_table().unwrap();
        let mut keys: Vec<&str> = j.keys().map(String::as_str).collect();
        keys.sort_unstable();
        assert_eq!(keys, ["estimate", "family", "sigma"], "{}", e.text);
        // The same family again keeps every key.
        let same = Override::parse("jitter.family=uniform-sum").unwrap();
        let e = apply(text, &[same], None).unwrap().unwrap();
        assert!(
            e.text.contains("n = 2") && e.text.contains("a = 0.2"),
            "{}",
            e.text
        );
    }

    #[test]
    fn arrays_bare_words_and_new_sections() {
        let e = edit(&["system.den=[1,2,5]", "jitter.family=gaussian"]);
        assert!(e.text.contains("den = [1,2,5]"), "{}", e.text);
        assert!(e.text.contains("family = \"gaussian\""), "{}", e.text);
        assert!(e.text.contains("[system]"), "{}", e.text);
    }

    #[test]
    fn bad_arguments_name_the_key() {
        for (arg, want) in [
            ("jitter.sigma", "expected key=value"),
            ("jitter..sigma=1", "part 2 is empty"),
            (
                "system.den=[1,2",
                "`system.den`: the value `[1,2` is not a TOML value",
            ),
        ] {
            let m = Override::parse(arg).unwrap_err().to_string();
            assert!(m.starts_with(&format!("--set {arg}: ")), "{m}");
            assert!(m.contains(want), "{m}");
        }
        let doc = |arg: &str| {
            let x = Override::parse(arg).unwrap();
            apply(FILE, &[x], None).unwrap_err().to_string()
        };
        assert!(doc("jitter=3").contains("key `jitter` is a table"));
        assert!(doc("noise.std.x=3").contains("`noise.std` is a value, not a table"));
    }

    #[test]
    fn array_of_tables_by_index() {
        let text = "[jitter]\nfamily = \"sum\"\n[[jitter.terms]]\nfamily = \"gaussian\"\nsigma = 0.1\n[[jitter.terms]]\nfamily = \"two-point\"\nd = 0.3\n";
        let x = Override::parse("jitter.terms.1.d=0.05").unwrap();
        let e = apply(text, &[x], None).unwrap().unwrap();
        assert!(e.text.contains("d = 0.05"), "{}", e.text);
        assert!(e.text.contains("sigma = 0.1"), "{}", e.text);
        let x = Override::parse("jitter.terms.2.d=0.05").unwrap();
        let m = apply(text, &[x], None).unwrap_err().to_string();
        assert!(
            m.contains("has 2 tables; expected an index in 0..2, found `2`"),
            "{m}"
        );
    }
}
