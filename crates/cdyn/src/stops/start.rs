//! Whether a state is past a stop: the check of a run's start (a joint
//! must start within its range) and of a state set between steps.

use super::unilateral::Unilateral;
use crate::error::{Part, Problem, Result};

/// How far past a stop a joint is still at it, not past it: where a run may
/// start (a pose placed at a bound, a robot's zero pose at a limit of 0,
/// lands there only to round-off: 2.8e-17 seen) and where a step's end
/// is not a hit. A joint resting at a stop that no row holds (Panda's
/// second finger, a `<mimic>` of the first, held) wanders across it by
/// round-off, ±1e-16: seen as hits, each took a rebuild of the model —
/// 3 900 in Panda's first second. It is 1e-12, how far past a bound a
/// multi-turn joint's angle is read at it too.
pub const START_SLACK: f64 = crate::limit::AT_BOUND;

/// Refuses `(q0, v0)` as a start of `system` if it is past a stop (by more
/// than [`START_SLACK`]): [`Problem::StartsPastLimit`], naming the first
/// such stop's joint, side and bound and how far past it the state is.
/// [`StopSimulation::new`](super::StopSimulation::new) refuses such a start; this tells it beforehand.
pub fn check_start<U: Unilateral + ?Sized>(system: &U, q0: &[f64], v0: &[f64]) -> Result<()> {
    let mut gaps = vec![[0.0; 2]; system.stops()];
    system.gaps(q0, v0, &mut gaps)?;
    refuse_passed(system, &gaps)
}

/// [`check_start`] of the stops' `gaps` at the start.
pub(super) fn refuse_passed<U: Unilateral + ?Sized>(system: &U, gaps: &[[f64; 2]]) -> Result<()> {
    let Some((stop, g)) = passed(gaps, |_| false) else { return Ok(()) };
    let (upper, bound) = system.side(stop);
    let joint = system.joint(stop);
    Err(Problem::StartsPastLimit { stop, joint, upper, bound, by: -g }.at(Part::InitialState))
}

/// The first stop passed (`g < −START_SLACK`) among those `gaps` that
/// `held` does not exempt, and its gap.
pub(super) fn passed(gaps: &[[f64; 2]], held: impl Fn(usize) -> bool) -> Option<(usize, f64)> {
    gaps.iter().enumerate().map(|(k, [g, _])| (k, *g)).find(|&(k, g)| g < -START_SLACK && !held(k))
}
