//! One run: the scenario file and its typed keys ([`scenario`]), its inputs
//! and outputs ([`inputs`]), the case
//! it builds, a case stepped from outside ([`live`]) and how a case is run, to files or in memory ([`runner`]),
//! and the positions kept for the viewer's animation ([`frames`]).
//!
//! May import: `io`.

mod build;
pub mod frames;
pub mod inputs;
pub mod live;
pub mod runner;
pub mod scenario;
mod wording;
