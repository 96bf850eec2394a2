//! The journal of an output set's renames, which makes a commit whole after a kill at any point.
//!
//! Before the first rename, the writer records every file of the set (its target, the staged
//! new file, where the file it replaces was kept aside, and the staged file's identity) in a
//! journal, one copy in each directory the set writes to, each created new and synced. It
//! removes the copies after the last rename. A writer killed in between leaves the copies, and
//! the next writer that locks any of those directories (and, for a set spread over several,
//! the others too) finishes the set:
//!
//! - every copy there, none marked for undoing: the renames had begun and every staged file is
//!   whole, so the rest are renamed into place (**all new**);
//! - a copy marked for undoing (the writer met an error and was killed while it restored the
//!   old files): the files renamed into place are replaced by what was kept aside, or removed
//!   where there was nothing (**all old**);
//! - a copy missing from a directory: either the journal was still being written (nothing was
//!   renamed yet) or already being removed (everything was): which one is told by whether every
//!   target is the staged file itself (same device and inode), and the set is left new or
//!   restored to old accordingly.
//!
//! A copy cut short by the kill (no last line) was never followed by a rename, so it is ignored.
//! Whatever the journal names is then gone, and the usual cleaning removes the rest of the
//! temporaries.

use super::{fresh_stamp, lock_dir, temp_name, DirLock, Kind, LOCK_WAIT};
use jitterid_study::error::StudyResult;
use jitterid_study::study_err;
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A file's identity: device and inode (`None` where the platform does not give them).
pub(super) type FileId = Option<(u64, u64)>;

/// The identity of the file at `path` itself (a link is not followed).
pub(super) fn file_id(path: &Path) -> FileId {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::symlink_metadata(path)
            .ok()
            .map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// One file of a set, by absolute paths (a later writer may run elsewhere).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Entry {
    /// Where the file goes.
    pub target: PathBuf,
    /// The staged new file.
    pub new: PathBuf,
    /// Where the file it replaces was kept, if there was one.
    pub aside: Option<PathBuf>,
    /// The staged file's identity.
    pub id: FileId,
}

impl Entry {
    /// Whether the staged file is in place (the target is that very file).
    fn placed(&self) -> bool {
        match self.id {
            Some(id) => file_id(&self.target) == Some(id),
            None => !exists(&self.new) && exists(&self.target),
        }
    }
}

/// Whether anything is at `path` (a link counts, followed or not).
fn exists(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok()
}

/// The copies of one set's journal.
#[derive(Debug)]
pub(super) struct Journal {
    /// `<pid>-<hex>`: what the copies' names share.
    stamp: String,
    /// The set's files.
    pub entries: Vec<Entry>,
}

/// The first line of a journal.
const HEADER: &str = "jitterid output set journal 1";
/// The last line of a whole journal.
const END: &str = "end";
/// The name the copies' file names are made from.
const SET_NAME: &str = "output-set";

impl Journal {
    /// A journal of `entries`, with a stamp not used before.
    pub fn new(entries: Vec<Entry>) -> Self {
        Self {
            stamp: fresh_stamp(),
            entries,
        }
    }

    /// The directories of the set, each once, in order.
    pub fn dirs(&self) -> Vec<PathBuf> {
        let dirs: BTreeSet<PathBuf> = self
            .entries
            .iter()
            .map(|e| super::dir_of(&e.target).to_path_buf())
            .collect();
        dirs.into_iter().collect()
    }

    /// The copy of kind `kind` ([`Kind::Journal`] or [`Kind::Undo`]) in `dir`.
    fn copy(&self, dir: &Path, kind: Kind) -> PathBuf {
        temp_name(dir, SET_NAME, kind, &self.stamp)
    }

    fn text(&self) -> String {
        let mut out = format!("{HEADER}\n");
        for e in &self.entries {
            let aside = e.aside.as_deref().map_or("-".to_string(), hex_path);
            let id = e.id.map_or("-".to_string(), |(d, i)| format!("{d}:{i}"));
            out.push_str(&format!(
                "{} {} {aside} {id}\n",
                hex_path(&e.target),
                hex_path(&e.new)
            ));
        }
        out.push_str(END);
        out.push('\n');
        out
    }

    /// The entries of a journal's text; `None` for one cut short or not a journal.
    fn parse(text: &str) -> Option<Vec<Entry>> {
        let mut lines = text.lines();
        if lines.next()? != HEADER {
            return None;
        }
        let mut entries = Vec::new();
        for line in lines.by_ref() {
            if line == END {
                return (lines.next().is_none() && text.ends_with('\n')).then_some(entries);
            }
            let mut f = line.split(' ');
            let target = path_of_hex(f.next()?)?;
            let new = path_of_hex(f.next()?)?;
            let aside = match f.next()? {
                "-" => None,
                h => Some(path_of_hex(h)?),
            };
            let id = match f.next()? {
                "-" => None,
                s => {
                    let (d, i) = s.split_once(':')?;
                    Some((d.parse().ok()?, i.parse().ok()?))
                }
            };
            if f.next().is_some() {
                return None;
            }
            entries.push(Entry {
                target,
                new,
                aside,
                id,
            });
        }
        None
    }

    /// Writes a copy in every directory of the set, each created new (never through a link)
    /// and synced with its directory, so that no rename can be on disk before the journal.
    pub fn write(&self) -> std::io::Result<()> {
        let text = self.text();
        for dir in self.dirs() {
            let path = self.copy(&dir, Kind::Journal);
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)?;
            f.write_all(text.as_bytes())?;
            f.sync_all()?;
            sync_dir(&dir);
        }
        Ok(())
    }

    /// Marks the set for undoing: every copy renamed to its undo name (one such copy decides).
    pub fn mark_undo(&self) {
        for dir in self.dirs() {
            let _ = std::fs::rename(self.copy(&dir, Kind::Journal), self.copy(&dir, Kind::Undo));
            sync_dir(&dir);
        }
    }

    /// Removes every copy.
    pub fn remove(&self) {
        for dir in self.dirs() {
            for kind in [Kind::Journal, Kind::Undo] {
                let _ = std::fs::remove_file(self.copy(&dir, kind));
            }
        }
    }
}

/// Makes the names created and renamed in `dir` durable (best effort: not every platform or
/// file system can sync a directory).
fn sync_dir(dir: &Path) {
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
}

/// A path as hexadecimal bytes: any path, spaces and line ends included, on one line.
fn hex_path(p: &Path) -> String {
    path_bytes(p).iter().map(|b| format!("{b:02x}")).collect()
}

fn path_of_hex(h: &str) -> Option<PathBuf> {
    if h.len() % 2 != 0 || h.is_empty() {
        return None;
    }
    let bytes = (0..h.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(h.get(i..i + 2)?, 16).ok())
        .collect::<Option<Vec<u8>>>()?;
    path_from_bytes(bytes)
}

#[cfg(unix)]
fn path_bytes(p: &Path) -> Vec<u8> {
    use std::os::unix::ffi::OsStrExt;
    p.as_os_str().as_bytes().to_vec()
}

#[cfg(unix)]
fn path_from_bytes(b: Vec<u8>) -> Option<PathBuf> {
    use std::os::unix::ffi::OsStringExt;
    Some(PathBuf::from(std::ffi::OsString::from_vec(b)))
}

#[cfg(not(unix))]
fn path_bytes(p: &Path) -> Vec<u8> {
    p.to_string_lossy().into_owned().into_bytes()
}

#[cfg(not(unix))]
fn path_from_bytes(b: Vec<u8>) -> Option<PathBuf> {
    String::from_utf8(b).ok().map(PathBuf::from)
}

/// What the next writer does with a set a killed writer left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Recovery {
    /// Rename the remaining staged files into place.
    Finish,
    /// Put back what the set replaced.
    Undo,
}

/// Finishes or undoes every set whose journal is in `dir` (the caller holds its lock when
/// `locked`; otherwise only the journals of writers no longer running are taken). Other
/// directories of such a set are locked here (the locks go to `held`, with their directories
/// in `held_dirs`) and cleaned; `dir` itself is left for the caller to clean.
///
/// # Errors
///
/// When a file of the set cannot be renamed or removed, or another directory of the set is
/// locked by a running writer for longer than the wait.
pub(super) fn recover(
    dir: &Path,
    locked: bool,
    held: &mut Vec<DirLock>,
    held_dirs: &mut BTreeSet<PathBuf>,
) -> StudyResult<()> {
    let Ok(listing) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let mut stamps = BTreeSet::new();
    for entry in listing.flatten() {
        let name = entry.file_name();
        let Some((kind, pid, set)) = name.to_str().and_then(super::parse_temp) else {
            continue;
        };
        if !matches!(kind, Kind::Journal | Kind::Undo) || set != SET_NAME {
            continue;
        }
        if !locked && super::may_be_alive(pid) {
            continue;
        }
        // `.output-set.jitterid-<kind>-<pid>-<hex>`: the stamp is `<pid>-<hex>`.
        if let Some((_, stamp)) = name
            .to_str()
            .and_then(|n| n.rsplit_once(super::MARK))
            .and_then(|(_, tail)| tail.split_once('-'))
        {
            stamps.insert(stamp.to_string());
        }
    }
    for stamp in stamps {
        let probe = Journal {
            stamp,
            entries: Vec::new(),
        };
        let text = [Kind::Journal, Kind::Undo]
            .iter()
            .find_map(|&k| std::fs::read_to_string(probe.copy(dir, k)).ok());
        let Some(entries) = text.as_deref().and_then(Journal::parse) else {
            // Cut short: the writer was killed writing it, before any rename.
            for k in [Kind::Journal, Kind::Undo] {
                let _ = std::fs::remove_file(probe.copy(dir, k));
            }
            continue;
        };
        let journal = Journal { entries, ..probe };
        // The set's other directories, locked here; cleaned below as their lock allows.
        let mut others: Vec<(PathBuf, bool)> = Vec::new();
        for d in journal.dirs() {
            if held_dirs.insert(d.clone()) {
                let lock = lock_dir(&d, LOCK_WAIT)?;
                others.push((d, lock.is_some()));
                held.extend(lock);
            }
        }
        let how = decide(&journal);
        apply(&journal, how).map_err(|e| {
            study_err!(
                "{}: cannot finish the outputs a killed jitterid left there: {e}",
                dir.display()
            )
        })?;
        journal.remove();
        for (d, is_locked) in others {
            super::clean_stale(&d, is_locked);
        }
    }
    Ok(())
}

/// Whether a killed writer's set is finished or undone (see the module's documentation).
pub(super) fn decide(journal: &Journal) -> Recovery {
    let dirs = journal.dirs();
    if dirs.iter().any(|d| exists(&journal.copy(d, Kind::Undo))) {
        return Recovery::Undo;
    }
    if dirs.iter().all(|d| exists(&journal.copy(d, Kind::Journal))) {
        return Recovery::Finish;
    }
    if journal.entries.iter().all(Entry::placed) {
        Recovery::Finish
    } else {
        Recovery::Undo
    }
}

/// Finishes or undoes the set's renames; what is already done is skipped, so that a writer
/// killed while recovering is recovered from again.
pub(super) fn apply(journal: &Journal, how: Recovery) -> std::io::Result<()> {
    for e in &journal.entries {
        match how {
            Recovery::Finish => {
                if exists(&e.new) {
                    std::fs::rename(&e.new, &e.target)?;
                }
            }
            Recovery::Undo => {
                let aside = e.aside.as_deref().filter(|a| exists(a));
                if e.placed() {
                    match aside {
                        Some(a) => std::fs::rename(a, &e.target)?,
                        None => std::fs::remove_file(&e.target)?,
                    }
                } else if let Some(a) = aside.filter(|_| !exists(&e.target)) {
                    // Moved aside (no hard links) and not yet replaced: back in place.
                    std::fs::rename(a, &e.target)?;
                }
                if exists(&e.new) {
                    std::fs::remove_file(&e.new)?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_journal_reads_back_and_one_cut_short_does_not() {
        let entries = vec![
            Entry {
                target: PathBuf::from("/d/a b\n.csv"),
                new: PathBuf::from("/d/.a.jitterid-tmp-1-00"),
                aside: None,
                id: Some((3, 4)),
            },
            Entry {
                target: PathBuf::from("/e/é.json"),
                new: PathBuf::from("/e/.x"),
                aside: Some(PathBuf::from("/e/.y")),
                id: None,
            },
        ];
        let j = Journal::new(entries.clone());
        let text = j.text();
        assert_eq!(Journal::parse(&text), Some(entries));
        assert_eq!(j.dirs(), [PathBuf::from("/d"), PathBuf::from("/e")]);
        // Every prefix of the text short of its last line end is refused.
        for cut in 0..text.len() {
            assert_eq!(Journal::parse(&text[..cut]), None, "cut at {cut}");
        }
    }
}
