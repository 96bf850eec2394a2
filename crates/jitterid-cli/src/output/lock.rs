//! The second half of a commit's safety: the directory lock that keeps two writers of the same
//! files apart, and the removal of the temporaries a killed writer left (see the parent
//! module's steps 2 and 3).

use super::{absolute_dir, journal, parse_temp, Kind, Target, NAME_KEPT};
use jitterid_study::error::StudyResult;
use jitterid_study::study_err;
use std::collections::BTreeSet;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How long a commit waits for another writer's lock on a directory before it gives up.
pub(super) const LOCK_WAIT: Duration = Duration::from_secs(30);

/// Whether the process `pid` may still be running (`true` where this cannot be told).
pub(super) fn may_be_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc = Path::new("/proc");
    if proc.join("self").exists() {
        proc.join(pid.to_string()).exists()
    } else {
        true
    }
}

/// Removes the temporaries a killed writer left in `dir`. With the directory's lock held every
/// temporary there is stale (a writer holds the lock for as long as its temporaries exist);
/// without it, only those of a process that is no longer running.
pub(super) fn clean_stale(dir: &Path, locked: bool) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some((kind, pid, name)) = file_name.to_str().and_then(parse_temp) else {
            continue;
        };
        if !locked && may_be_alive(pid) {
            continue;
        }
        if matches!(kind, Kind::Journal | Kind::Undo) {
            // Taken by the recovery of its set, never removed on its own.
            continue;
        }
        let path = entry.path();
        match std::fs::symlink_metadata(&path) {
            Ok(m) if !m.is_dir() => {}
            _ => continue,
        }
        if kind == Kind::Moved {
            // A replaced file: put back where its file is missing; kept where its name was
            // shortened (its file cannot be told), removed where its file is there.
            if name.chars().count() >= NAME_KEPT {
                continue;
            }
            let own = dir.join(&name);
            let missing = matches!(
                std::fs::symlink_metadata(&own),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound
            );
            if missing {
                let _ = std::fs::rename(&path, &own);
                continue;
            }
        }
        let _ = std::fs::remove_file(&path);
    }
}

/// An exclusive advisory lock (`flock`) on a directory, released when dropped.
pub(super) struct DirLock {
    #[allow(dead_code)] // held for its lock
    file: File,
}

/// Locks `dir` for one writer, waiting up to `wait` for another to finish. Where a directory
/// cannot be locked (not readable, a file system without `flock`), the set is written unlocked
/// (`Ok(None)`).
pub(super) fn lock_dir(dir: &Path, wait: Duration) -> StudyResult<Option<DirLock>> {
    #[cfg(unix)]
    {
        use rustix::fs::{flock, FlockOperation};
        let Ok(file) = File::open(dir) else {
            return Ok(None);
        };
        let start = Instant::now();
        loop {
            match flock(&file, FlockOperation::NonBlockingLockExclusive) {
                Ok(()) => return Ok(Some(DirLock { file })),
                Err(e) if e == rustix::io::Errno::WOULDBLOCK => {
                    if start.elapsed() >= wait {
                        return Err(study_err!(
                            "{}: cannot write: another jitterid is writing its outputs in this directory (waited {} s); try again when it has finished",
                            dir.display(),
                            wait.as_secs()
                        ));
                    }
                    std::thread::sleep(Duration::from_millis(10));
                }
                Err(_) => return Ok(None),
            }
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (dir, wait);
        Ok(None)
    }
}

/// Locks the directories the regular files of `targets` go to (each once, in one order, so
/// that two writers never wait on each other), finishes or undoes the sets a killed writer left
/// there ([`journal`]) and cleans the stale temporaries.
pub(super) fn lock_and_clean(targets: &[Target]) -> StudyResult<Vec<DirLock>> {
    let dirs: BTreeSet<PathBuf> = targets
        .iter()
        .filter_map(|t| match t {
            Target::Replace(p) => Some(absolute_dir(p)),
            Target::Stream(_) => None,
        })
        .collect();
    let mut locks = Vec::with_capacity(dirs.len());
    let mut locked = Vec::with_capacity(dirs.len());
    for d in &dirs {
        let lock = lock_dir(d, LOCK_WAIT)?;
        locked.push(lock.is_some());
        locks.extend(lock);
    }
    // A killed writer's set may reach into directories this one does not write: the recovery
    // locks those too, and holds them with the others.
    let mut held_dirs = dirs.clone();
    for (d, &is_locked) in dirs.iter().zip(&locked) {
        journal::recover(d, is_locked, &mut locks, &mut held_dirs)?;
        clean_stale(d, is_locked);
    }
    Ok(locks)
}
