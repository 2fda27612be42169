//! Progress bars with time estimates on a terminal, in the style of the
//! sweep's; nothing at all when standard error is not a terminal (a log
//! file, a pipe, the tests), so output stays clean there.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressFinish, ProgressStyle};
use std::io::IsTerminal;

/// A bar over `len` units named `unit` ("steps", "models"), hidden unless
/// standard error is a terminal.
pub fn bar(len: u64, unit: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let template = format!("{{bar:40}} {{human_pos}}/{{human_len}} {unit}, {{elapsed}} elapsed, about {{eta}} left");
    let style = ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar());
    // Cleared also when dropped early (an error), so the error line stands alone.
    ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr())
        .with_style(style)
        .with_finish(ProgressFinish::AndClear)
}

/// Steps between two updates of a run's bar: often enough for the eye, rare enough to cost nothing.
pub const STEPS_PER_TICK: u64 = 4096;
