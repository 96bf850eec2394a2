//! Helpers shared by the command-line test files (each file is its own crate).
#![allow(dead_code)] // each test file uses some of them

use std::path::{Path, PathBuf};
use std::process::Command;

/// The path of an example experiment file.
pub fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/experiments")
        .join(name)
        .display()
        .to_string()
}

/// A fresh, empty directory `name` of the test group `group`.
pub fn scratch(group: &str, name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(group)
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The built `jitterid` binary.
pub fn jitterid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_jitterid"))
}

/// An example experiment file's text with its first line starting with `from` replaced.
pub fn example_with(name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(example(name)).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with(from))
        .unwrap_or_else(|| panic!("{name} has no line starting with {from:?}"));
    text.replacen(line, to, 1)
}
