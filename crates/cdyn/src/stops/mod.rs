//! One-sided constraints: stops that hold a coordinate on one side
//! (`g(q) ≥ 0`), joint limits being the first (of spatial and planar
//! mechanisms: [`MechanismStops`], [`PlanarStops`], each a [`Unilateral`]
//! system read at every step without allocating). A stop is a row of the
//! model only while it holds: the run steps the model of the stops held,
//! and between two steps
//!
//! - a stop whose gap closed (`g < 0`) is hit where it closed: the
//!   positions are projected onto `g = 0` and the other rows, the
//!   velocities by Newton's impact law (the plastic correction in the
//!   kinetic-energy metric, which takes exactly the kinetic energy of the
//!   velocity along the stop, scaled by `1 + e` for restitution `e`), and
//!   with `e = 0` the stop is held;
//! - a held stop whose multiplier turned to pulling (`λ > 0` for the row
//!   `g = 0`, whose force is `−g_qᵀ λ`) is released.
//!
//! Either changes the model's rows, so the run restarts its scheme from
//! the new state: a multistep scheme's history (AB-3, ABM-4) is of the
//! old right-hand side and would make the first steps after a change
//! first-order, so it starts afresh, as at `t = 0`; the energy reference
//! of `E₀ + ∫Ė` is the energy after the change (an impact's loss is not
//! a violation for energy control to undo).
//!
//! Velocity bounds are watched, not enforced: [`Report::overspeed`] lists
//! each coordinate that exceeded its bound, by how much and from when.
//!
//! A stop's gap may be periodic ([`Unilateral::period`]): a revolute
//! joint whose range is a turn or more (UR5's ±2π) has its angle, read
//! from the state, only up to whole turns. The run takes each new reading
//! of such a gap as the one nearest the stop's last (one step turns a
//! joint far less than half a turn), so that its stops follow the turns.
//!
//! A stop is found closed at the end of a step; the step is then taken
//! again in parts ([`StopSimulation`]): to the crossing, the root of the
//! cubic through `(g, ġ)` at the step's two ends, where the impact is
//! applied at the stop's own rate, and on to the step's end, so the run
//! stays on its grid `t = k h`. The parts take the run's scheme, or its
//! start-up scheme where it is a multistep one (RK-4 for AB-3 and ABM-4).
//!
//! May import: `error`, `model`, `dynamics`, `simulate`, `spatial`, `planar`, `limit`.

mod impact;
mod planar;
mod reads;
mod snapshot;
mod spatial;
mod start;
mod stepping;
mod tree;
mod turns;
mod unilateral;

pub use planar::PlanarStops;
pub use snapshot::StopSnapshot;
pub use spatial::MechanismStops;
pub use start::{START_SLACK, check_start};
pub use stepping::{StopSimulation, run_with_stops};
pub use tree::TreeStops;
pub use unilateral::{Change, Event, Report, Unilateral};
