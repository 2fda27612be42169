//! cdyn from C and inside other tools: the C API of `include/cdyn.h`
//! ([`api`]) and the FMI 2.0 co-simulation functions ([`fmi`]) that make
//! this library the binary of every FMU `cdyn fmu` writes. Both step the
//! CLI library's [`Live`](cdyn_cli::case::live::Live) case, as Python does.
//!
//! Every entry point catches panics (a panic never crosses into C), reports
//! failures as a status code with a one-line message (the C API's
//! [`cdyn_last_error`](api::cdyn_last_error), the FMU's logger), and frees
//! what it allocated when its owner asks.

#![deny(missing_docs)]

pub mod api;
pub mod fmi;
mod guard;
