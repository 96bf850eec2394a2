//! Output files are written whole or not at all: to a temporary file in the target's directory,
//! then renamed over the target.

use crate::error::{CliError, CliResult};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The temporary sibling of `path` (same directory, so the rename is atomic).
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let tmp = format!(".{name}.tmp-{}", std::process::id());
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

/// Writes `contents` to `path` atomically: nothing is left at `path` (nor a temporary file) if
/// anything fails.
pub fn write_atomic(path: &Path, contents: &[u8]) -> CliResult<()> {
    let tmp = temp_path(path);
    let result = (|| -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(contents)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        CliError::new(format!("{}: cannot write: {e}", path.display()))
    })
}

/// A set of files written together: all are staged as temporaries and renamed only when every
/// one has been written, so a failure leaves none of them.
#[derive(Debug, Default)]
pub struct Staged {
    files: Vec<(PathBuf, PathBuf)>,
}

impl Staged {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Stages one file.
    pub fn add(&mut self, path: &Path, contents: &[u8]) -> CliResult<()> {
        let tmp = temp_path(path);
        let result = (|| -> std::io::Result<()> {
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(contents)?;
            f.sync_all()
        })();
        match result {
            Ok(()) => {
                self.files.push((tmp, path.to_path_buf()));
                Ok(())
            }
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                Err(CliError::new(format!(
                    "{}: cannot write: {e}",
                    path.display()
                )))
            }
        }
    }

    /// Renames every staged file into place.
    pub fn commit(mut self) -> CliResult<()> {
        let files = std::mem::take(&mut self.files);
        for (i, (tmp, path)) in files.iter().enumerate() {
            if let Err(e) = std::fs::rename(tmp, path) {
                for (t, _) in &files[i..] {
                    let _ = std::fs::remove_file(t);
                }
                return Err(CliError::new(format!(
                    "{}: cannot write: {e}",
                    path.display()
                )));
            }
        }
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (tmp, _) in &self.files {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Creates the directory `dir` (and its parents) for plots.
pub fn ensure_dir(dir: &Path) -> CliResult<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::new(format!("{}: cannot create directory: {e}", dir.display())))
}
