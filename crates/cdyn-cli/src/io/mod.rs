//! What a command needs of the outside world: files written whole or not
//! at all ([`output`]), the terminal ([`terminal`]), progress bars
//! ([`progress`]), Ctrl-C ([`interrupt`]) and the allocation counter the
//! benchmarks read ([`alloc_count`]).
//!
//! May import: nothing of the crate.

pub mod alloc_count;
pub mod interrupt;
pub mod output;
pub mod progress;
pub mod terminal;
