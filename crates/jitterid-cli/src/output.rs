//! Output files appear whole and together, or not at all.
//!
//! A command collects everything it writes (a data file and its side file; a JSON file and its
//! figures) in one [`OutputSet`] and commits it once its results are computed. The commit first
//! checks every destination, then writes each file as a temporary in its target's directory,
//! then renames them all into place; if any step fails, the temporaries are removed and the files
//! already renamed are restored to what they were, so previous outputs are left untouched.
//!
//! What a destination may be:
//! - absent, or a regular file: replaced atomically (keeping the old file's permissions);
//! - a symbolic link: followed; the file it points to is treated by these rules and the link
//!   itself stays;
//! - a character device or a FIFO (`/dev/null`, a named pipe): written through, never replaced
//!   (these cannot be rolled back, so they are written after every rename has succeeded);
//! - anything else (a directory, a block device, a socket, a link to nothing): refused.

use jitterid_study::error::StudyResult;
use jitterid_study::study_err;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use tempfile::{NamedTempFile, TempPath};

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

/// A file renamed into place, with what was there before (to restore on failure).
struct Placed {
    target: PathBuf,
    previous: Option<TempPath>,
}

/// The files (and figure directories) one command writes, committed together.
#[derive(Debug, Default)]
pub struct OutputSet {
    files: Vec<(PathBuf, Vec<u8>)>,
    dirs: Vec<PathBuf>,
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
    pub fn figures(&mut self, dir: &Path, figures: Vec<(String, String)>) {
        self.dir(dir);
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
        let result = write_all(&self.files, &targets);
        if result.is_err() {
            for d in created.iter().rev() {
                let _ = std::fs::remove_dir(d);
            }
        }
        result
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

fn write_all(files: &[(PathBuf, Vec<u8>)], targets: &[Target]) -> StudyResult<()> {
    let mut staged: Vec<(NamedTempFile, &Path, &Path)> = Vec::new();
    for ((path, contents), target) in files.iter().zip(targets) {
        if let Target::Replace(p) = target {
            staged.push((stage(p, contents, path)?, p, path));
        }
    }
    let mut placed: Vec<Placed> = Vec::new();
    for (tmp, target, path) in staged {
        match place(tmp, target) {
            Ok(p) => placed.push(p),
            Err(e) => {
                roll_back(placed);
                return Err(study_err!("{}: cannot write: {e}", path.display()));
            }
        }
    }
    for ((path, contents), target) in files.iter().zip(targets) {
        if let Target::Stream(p) = target {
            if let Err(e) = stream(p, contents) {
                roll_back(placed);
                return Err(study_err!("{}: cannot write: {e}", path.display()));
            }
        }
    }
    Ok(())
}

/// Writes `contents` to a temporary beside `target`.
fn stage(target: &Path, contents: &[u8], path: &Path) -> StudyResult<NamedTempFile> {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let result = (|| -> std::io::Result<NamedTempFile> {
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // A new file gets the permissions `File::create` would give (0666 less the umask), a
        // replaced one keeps its own.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let mut tmp = builder.tempfile_in(dir_of(target))?;
        if let Ok(m) = std::fs::metadata(target) {
            tmp.as_file().set_permissions(m.permissions())?;
        }
        tmp.write_all(contents)?;
        tmp.as_file().sync_all()?;
        Ok(tmp)
    })();
    result.map_err(|e| study_err!("{}: cannot write: {e}", path.display()))
}

/// Renames the temporary over `target`, keeping what was there as a backup.
fn place(tmp: NamedTempFile, target: &Path) -> std::io::Result<Placed> {
    let previous = if target.is_file() {
        let backup = tempfile::Builder::new()
            .prefix(".backup.")
            .suffix(".tmp")
            .tempfile_in(dir_of(target))?
            .into_temp_path();
        std::fs::remove_file(&backup)?;
        if std::fs::hard_link(target, &backup).is_err() {
            std::fs::copy(target, &backup)?;
        }
        Some(backup)
    } else {
        None
    };
    tmp.persist(target).map_err(|e| e.error)?;
    Ok(Placed {
        target: target.to_path_buf(),
        previous,
    })
}

/// Restores what the renamed files replaced (or removes them where there was nothing).
fn roll_back(placed: Vec<Placed>) {
    for p in placed.into_iter().rev() {
        match p.previous {
            Some(backup) => {
                let _ = std::fs::rename(&backup, &p.target);
                drop(backup);
            }
            None => {
                let _ = std::fs::remove_file(&p.target);
            }
        }
    }
}

/// Writes into a device or FIFO without replacing it.
fn stream(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    let mut f: File = OpenOptions::new().write(true).open(path)?;
    f.write_all(contents)?;
    f.flush()
}

/// Whether `path` is (or links to) a character device or FIFO, which is written through rather
/// than replaced (so a file meant to sit beside it, such as `/dev/null.input.csv`, has no place).
pub fn writes_through(path: &Path) -> bool {
    matches!(target_of(path, ""), Ok(Target::Stream(_)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn devices_are_written_through_and_directories_refused() {
        // Classification only: nothing is written to the device.
        assert_eq!(
            target_of(Path::new("/dev/null"), "null").unwrap(),
            Target::Stream(PathBuf::from("/dev/null"))
        );
        assert!(writes_through(Path::new("/dev/null")));
        let e = target_of(Path::new("/"), "/").unwrap_err();
        assert!(e.message().contains("is a directory"), "{e}");
        let missing = Path::new("/no/such/file.csv");
        assert_eq!(
            target_of(missing, "x").unwrap(),
            Target::Replace(missing.to_path_buf())
        );
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// A failure after the checks (a destination changed meanwhile) rolls back the renames.
    #[test]
    fn a_late_failure_restores_the_files_already_renamed() {
        let dir = tempfile::tempdir().unwrap();
        let (old, new, blocked) = (
            dir.path().join("old.csv"),
            dir.path().join("new.csv"),
            dir.path().join("blocked"),
        );
        std::fs::write(&old, "previous").unwrap();
        // A non-empty directory cannot be renamed over; it stands for a target that became
        // one after the checks.
        std::fs::create_dir(&blocked).unwrap();
        std::fs::write(blocked.join("inside"), "x").unwrap();
        let files = vec![
            (old.clone(), b"replaced".to_vec()),
            (new.clone(), b"created".to_vec()),
            (blocked.clone(), b"never".to_vec()),
        ];
        let targets: Vec<Target> = files
            .iter()
            .map(|(p, _)| Target::Replace(p.clone()))
            .collect();
        let e = write_all(&files, &targets).unwrap_err();
        assert!(e.message().contains("blocked"), "{e}");
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "previous");
        assert_eq!(names(dir.path()), ["blocked", "old.csv"]);
        // A stream that cannot be opened rolls back the renamed files too.
        let files = vec![
            (old.clone(), b"replaced".to_vec()),
            (dir.path().join("pipe"), b"never".to_vec()),
        ];
        let targets = vec![
            Target::Replace(old.clone()),
            Target::Stream(dir.path().join("no/such/pipe")),
        ];
        assert!(write_all(&files, &targets).is_err());
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "previous");
        assert_eq!(names(dir.path()), ["blocked", "old.csv"]);
        // And when nothing fails, every file is there.
        let files = vec![
            (old.clone(), b"replaced".to_vec()),
            (new.clone(), b"created".to_vec()),
        ];
        let targets: Vec<Target> = files
            .iter()
            .map(|(p, _)| Target::Replace(p.clone()))
            .collect();
        write_all(&files, &targets).unwrap();
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "replaced");
        assert_eq!(std::fs::read_to_string(&new).unwrap(), "created");
        assert_eq!(names(dir.path()), ["blocked", "new.csv", "old.csv"]);
    }

    #[test]
    fn a_file_written_twice_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let mut set = OutputSet::new();
        set.file(&dir.path().join("a.svg"), "one");
        set.file(&dir.path().join("./a.svg"), "two");
        let e = set.commit().unwrap_err();
        assert!(e.message().contains("twice"), "{e}");
        assert!(names(dir.path()).is_empty());
    }

    #[test]
    fn a_figure_directory_is_removed_again_when_the_set_fails() {
        let dir = tempfile::tempdir().unwrap();
        let figs = dir.path().join("figs/deeper");
        let mut set = OutputSet::new();
        set.dir(&figs);
        set.file(&figs.join("a.svg"), "<svg/>");
        set.file(&dir.path().join("nodir/r.json"), "{}");
        let e = set.commit().unwrap_err();
        assert!(e.message().contains("does not exist"), "{e}");
        assert!(names(dir.path()).is_empty(), "{:?}", names(dir.path()));
    }
}
