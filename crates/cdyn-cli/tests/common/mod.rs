//! Helpers shared by the CLI tests that run the binary on scenario files
//! written on the fly.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `cdyn` binary with `args`.
pub fn cdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cdyn")).args(args).output().unwrap()
}

/// A path as the `&str` an argument list takes.
pub fn path_str(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Writes `text` as `name` into a fresh directory; returns the directory and the file.
pub fn scenario(name: &str, text: &str) -> (PathBuf, PathBuf) {
    let dir = tempfile::tempdir().unwrap().keep();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

/// The one error line of a failed command, checked to be one line without a panic.
pub fn one_error_line(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "expected failure, got success: {stderr}");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    stderr
}
