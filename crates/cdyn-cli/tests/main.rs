//! The command line's integration tests, one module per file, in one test binary: one link of the
//! libraries and one copy of the generic code they instantiate, where a
//! binary per file took most of a cold CI build (a 12-minute test build,
//! 50 binaries). The allocation-counting tests, which install their own
//! global allocator, stay binaries of their own.

mod bench;
mod builtin;
mod common;
mod docs;
mod errors;
mod help;
mod limits;
mod live_limits;
mod mechanisms;
mod mutations;
mod paper;
mod precision;
mod reliable;
mod runs;
mod spatial;
mod suite;
mod sweep;
mod sweeps;
mod viewer;
