//! Output files appear whole and together, or not at all, and cannot be turned against the user.
//!
//! A command collects everything it writes (a data file and its side file; a JSON file and its
//! figures) in one [`OutputSet`] and commits it once its results are computed:
//!
//! 1. every destination is checked (see below) and missing figure directories are created;
//! 2. the directories the files go to are locked (`flock`, exclusive, advisory; each once, in
//!    one order), waiting up to 30 s for another writer, so that two commands writing the same
//!    files never interleave (one's data file beside the other's side file);
//! 3. a set that a killed writer left half renamed there is finished or undone from its
//!    journal (step 6; `output::journal`), then stale temporaries
//!    (`.<name>.jitterid-{tmp,old,moved}-<pid>-<hex>`; with the lock held every such file is
//!    stale) are removed, and a replaced file that a kill left moved aside is put back where
//!    its file is missing;
//! 4. each file is written to a new temporary in its target's directory, created with `O_EXCL`
//!    (never through a link, never over another file) and synced;
//! 5. what each file replaces is kept under a fresh name by a second hard link (`link` fails on
//!    an existing name, another name is drawn) or, where the file system has no hard links, by
//!    renaming it there (a rename replaces a name, it never writes through it). Nothing is ever
//!    copied, so a link planted at any of these names is never followed;
//! 6. a journal naming every file of the set, its temporary and its kept predecessor is written
//!    (synced) in each directory of the set;
//! 7. the temporaries are renamed into place one by one, then devices and FIFOs are written
//!    (they cannot be rolled back);
//! 8. only then is the journal removed, then the kept predecessors, and the locks released.
//!
//! If any step fails, the temporaries are removed and the files already renamed are restored
//! from what was kept (the journal marked for undoing first), so previous outputs are left
//! untouched. A kill at any point leaves a set that the next commit to any of its directories
//! makes all old (killed before the journal was whole, or while undoing) or all new (killed
//! during the renames or after them), and whose temporaries it removes. Where a directory
//! cannot be locked (not readable, a file system without `flock`), the set is written unlocked
//! and only journals and temporaries of processes that are no longer running are taken.
//!
//! What a destination may be:
//! - absent, or a regular file: replaced atomically (keeping the old file's permissions);
//! - a symbolic link: followed; the file it points to is treated by these rules and the link
//!   itself stays;
//! - a character device or a FIFO (`/dev/null`, a named pipe): written through, never replaced,
//!   opened without waiting (`O_NONBLOCK`): a FIFO with no reader is retried for 5 s, then
//!   refused with an error instead of blocking for ever;
//! - anything else (a directory, a block device, a socket, a link to nothing): refused.

mod journal;
mod lock;

use jitterid_study::error::StudyResult;
use jitterid_study::study_err;
use lock::{clean_stale, lock_and_clean, lock_dir, may_be_alive, DirLock, LOCK_WAIT};
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How one destination is written.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Target {
    /// A regular file (or none yet) at this path, replaced by a rename.
    Replace(PathBuf),
    /// A device or FIFO at this path, opened and written in place.
    Stream(PathBuf),
}

/// What is at `path` now, and so how it is written; refuses what must not be written.
fn target_of(path: &Path, name: &str) -> StudyResult<Target> {
    let meta = match std::fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Target::Replace(path.to_path_buf()))
        }
        Err(e) => return Err(study_err!("{name}: cannot write: {e}")),
    };
    if meta.file_type().is_symlink() {
        let resolved = std::fs::canonicalize(path).map_err(|_| {
            study_err!("{name}: cannot write: a symbolic link to a file that does not exist")
        })?;
        return match target_of(&resolved, name)? {
            Target::Replace(_) => Ok(Target::Replace(resolved)),
            stream => Ok(stream),
        };
    }
    let kind = meta.file_type();
    if kind.is_file() {
        return Ok(Target::Replace(path.to_path_buf()));
    }
    if kind.is_dir() {
        return Err(study_err!(
            "{name}: cannot write: is a directory; expected a file name"
        ));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() || kind.is_fifo() {
            return Ok(Target::Stream(path.to_path_buf()));
        }
        if kind.is_block_device() {
            return Err(study_err!(
                "{name}: cannot write: is a block device; refusing to write over a disk"
            ));
        }
    }
    Err(study_err!(
        "{name}: cannot write: not a regular file, character device or FIFO"
    ))
}

/// The directory a file at `path` is renamed within.
fn dir_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The files (and figure directories) one command writes, committed together.
#[derive(Debug, Default)]
pub struct OutputSet {
    files: Vec<(PathBuf, Vec<u8>)>,
    dirs: Vec<PathBuf>,
    /// Figures of an earlier run that this set does not redraw, removed once it is written.
    stale: Vec<PathBuf>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a file to write.
    pub fn file(&mut self, path: &Path, contents: impl Into<Vec<u8>>) {
        self.files.push((path.to_path_buf(), contents.into()));
    }

    /// Adds a directory to create (with its parents) if it is not there, for the files inside it.
    pub fn dir(&mut self, dir: &Path) {
        self.dirs.push(dir.to_path_buf());
    }

    /// Adds the figures `figures` (file name, SVG) in the directory `dir`, created if needed.
    /// Of the names a command may draw (`may_draw`), those it did not draw this time are
    /// removed from `dir` once the set is written (a figure of an earlier run whose model had
    /// it, such as a Bode diagram, would otherwise stand beside this run's as if it were one).
    pub fn figures(&mut self, dir: &Path, figures: Vec<(String, String)>, may_draw: &[&str]) {
        self.dir(dir);
        for name in may_draw {
            if !figures.iter().any(|(n, _)| n == name) {
                self.stale.push(dir.join(name));
            }
        }
        for (name, svg) in figures {
            self.file(&dir.join(name), svg);
        }
    }

    /// Checks every destination, then writes every file; on failure nothing is changed (no new
    /// file, no temporary, no directory created, previous files as they were).
    pub fn commit(self) -> StudyResult<()> {
        for d in &self.dirs {
            check_dir(d)?;
        }
        let mut targets = Vec::with_capacity(self.files.len());
        for (path, _) in &self.files {
            let name = path.display().to_string();
            let target = target_of(path, &name)?;
            if let Target::Replace(p) = &target {
                let dir = dir_of(p);
                if !self.dirs.iter().any(|d| d == dir) && !dir.is_dir() {
                    return Err(study_err!(
                        "{name}: cannot write: the directory {} does not exist",
                        dir.display()
                    ));
                }
            }
            if targets.contains(&target) {
                return Err(study_err!(
                    "{name}: cannot write: the command would write this file twice (check --out against --plot)"
                ));
            }
            targets.push(target);
        }
        let created = create_dirs(&self.dirs)?;
        let result = lock_and_clean(&targets).and_then(|_locks| {
            write_all(&self.files, &targets)?;
            remove_stale(&self.stale);
            Ok(())
        });
        if result.is_err() {
            for d in created.iter().rev() {
                let _ = std::fs::remove_dir(d);
            }
        }
        result
    }
}

/// Removes the regular files among `paths` (a link or anything else there is left alone: only
/// a figure this program wrote is taken), with the set's directories still locked. Best
/// effort: the set is written whole by then, and an error here (the file removed meanwhile by
/// someone else) must not report a written set as failed.
fn remove_stale(paths: &[PathBuf]) {
    for p in paths {
        if std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_file()) {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// A directory to create must be one already, or be creatable under an existing directory.
fn check_dir(dir: &Path) -> StudyResult<()> {
    let name = dir.display();
    let mut p = dir;
    loop {
        match std::fs::metadata(p) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(_) => {
                return Err(study_err!(
                    "{name}: cannot create directory: {} is not a directory",
                    p.display()
                ))
            }
            Err(_) => match p.parent() {
                Some(up) if !up.as_os_str().is_empty() => p = up,
                _ => return Ok(()),
            },
        }
    }
}

/// Creates the missing directories; returns those created, outermost first.
fn create_dirs(dirs: &[PathBuf]) -> StudyResult<Vec<PathBuf>> {
    let mut created = Vec::new();
    for dir in dirs {
        let mut missing: Vec<&Path> = dir.ancestors().take_while(|p| !p.exists()).collect();
        missing.reverse();
        for p in missing {
            if p.as_os_str().is_empty() {
                continue;
            }
            if let Err(e) = std::fs::create_dir(p) {
                for c in created.iter().rev() {
                    let _ = std::fs::remove_dir(c);
                }
                return Err(study_err!(
                    "{}: cannot create directory: {e}",
                    dir.display()
                ));
            }
            created.push(p.to_path_buf());
        }
    }
    Ok(created)
}

/// How long a FIFO given as a destination may have no reader before the commit gives up.
const READER_WAIT: Duration = Duration::from_secs(5);

/// What every temporary of this module has in its name: `.<name>.jitterid-<kind>-<pid>-<hex>`.
const MARK: &str = ".jitterid-";

/// At most this many characters of a file's name go into its temporaries' names (which stay
/// below the usual 255-byte limit); a shorter name in a temporary is its file's whole name.
const NAME_KEPT: usize = 100;

/// The kinds of temporaries, by what a later run does with a stale one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// A new file being written (`tmp`): removed.
    New,
    /// A second link to a replaced file, kept for a roll-back (`old`): removed.
    Linked,
    /// A replaced file renamed aside where hard links are not available (`moved`): renamed back
    /// if its file is missing (a kill between the two renames), removed otherwise (kept if its
    /// name was shortened).
    Moved,
    /// A copy of a set's journal (`journal`, [`journal`]): the set is finished by the next
    /// writer.
    Journal,
    /// A copy of a set's journal marked for undoing (`undo`): the set is rolled back.
    Undo,
}

impl Kind {
    fn tag(self) -> &'static str {
        match self {
            Kind::New => "tmp",
            Kind::Linked => "old",
            Kind::Moved => "moved",
            Kind::Journal => "journal",
            Kind::Undo => "undo",
        }
    }

    fn from_tag(tag: &str) -> Option<Self> {
        [
            Kind::New,
            Kind::Linked,
            Kind::Moved,
            Kind::Journal,
            Kind::Undo,
        ]
        .into_iter()
        .find(|k| k.tag() == tag)
    }
}

/// A fresh name for a temporary of `kind` beside `target`: `.<name>.jitterid-<kind>-<pid>-<hex>`
/// with 64 random bits. The name is only a candidate: it is created with `O_EXCL` or linked
/// (which fails on an existing name), never opened if it exists.
fn fresh_name(target: &Path, kind: Kind) -> PathBuf {
    let name: String = target
        .file_name()
        .map(|n| n.to_string_lossy().chars().take(NAME_KEPT).collect())
        .unwrap_or_else(|| "output".into());
    temp_name(dir_of(target), &name, kind, &fresh_stamp())
}

/// `<pid>-<hex>`: this process and 64 random bits, drawn afresh at each call.
fn fresh_stamp() -> String {
    use std::hash::{BuildHasher, Hasher};
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(COUNTER.fetch_add(1, Ordering::Relaxed));
    if let Ok(t) = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH) {
        h.write_u128(t.as_nanos());
    }
    format!("{}-{:016x}", std::process::id(), h.finish())
}

/// `dir/.<name>.jitterid-<kind>-<stamp>`.
fn temp_name(dir: &Path, name: &str, kind: Kind, stamp: &str) -> PathBuf {
    dir.join(format!(".{name}{MARK}{}-{stamp}", kind.tag()))
}

/// A temporary's kind, writer's pid and the file it belongs to, from its name; `None` for a
/// name this module does not make.
fn parse_temp(file_name: &str) -> Option<(Kind, u32, String)> {
    let rest = file_name.strip_prefix('.')?;
    let at = rest.rfind(MARK)?;
    let (name, tail) = (&rest[..at], &rest[at + MARK.len()..]);
    let mut parts = tail.split('-');
    let kind = Kind::from_tag(parts.next()?)?;
    let pid = parts.next()?;
    let hex = parts.next()?;
    let digits = |s: &str, hexa: bool| {
        !s.is_empty()
            && s.chars().all(|c| {
                if hexa {
                    c.is_ascii_hexdigit()
                } else {
                    c.is_ascii_digit()
                }
            })
    };
    if parts.next().is_some() || name.is_empty() || !digits(pid, false) || hex.len() != 16 {
        return None;
    }
    if !digits(hex, true) {
        return None;
    }
    Some((kind, pid.parse().ok()?, name.to_string()))
}

/// The directory of `path`, absolute and with its links resolved where it exists (so that a
/// journal names files that a writer started elsewhere finds).
fn absolute_dir(path: &Path) -> PathBuf {
    let d = dir_of(path);
    std::fs::canonicalize(d).unwrap_or_else(|_| {
        std::env::current_dir()
            .map(|cwd| cwd.join(d))
            .unwrap_or_else(|_| d.to_path_buf())
    })
}

/// Where a commit can be stopped as a kill would stop it, for the tests of the recovery.
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum KillPoint {
    /// The new files staged, the old ones kept aside, no journal yet.
    BeforeJournal,
    /// After this many renames (the journal written).
    AfterRenames(usize),
    /// Every rename done, the journal removed, the old files still kept aside.
    AfterJournal,
    /// A rename failed and this many of the files renamed before it were put back.
    WhileUndoing(usize),
}

/// The error of a commit stopped at a [`KillPoint`]: everything is left as a killed process
/// would leave it.
fn killed() -> jitterid_study::error::StudyError {
    study_err!("stopped as by a kill (a test)")
}

fn write_all(files: &[(PathBuf, Vec<u8>)], targets: &[Target]) -> StudyResult<()> {
    write_all_with(files, targets, &mut fresh_name, READER_WAIT, None)
}

/// [`write_all`] with the names of temporaries drawn from `names` (a test plants files there),
/// a FIFO's reader awaited for `reader_wait`, and the commit stopped at `kill` (a test).
///
/// The regular files are staged, what they replace is kept aside, the journal is written,
/// the staged files are renamed into place, devices and FIFOs are written, and only then is
/// the journal removed and what was kept aside deleted. On an error every step is undone.
fn write_all_with(
    files: &[(PathBuf, Vec<u8>)],
    targets: &[Target],
    names: &mut dyn FnMut(&Path, Kind) -> PathBuf,
    reader_wait: Duration,
    kill: Option<KillPoint>,
) -> StudyResult<()> {
    let mut entries: Vec<journal::Entry> = Vec::new();
    // How each file's predecessor was kept, and the file's name as the user gave it.
    let mut kinds: Vec<Option<Kind>> = Vec::new();
    let mut shown: Vec<&Path> = Vec::new();
    let undo_staged = |entries: &[journal::Entry], kinds: &[Option<Kind>]| {
        for (e, k) in entries.iter().zip(kinds) {
            let _ = std::fs::remove_file(&e.new);
            match (k, &e.aside) {
                (Some(Kind::Moved), Some(a)) => {
                    let _ = std::fs::rename(a, &e.target);
                }
                (_, Some(a)) => {
                    let _ = std::fs::remove_file(a);
                }
                _ => {}
            }
        }
    };
    for ((path, contents), target) in files.iter().zip(targets) {
        let Target::Replace(p) = target else {
            continue;
        };
        // Absolute names: a later writer that finishes the set may run elsewhere.
        let dir = absolute_dir(p);
        let target = p.file_name().map_or_else(|| p.clone(), |f| dir.join(f));
        let (new, id) = match stage(&target, contents, path, names) {
            Ok(staged) => staged,
            Err(e) => {
                undo_staged(&entries, &kinds);
                return Err(e);
            }
        };
        let previous = match std::fs::symlink_metadata(&target) {
            Ok(m) if !m.is_dir() => match keep_aside(&target, names, true) {
                Ok((aside, kind)) => Some((aside, kind)),
                Err(e) => {
                    let _ = std::fs::remove_file(&new);
                    undo_staged(&entries, &kinds);
                    return Err(study_err!("{}: cannot write: {e}", path.display()));
                }
            },
            _ => None,
        };
        kinds.push(previous.as_ref().map(|(_, k)| *k));
        shown.push(path);
        entries.push(journal::Entry {
            target,
            new,
            aside: previous.map(|(a, _)| a),
            id,
        });
    }
    if kill == Some(KillPoint::BeforeJournal) {
        return Err(killed());
    }
    let journal = journal::Journal::new(entries);
    if let Err(e) = journal.write() {
        journal.remove();
        undo_staged(&journal.entries, &kinds);
        return Err(study_err!("cannot write the outputs' journal: {e}"));
    }
    // Puts back what the first `placed` renames replaced, the journal marked for undoing
    // first so that a kill meanwhile is undone by the next writer, not finished.
    let undo = |placed: usize, kill: Option<KillPoint>| -> StudyResult<()> {
        journal.mark_undo();
        for (i, e) in journal.entries[..placed].iter().enumerate().rev() {
            if kill == Some(KillPoint::WhileUndoing(placed - 1 - i)) {
                return Err(killed());
            }
            match &e.aside {
                Some(a) => {
                    let _ = std::fs::rename(a, &e.target);
                }
                None => {
                    let _ = std::fs::remove_file(&e.target);
                }
            }
        }
        undo_staged(&journal.entries[placed..], &kinds[placed..]);
        journal.remove();
        Ok(())
    };
    for (i, e) in journal.entries.iter().enumerate() {
        if kill == Some(KillPoint::AfterRenames(i)) {
            return Err(killed());
        }
        if let Err(err) = std::fs::rename(&e.new, &e.target) {
            undo(i, kill)?;
            return Err(study_err!("{}: cannot write: {err}", shown[i].display()));
        }
    }
    if kill == Some(KillPoint::AfterRenames(journal.entries.len())) {
        return Err(killed());
    }
    for ((path, contents), target) in files.iter().zip(targets) {
        if let Target::Stream(p) = target {
            if let Err(e) = stream(p, contents, reader_wait) {
                undo(journal.entries.len(), kill)?;
                return Err(study_err!("{}: cannot write: {e}", path.display()));
            }
        }
    }
    // Every file is in place: the set is new, and what it replaced goes.
    journal.remove();
    if kill == Some(KillPoint::AfterJournal) {
        return Err(killed());
    }
    for e in &journal.entries {
        if let Some(a) = &e.aside {
            let _ = std::fs::remove_file(a);
        }
    }
    Ok(())
}

/// Writes `contents` to a new temporary beside `target`, created with `O_EXCL` (so never
/// through a link or over another file) and synced; returns its name and identity.
fn stage(
    target: &Path,
    contents: &[u8],
    path: &Path,
    names: &mut dyn FnMut(&Path, Kind) -> PathBuf,
) -> StudyResult<(PathBuf, journal::FileId)> {
    let mut created: Option<PathBuf> = None;
    let result = (|| -> std::io::Result<()> {
        let mut attempt = 0;
        let mut file = loop {
            let candidate = names(target, Kind::New);
            // A new file gets the permissions `File::create` would give (0666 less the umask),
            // a replaced one keeps its own.
            match OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&candidate)
            {
                Ok(f) => {
                    created = Some(candidate);
                    break f;
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && attempt < 100 => {
                    attempt += 1
                }
                Err(e) => return Err(e),
            }
        };
        if let Ok(m) = std::fs::metadata(target) {
            file.set_permissions(m.permissions())?;
        }
        file.write_all(contents)?;
        file.sync_all()?;
        Ok(())
    })();
    match (result, created) {
        (Ok(()), Some(tmp)) => {
            let id = journal::file_id(&tmp);
            Ok((tmp, id))
        }
        (result, created) => {
            if let Some(tmp) = created {
                let _ = std::fs::remove_file(tmp);
            }
            let e = result
                .err()
                .unwrap_or_else(|| std::io::Error::other("no temporary created"));
            Err(study_err!("{}: cannot write: {e}", path.display()))
        }
    }
}

/// Keeps what is at `target` under a fresh name beside it: a second hard link (`link` never
/// follows or replaces what is at the new name: an existing name fails, and another is drawn),
/// or, where the file system has no hard links, the file itself renamed there (a rename
/// replaces a name, it never writes through one). Nothing is ever copied.
/// (`hard_links: false` goes straight to the rename, for a test.)
fn keep_aside(
    target: &Path,
    names: &mut dyn FnMut(&Path, Kind) -> PathBuf,
    hard_links: bool,
) -> std::io::Result<(PathBuf, Kind)> {
    for _ in 0..100 {
        if hard_links {
            let aside = names(target, Kind::Linked);
            match std::fs::hard_link(target, &aside) {
                Ok(()) => return Ok((aside, Kind::Linked)),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(_) => {}
            }
        }
        let aside = names(target, Kind::Moved);
        std::fs::rename(target, &aside)?;
        return Ok((aside, Kind::Moved));
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::AlreadyExists,
        "no free name for a temporary beside it",
    ))
}

/// Writes into a device or FIFO without replacing it. The open does not wait for a FIFO's
/// reader (`O_NONBLOCK`): it tries again for up to `reader_wait`, then gives up.
fn stream(path: &Path, contents: &[u8], reader_wait: Duration) -> std::io::Result<()> {
    let mut f = open_stream(path, reader_wait)?;
    f.write_all(contents)?;
    f.flush()
}

#[cfg(unix)]
fn open_stream(path: &Path, reader_wait: Duration) -> std::io::Result<File> {
    use rustix::fs::{fcntl_getfl, fcntl_setfl, open, Mode, OFlags};
    let start = Instant::now();
    let flags = OFlags::WRONLY | OFlags::NONBLOCK | OFlags::NOCTTY | OFlags::CLOEXEC;
    loop {
        match open(path, flags, Mode::empty()) {
            Ok(fd) => {
                // Written blocking from here on: a slow reader is waited for, not an error.
                fcntl_setfl(&fd, fcntl_getfl(&fd)?.difference(OFlags::NONBLOCK))?;
                return Ok(File::from(fd));
            }
            // ENXIO: a FIFO that no process has open for reading.
            Err(e) if e == rustix::io::Errno::NXIO => {
                if start.elapsed() >= reader_wait {
                    return Err(std::io::Error::other(format!(
                        "a FIFO that no process is reading (waited {:.1} s)",
                        reader_wait.as_secs_f64()
                    )));
                }
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(e) => return Err(e.into()),
        }
    }
}

#[cfg(not(unix))]
fn open_stream(path: &Path, _reader_wait: Duration) -> std::io::Result<File> {
    OpenOptions::new().write(true).open(path)
}

/// Whether `path` is (or links to) a character device or FIFO, which is written through rather
/// than replaced (so a file meant to sit beside it, such as `/dev/null.input.csv`, has no place).
pub fn writes_through(path: &Path) -> bool {
    matches!(target_of(path, ""), Ok(Target::Stream(_)))
}

#[cfg(test)]
mod tests;
