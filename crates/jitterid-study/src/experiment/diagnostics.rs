//! Where an error is in the file and what the user probably meant: every message is one line
//! `file:line: [section] key: what was expected`.

use super::paths::Paths;
use super::raw::keys_of;
use crate::error::StudyError;
use crate::study_err;
use crate::Registries;
use std::ops::Range;
use std::path::PathBuf;

/// The text being read, so that an error can be located at the key it is about.
pub(super) struct Source<'a> {
    pub(super) file: &'a str,
    pub(super) text: &'a str,
    /// The directory relative paths are resolved from.
    pub(super) dir: PathBuf,
    /// Where the files the experiment names may be.
    pub(super) paths: Paths,
    /// Line of every section header given.
    section_lines: Vec<(&'static str, usize)>,
    /// The registries every name in the file is looked up in.
    pub(super) registries: &'a Registries,
}

impl<'a> Source<'a> {
    /// The text of `file`, with its section headers located.
    pub(super) fn new(
        file: &'a str,
        text: &'a str,
        dir: PathBuf,
        paths: Paths,
        registries: &'a Registries,
    ) -> Self {
        let mut section_lines = Vec::new();
        for (i, l) in text.lines().enumerate() {
            let l = l.trim();
            if let Some(inner) = l.strip_prefix('[').and_then(|r| r.split(']').next()) {
                let inner = inner.trim();
                if let Some(s) = super::raw::SECTIONS.iter().find(|s| **s == inner) {
                    section_lines.push((*s, i + 1));
                }
            }
        }
        Self {
            file,
            text,
            dir,
            paths,
            section_lines,
            registries,
        }
    }

    /// An error about the key whose value starts at `span`.
    pub(super) fn err(
        &self,
        section: &str,
        key: &str,
        span: &Range<usize>,
        msg: impl std::fmt::Display,
    ) -> StudyError {
        study_err!(
            "{}:{}: [{section}] {key}: {msg}",
            self.file,
            line_of(self.text, span.start)
        )
    }

    /// An error about a key that is not in the file: located at its section's header.
    pub(super) fn err_section(
        &self,
        section: &str,
        key: &str,
        msg: impl std::fmt::Display,
    ) -> StudyError {
        let line = self
            .section_lines
            .iter()
            .find(|(s, _)| *s == section)
            .map(|x| x.1);
        match line {
            Some(l) => study_err!("{}:{l}: [{section}] {key}: {msg}", self.file),
            None => study_err!("{}: [{section}] {key}: {msg}", self.file),
        }
    }

    /// An error on `line`, or at the section header when the line is not known.
    pub(super) fn err_on_line(
        &self,
        section: &str,
        key: &str,
        line: Option<usize>,
        msg: impl std::fmt::Display,
    ) -> StudyError {
        match line {
            Some(l) => study_err!("{}:{l}: [{section}] {key}: {msg}", self.file),
            None => self.err_section(section, key, msg),
        }
    }

    /// The line of a byte offset range.
    pub(super) fn line_of_span(&self, span: &Range<usize>) -> usize {
        line_of(self.text, span.start)
    }

    /// The line of `key = …` in the `index`-th table `[[array]]` of the file (`array` as
    /// written in the header, for example `jitter.terms`).
    pub(super) fn array_table_key_line(
        &self,
        array: &str,
        index: usize,
        key: &str,
    ) -> Option<usize> {
        let mut seen = 0;
        let mut inside = false;
        for (i, l) in self.text.lines().enumerate() {
            let t = l.trim();
            if t.starts_with('[') {
                let name = t.trim_start_matches('[').split(']').next().map(str::trim);
                inside = t.starts_with("[[") && name == Some(array) && {
                    seen += 1;
                    seen == index + 1
                };
                continue;
            }
            if inside && key_on_line(self.text, i + 1).as_deref() == Some(key) {
                return Some(i + 1);
            }
        }
        None
    }

    /// An error about the key at `span` when the key was given, else at the section header.
    pub(super) fn err_at<T>(
        &self,
        section: &str,
        key: &str,
        value: Option<&toml::Spanned<T>>,
        msg: impl std::fmt::Display,
    ) -> StudyError {
        match value {
            Some(v) => self.err(section, key, &v.span(), msg),
            None => self.err_section(section, key, msg),
        }
    }
}

/// 1-based line of a byte offset.
pub(super) fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The section header in force at `line` (the last `[name]` at or before it).
fn section_at(text: &str, line: usize) -> Option<String> {
    text.lines()
        .take(line)
        .filter_map(|l| {
            let l = l.trim();
            let inner = l.strip_prefix('[')?.split(']').next()?.trim();
            (!inner.starts_with('[') && !inner.is_empty()).then(|| inner.to_string())
        })
        .last()
}

/// The bare key defined on `line`, if the line reads `key = …`.
fn key_on_line(text: &str, line: usize) -> Option<String> {
    let l = text.lines().nth(line.checked_sub(1)?)?;
    let (k, _) = l.split_once('=')?;
    let k = k.trim();
    (!k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.'))
    .then(|| k.to_string())
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        prev = cur;
    }
    prev[b.len()]
}

fn suggestion<'k>(unknown: &str, known: &[&'k str]) -> Option<&'k str> {
    known
        .iter()
        .map(|k| (edit_distance(unknown, k), *k))
        .filter(|(d, k)| *d <= 2 && *d < k.len())
        .min()
        .map(|x| x.1)
}

/// "unknown key `name`", with the closest of `known` as a suggestion, and the `list` expected.
pub(super) fn unknown_key(name: &str, known: &[&str], list: &str) -> String {
    match suggestion(name, known) {
        Some(s) => format!("unknown key `{name}` (did you mean `{s}`?); expected one of {list}"),
        None => format!("unknown key `{name}`; expected one of {list}"),
    }
}

/// Turns a TOML/serde error into one located line.
pub(super) fn toml_error(file: &str, text: &str, e: &toml::de::Error) -> StudyError {
    let line = e.span().map(|s| line_of(text, s.start));
    let section = line.and_then(|l| section_at(text, l));
    let mut msg = e.message().trim().to_string();
    let mut key = line.and_then(|l| key_on_line(text, l));
    if let Some(rest) = msg.strip_prefix("unknown field `") {
        let name = rest.split('`').next().unwrap_or("").to_string();
        let known = keys_of(section.as_deref().unwrap_or(""));
        let list = known
            .iter()
            .filter(|k| **k != "title" || section.is_none())
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ");
        msg = unknown_key(&name, known, &list);
        key = None;
    } else if let Some(rest) = msg.strip_prefix("missing field `") {
        let name = rest.split('`').next().unwrap_or("");
        msg = format!("missing key `{name}`");
        key = None;
    }
    msg = msg
        .replace("expected i64", "expected a whole number")
        .replace("expected f64", "expected a number")
        .replace("expected a sequence", "expected a list")
        .replace("invalid type: map", "invalid type: table")
        .replace("expected struct table ", "expected the table ")
        .replace(
            "expected struct experiment file",
            "expected a table of sections",
        );
    let section = section.map(|s| format!("[{s}] ")).unwrap_or_default();
    let key = key.map(|k| format!("{k}: ")).unwrap_or_default();
    match line {
        Some(l) => study_err!("{file}:{l}: {section}{key}{msg}"),
        None => study_err!("{file}: {section}{key}{msg}"),
    }
}

/// The line of `key = …` in the section `[section]`, if the file has one.
fn key_line(text: &str, section: &str, key: &str) -> Option<usize> {
    let mut current: Option<String> = None;
    for (i, l) in text.lines().enumerate() {
        let t = l.trim();
        if let Some(rest) = t.strip_prefix('[') {
            let name = rest.trim_start_matches('[').split(']').next();
            current = name.map(|s| s.trim().to_string());
            continue;
        }
        if current.as_deref() == Some(section) && key_on_line(text, i + 1).as_deref() == Some(key) {
            return Some(i + 1);
        }
    }
    None
}

/// The line of the header `[[section]]`.
fn array_header_line(text: &str, section: &str) -> Option<usize> {
    text.lines()
        .position(|l| {
            let t = l.trim();
            t.strip_prefix("[[")
                .and_then(|r| r.split("]]").next())
                .is_some_and(|s| s.trim() == section)
        })
        .map(|i| i + 1)
}

/// Mistakes of shape that serde would report without the key: a section written as an array
/// of tables (`[[sampling]]`), and a date where a number or a string is expected (a TOML date
/// reads as a table). `None` when the file has neither, or does not parse as TOML at all (the
/// typed parse then says why).
pub(super) fn shape_error(file: &str, text: &str) -> Option<StudyError> {
    let doc: toml::Table = text.parse().ok()?;
    let at = |line: Option<usize>, msg: String| match line {
        Some(l) => study_err!("{file}:{l}: {msg}"),
        None => study_err!("{file}: {msg}"),
    };
    // A date in a section's table, with its line.
    let dated = |t: &toml::Table, name: &str| {
        t.iter().find_map(|(key, v)| {
            let date = match v {
                toml::Value::Datetime(d) => Some(d),
                toml::Value::Array(a) => a.iter().find_map(|x| match x {
                    toml::Value::Datetime(d) => Some(d),
                    _ => None,
                }),
                _ => None,
            }?;
            Some(at(
                key_line(text, name, key),
                format!("[{name}] {key}: expected a number or a string, found the date {date}"),
            ))
        })
    };
    for &name in super::raw::SECTIONS.iter().filter(|s| **s != "title") {
        match doc.get(name) {
            Some(toml::Value::Array(a)) if MANY.contains(&name) => {
                if let Some(e) = a.iter().find_map(|t| match t {
                    toml::Value::Table(t) => dated(t, name),
                    _ => None,
                }) {
                    return Some(e);
                }
            }
            Some(toml::Value::Array(_)) => {
                return Some(at(
                    array_header_line(text, name),
                    format!("[[{name}]]: expected one table [{name}], found an array of tables"),
                ))
            }
            Some(toml::Value::Table(t)) => {
                if let Some(e) = dated(t, name) {
                    return Some(e);
                }
            }
            _ => {}
        }
    }
    None
}

/// The sections that may be written as an array of tables, one per input of a multi-input
/// system (`[[input]]`, `[[system]]`).
const MANY: &[&str] = &["input", "system"];
