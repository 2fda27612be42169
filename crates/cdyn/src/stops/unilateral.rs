//! What a system with stops is ([`Unilateral`]) and what its run reports
//! ([`Report`]: the stops hit and released, the velocity bounds exceeded).

use crate::error::Result;
use crate::model::Model;

/// A system with stops, for [`run_with_stops`](super::run_with_stops).
///
/// [`gaps`](Self::gaps) and [`overspeed`](Self::overspeed) are read after
/// every step, so they write into the caller's buffers: an implementation
/// that allocates nothing there keeps an ordinary step allocation-free.
pub trait Unilateral {
    /// How many stops it has.
    fn stops(&self) -> usize;
    /// Its model with the stops `held` (indices, in this order) as its last
    /// rows, each `g = 0`.
    fn model_holding(&self, held: &[usize]) -> Result<Model>;
    /// Each stop's gap `g` (`≥ 0` allowed) and its rate `ġ` at `(q, v)`,
    /// into `gaps` (one entry per stop).
    fn gaps(&self, q: &[f64], v: &[f64], gaps: &mut [[f64; 2]]) -> Result<()>;
    /// The period of a stop's gap, if it has one: a joint whose angle is
    /// read from the state only up to whole turns (a revolute joint's
    /// range of a turn or more) has gaps a turn apart for the same state.
    /// A run takes each new reading of such a gap as the one nearest the
    /// last, so that it follows the joint's turns.
    fn period(&self, _stop: usize) -> Option<f64> {
        None
    }
    /// Newton's coefficient of restitution of a stop.
    fn restitution(&self, stop: usize) -> f64;
    /// How messages name a stop's joint (`"joint 2"`).
    fn joint(&self, stop: usize) -> String;
    /// Which side of its joint's limit a stop is (`true`: the upper) and its bound.
    fn side(&self, stop: usize) -> (bool, f64);
    /// How messages name a stop (`"joint 2's upper limit"`).
    fn name(&self, stop: usize) -> String {
        format!("{}'s {} limit", self.joint(stop), if self.side(stop).0 { "upper" } else { "lower" })
    }
    /// How many coordinates have a velocity bound: the most entries
    /// [`Report::overspeed`] can hold.
    fn speed_bounds(&self) -> usize {
        0
    }
    /// Calls `exceeded(index, |rate| / bound)` for each coordinate moving
    /// faster than its velocity bound at `(q, v)` (the ratio above 1).
    /// Reported, not enforced.
    fn overspeed(&self, _q: &[f64], _v: &[f64], _exceeded: &mut dyn FnMut(usize, f64)) -> Result<()> {
        Ok(())
    }
}

/// What a run with stops did besides its states.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Report {
    /// The stops hit and released, in order.
    pub events: Vec<Event>,
    /// Each coordinate that exceeded its velocity bound at a step's end:
    /// `(index, largest |rate| / bound, first time)`, by index.
    pub overspeed: Vec<(usize, f64, f64)>,
}

/// What happened at a stop.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Change {
    /// Hit with the gap's rate `rate` (< 0); the impact took `kinetic_lost`
    /// of kinetic energy; `held` unless it rebounded (`e > 0`). A stop the
    /// joint crossed and turned back from within the step (`rate ≥ 0`, a
    /// graze) only has its position put back: not held, no energy taken.
    Impact {
        /// `ġ` just before the impact, at the stop (the positions projected
        /// onto it, the velocities onto the other rows there).
        rate: f64,
        /// `T⁻ − T⁺` across the impact, at the stop: `(1 − e²) ġ² / (2 g_q M⁻¹ g_qᵀ)`
        /// for one stop. A rebound the load would end within a step
        /// (`2 e |ġ| < |g̈| h`) is plastic: bounces end held instead of
        /// coming at every step.
        kinetic_lost: f64,
        /// Whether the stop is held now.
        held: bool,
    },
    /// Released: the row's multiplier turned to pulling.
    Release {
        /// `λ` of the row `g = 0` (> 0).
        multiplier: f64,
    },
}

/// A stop hit or released.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Event {
    /// Which stop (see [`Unilateral::stops`]).
    pub stop: usize,
    /// The step within which it happened (ending at `t = step · h`).
    pub step: u64,
    /// When: for an impact, the crossing within that step, where it is
    /// applied; for a release, the step's end.
    pub t: f64,
    /// What happened.
    pub change: Change,
}
