//! Files named inside an experiment file: where they may be.
//!
//! The rule: a path written in an experiment file (`[input] path`) is resolved against the
//! experiment file's directory and must stay inside it. An absolute path, a path with a `..`
//! component, or a path that resolves through a symbolic link to a file outside that directory
//! (both sides canonicalized, then compared component by component) is refused before the file
//! is opened, with one line naming the experiment file, the line and the key
//! ([`StudyErrorKind::PathOutside`]). A caller that means it allows such paths explicitly with
//! [`Paths::Anywhere`] (the command line's `--allow-paths-outside`, Python's
//! `allow_paths_outside=True`). An experiment parsed from text without a file takes the
//! directory it is given (Python: the current directory unless `dir` is given) and the same rule
//! applies to it.
//!
//! An experiment file can be someone else's (downloaded, shipped to a worker): without the rule
//! it could make a front end read any file the user can read and echo part of it in an error.

use super::diagnostics::Source;
use crate::error::{StudyErrorKind, StudyResult};
use std::path::{Component, Path, PathBuf};
use toml::Spanned;

/// Where the files an experiment file names may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Paths {
    /// Inside the experiment file's directory (the default).
    #[default]
    Inside,
    /// Anywhere the user can read (absolute paths, `..`, links leading out): the user allowed
    /// it explicitly.
    Anywhere,
}

/// A file named by the experiment file: the path to open and the name to give it in messages.
pub(super) struct NamedFile {
    /// The path to open (canonical when the rule was checked and the file exists).
    pub(super) open: PathBuf,
    /// The path as resolved against the experiment's directory, for messages.
    pub(super) name: String,
}

/// The file that `[section] key = value` names, resolved against the experiment's directory
/// and checked against the rule in force.
///
/// # Errors
///
/// A [`StudyErrorKind::PathOutside`] error at the key when the path leads outside the
/// directory and the rule is [`Paths::Inside`].
pub(super) fn resolve(
    cx: &Source,
    section: &str,
    key: &str,
    value: &Spanned<String>,
) -> StudyResult<NamedFile> {
    let written = Path::new(value.get_ref());
    let joined = cx.dir.join(written);
    let name = joined.display().to_string();
    if cx.paths == Paths::Anywhere {
        return Ok(NamedFile { open: joined, name });
    }
    let refuse = |why: &str| {
        cx.err(
            section,
            key,
            &value.span(),
            format!(
                "{why}; files named by an experiment file must be inside its directory {} (allow it explicitly with --allow-paths-outside, or allow_paths_outside=True in Python)",
                shown_dir(&cx.dir)
            ),
        )
        .with_kind(StudyErrorKind::PathOutside)
    };
    if written.has_root()
        || written
            .components()
            .any(|c| matches!(c, Component::Prefix(_) | Component::RootDir))
    {
        return Err(refuse("an absolute path"));
    }
    if written.components().any(|c| c == Component::ParentDir) {
        return Err(refuse("a path with a `..` component"));
    }
    // A link inside the directory may still lead out: compare where both really are. A file
    // that does not exist (or cannot be reached) is left to the reader, which says so and reads
    // nothing.
    let (Ok(file), Ok(dir)) = (joined.canonicalize(), canonical_dir(&cx.dir)) else {
        return Ok(NamedFile { open: joined, name });
    };
    if !file.starts_with(&dir) {
        return Err(refuse(
            "the path leads through a symbolic link to a file outside the experiment's directory",
        ));
    }
    Ok(NamedFile { open: file, name })
}

/// The directory, canonical (the empty path is the current directory).
fn canonical_dir(dir: &Path) -> std::io::Result<PathBuf> {
    if dir.as_os_str().is_empty() {
        Path::new(".").canonicalize()
    } else {
        dir.canonicalize()
    }
}

fn shown_dir(dir: &Path) -> String {
    if dir.as_os_str().is_empty() {
        "`.`".to_string()
    } else {
        format!("`{}`", dir.display())
    }
}
