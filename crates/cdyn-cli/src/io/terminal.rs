//! Printing to the terminal. The output files are what a run is for, so a
//! closed standard output (`cdyn sweep … | head -1`) ends the printing, not
//! the run: a broken pipe means the reader has seen enough. (`print!` would
//! panic there and lose the run.) Standard error is the last resort for
//! messages; if it is gone, nothing is left to tell, so its errors are dropped.

use anyhow::{Context, Result};
use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once standard output turned out to be a closed pipe.
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// Prints `text` on standard output, or nothing once it has been closed;
/// another write error (a full disk behind a redirection) is returned.
pub fn print(text: &str) -> Result<()> {
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            STDOUT_CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        result => result.context("cannot write to standard output"),
    }
}

/// Prints `line` and a newline on standard error, if it is still open.
pub fn eprint_line(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
