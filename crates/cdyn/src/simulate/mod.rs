//! Running a model: the controlled state equation `ẋ = f(x, t) + U(x, t)`
//! ([`system`]), the schemes that step a model itself — RATTLE
//! ([`rattle`]) and generalized-α ([`generalized_alpha`]) — and the loop
//! that steps it from a consistent initial state with observers every `k`
//! steps ([`Simulation`], [`Settings`]).
//!
//! May import: `error`, `ad`, `linalg`, `model`, `dynamics`, `integrate`,
//! `control`.

pub mod generalized_alpha;
mod inputs;
pub mod rattle;
mod settings;
mod simulation;
mod snapshot;
mod stepper;
pub mod system;

pub use settings::*;
pub use simulation::*;
pub use snapshot::Snapshot;
pub use stepper::*;
