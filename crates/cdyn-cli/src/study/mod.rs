//! What the commands compute from many runs, as data, shared by the `cdyn`
//! binary and the Python package: the paper's cases ([`paper`]), a model
//! under every method ([`compare`]), the method suite with its verdicts
//! ([`suite`]), work-precision diagrams ([`precision`]), grids over gains
//! and steps ([`sweep`]), and the cost of a
//! step ([`bench`](mod@bench)). Nothing here draws; the figures are in `render`.
//!
//! May import: `io`, `case`.

pub mod bench;
pub mod compare;
pub mod paper;
pub mod precision;
pub mod suite;
pub mod sweep;
