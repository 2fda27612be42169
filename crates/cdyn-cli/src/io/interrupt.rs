//! SIGINT and SIGTERM stop a run at the next step instead of killing the
//! process, so that the CSV keeps only complete rows and summary.json and
//! the figures are still written (marked interrupted). A second signal
//! while the first is being handled ends the process at once, so a user is
//! never stuck waiting on a slow figure.

use signal_hook::consts::{SIGINT, SIGTERM};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The signal that asked the run to stop; 0 while none has.
static SIGNAL: AtomicUsize = AtomicUsize::new(0);
/// Set by the first signal: arms the immediate exit on the second.
static ARMED: AtomicBool = AtomicBool::new(false);

/// Installs the handlers. If they cannot be installed, the default action
/// (ending the process) stays, which is what a run did before.
pub fn install() {
    for signal in [SIGINT, SIGTERM] {
        // Order matters: the shutdown must see the flag as the previous signal left it.
        let _ = signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, &ARMED);
        let _ = signal_hook::flag::register(signal, &ARMED);
        let _ = signal_hook::flag::register_usize(signal, &SIGNAL, signal as usize);
    }
}

/// The signal received, if a stop was asked for.
pub fn requested() -> Option<i32> {
    match SIGNAL.load(Ordering::Relaxed) {
        0 => None,
        s => Some(s as i32),
    }
}

/// The conventional exit status of a process stopped by `signal` (130 for SIGINT, 143 for SIGTERM).
pub fn exit_status(signal: i32) -> u8 {
    (128 + signal).clamp(0, 255) as u8
}

/// The signal's name, for the message.
pub fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}
