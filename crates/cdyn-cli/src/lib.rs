//! The commands of `cdyn` as a library, shared by the `cdyn` binary and the
//! Python package (crates/cdyn-py), so both read scenarios, run cases and
//! word errors the same way.
//!
//! | folder | what lives there |
//! |---|---|
//! | [`io`] | files written whole, the terminal, progress, Ctrl-C |
//! | [`case`] | the scenario file, the case it builds, running a case |
//! | [`study`] | what the commands compute from many runs: paper, compare, suite, sweep, bench |
//! | [`render`] | what they write for people to look at: summaries, plots, heat maps, GIFs, viewers |
//! | [`export`] | a scenario packed for other tools: its variables, the FMI 2.0 FMU |
//!
//! The commands themselves (argument parsing, which of these to call) are
//! the binary's, in `src/commands/`.

#![deny(missing_docs)]

pub mod case;
pub mod export;
pub mod io;
pub mod render;
pub mod study;
