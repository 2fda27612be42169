//! Systems written out by hand — closed-form derivatives, no automatic
//! differentiation, no generic code — with cdyn's equations, control and
//! scheme, so that a benchmark can measure cdyn's overhead against them
//! and a test can hold them to cdyn's trajectories.
//!
//! For benchmarks and comparisons only: public because the benches and
//! the command line's `bench` use it, and hidden from the documentation
//! because it is not a capability of the library.
//!
//! May import: `integrate`, `control`, `simulate`, `spatial`.

mod pendulum;
mod spatial_chain;

pub use pendulum::{HandWritten, State};
pub use spatial_chain::HandWrittenChain;
