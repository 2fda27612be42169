//! Helpers shared by the CLI tests that run the binary on scenario files
//! written on the fly.
#![allow(dead_code)] // each test file uses some of the helpers

pub mod rod;

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

/// A CSV's header and rows.
pub type Table = (Vec<String>, Vec<Vec<f64>>);

/// The header and rows of the CSV at `path`.
pub fn table(path: &Path) -> Table {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    (header, rows)
}

/// The first case of the `summary.json` a run wrote into `out`.
pub fn summary_case(out: &Path) -> serde_json::Value {
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    summary["cases"][0].clone()
}
