//! Output files written atomically: each file is written under a temporary
//! name in its own directory and renamed over its real name only when it is
//! complete, so a reader (or a killed, failed or full-disk run) never sees a
//! truncated CSV, summary.json or figure under a real name. Before a run the
//! files it will write are removed, so a directory never mixes two runs.

use anyhow::{Context, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Names of files being written start with this; a run removes leftovers of killed runs.
pub const PARTIAL_PREFIX: &str = ".cdyn-partial-";

/// The temporary name of `path` while it is written: same directory (so the
/// rename is atomic), hidden, and with the same extension (figure encoders look at it).
pub fn partial_path(path: &Path) -> PathBuf {
    let name = path.file_name().map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!("{PARTIAL_PREFIX}{}-{name}", std::process::id()))
}

/// A file being written under its temporary name. [`AtomicFile::commit`]
/// renames it to its real name; dropped without a commit, it is removed.
pub struct AtomicFile {
    path: PathBuf,
    partial: PathBuf,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `path`.
    pub fn create(path: &Path) -> Result<Self> {
        let partial = partial_path(path);
        let file = File::create(&partial).with_context(|| format!("cannot create {}", path.display()))?;
        Ok(AtomicFile { path: path.to_owned(), partial, out: Some(BufWriter::new(file)) })
    }

    /// Where to write the contents.
    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.out.as_mut().expect("an AtomicFile is written only before its commit")
    }

    /// Flushes the contents and gives the file its real name.
    pub fn commit(mut self) -> Result<()> {
        let out = self.out.take().expect("an AtomicFile is committed once");
        let done = out.into_inner().map_err(|e| e.into_error()).and_then(|f| f.sync_data().map(|()| f));
        done.and_then(|_| std::fs::rename(&self.partial, &self.path))
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.is_some() || self.partial.exists() {
            self.out = None;
            let _ = std::fs::remove_file(&self.partial);
        }
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.writer().write_all(bytes).with_context(|| format!("cannot write {}", path.display()))?;
    file.commit()
}

/// Removes the files `names` in `dir` that a previous run left, and any
/// partial file of a run that was killed, so that what this run writes is
/// never mixed with an earlier run's files.
pub fn clear(dir: &Path, names: &[String]) -> Result<()> {
    let remove = |path: &Path| match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("cannot remove the previous run's {}", path.display()))
        }
        _ => Ok(()),
    };
    for name in names {
        remove(&dir.join(name))?;
    }
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            if entry.file_name().to_string_lossy().starts_with(PARTIAL_PREFIX) {
                remove(&entry.path())?;
            }
        }
    }
    Ok(())
}
