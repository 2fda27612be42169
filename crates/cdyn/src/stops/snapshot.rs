//! Saving a run with stops and going back to it ([`StopSnapshot`]), and
//! putting it at a state: what a caller stepping it from outside (an FMU,
//! Python's `Simulation`) does between steps besides setting inputs.
//!
//! A snapshot holds the segment's simulation ([`Snapshot`]: the state, the
//! scheme's history, the inputs), the segment's model, the stops held, their
//! gaps at the step's start and the report so far: restored, the run
//! repeats the steps that followed bit for bit, across the hits and
//! releases among them.

use super::start::{START_SLACK, passed};
use super::stepping::StopSimulation;
use super::turns::read_following;
use super::unilateral::{Report, Unilateral};
use crate::error::{Error, Part, Problem, Result};
use crate::model::Model;
use crate::simulate::Snapshot;
use std::ops::Deref;
use std::sync::Arc;

/// A saved [`StopSimulation`] ([`StopSimulation::snapshot`]).
#[derive(Clone)]
pub struct StopSnapshot {
    // Declared before `model`, so dropped before it: it borrows the model.
    snapshot: Snapshot<'static>,
    model: Arc<Model>,
    /// Which run it was taken of: the address of its system.
    system: usize,
    held: Vec<usize>,
    implied: Vec<usize>,
    before: Vec<[f64; 2]>,
    report: Report,
}

impl StopSnapshot {
    /// Steps taken when it was taken.
    pub fn steps(&self) -> u64 {
        self.snapshot.steps()
    }

    /// The stops held when it was taken.
    pub fn held(&self) -> &[usize] {
        &self.held
    }
}

impl<S: Deref<Target: Unilateral>> StopSimulation<S> {
    /// Everything needed to come back to this point of the run.
    pub fn snapshot(&self) -> StopSnapshot {
        StopSnapshot {
            // SAFETY (of the snapshot's borrow, made up as `'static` by
            // `start`): the snapshot holds the `Arc` of the model it borrows,
            // and drops the borrow first.
            snapshot: self.sim.snapshot(),
            model: Arc::clone(&self.model),
            system: self.address(),
            held: self.held.clone(),
            implied: self.implied.clone(),
            before: self.before.clone(),
            report: self.report.clone(),
        }
    }

    /// Goes back to `snapshot`, which must be of this run (the same system).
    /// Across a hit or a release the segment's model comes back with it.
    pub fn restore(&mut self, snapshot: &StopSnapshot) -> Result<()> {
        if snapshot.system != self.address() {
            return Err(Error::Unsupported("a snapshot restores the run with stops it was taken of"));
        }
        if Arc::ptr_eq(&self.model, &snapshot.model) {
            self.sim.restore(&snapshot.snapshot)?;
        } else {
            // The old simulation goes first, then the model it borrowed.
            self.sim = snapshot.snapshot.resume();
            self.model = Arc::clone(&snapshot.model);
            self.dynamics = crate::dynamics::Dynamics::new(&self.model);
        }
        self.held.clone_from(&snapshot.held);
        self.implied.clone_from(&snapshot.implied);
        self.before.clone_from(&snapshot.before);
        // Field by field, so that each keeps its capacity (the velocity
        // entries' place reserved at the start).
        self.report.events.clone_from(&snapshot.report.events);
        self.report.overspeed.clone_from(&snapshot.report.overspeed);
        Ok(())
    }

    /// Puts the run at positions `q`, velocities `v` and `∫Ė = e` (see
    /// [`Simulation::set_state`](crate::Simulation::set_state)), at the same
    /// time and step. A stop passed there is an error: by more than
    /// [`START_SLACK`] for one not held, by more than the settings'
    /// consistency tolerance for one held (a state read while a stop is
    /// held meets its row as closely as the method keeps it, as a start
    /// must meet the rows). A held stop the state is away from by more than
    /// that tolerance is let go, with no event: the segment then starts
    /// afresh there, its model without the stop and its energy reference
    /// the energy there, as after a release (`e` is not kept).
    pub fn set_state(&mut self, q: &[f64], v: &[f64], e: f64) -> Result<()> {
        let held_tolerance = self.settings.consistency_tolerance.unwrap_or(START_SLACK);
        crate::simulate::check_initial_state(self.sim.model().n(), q, v)?;
        crate::error::finite("energy input", e)?;
        // A multi-turn joint's gaps are taken at the turn nearest the run's
        // (a state set between steps is near the last).
        read_following(&*self.system, q, v, &self.before, &mut self.after)?;
        let gaps = &self.after;
        let is_held = |k: usize| self.held.contains(&k) || self.implied.contains(&k);
        let passed_held = self.held.iter().map(|&k| (k, gaps[k][0])).find(|&(_, g)| g < -held_tolerance);
        if let Some((k, g)) = passed(gaps, is_held).or(passed_held) {
            let reason = format!("{} is passed by {:.3e}", self.system.name(k), -g);
            return Err(Problem::Stop { reason }.at(Part::InitialState));
        }
        std::mem::swap(&mut self.before, &mut self.after);
        let before = &self.before;
        let held = self.held.len();
        self.held.retain(|&k| before[k][0] <= held_tolerance);
        self.implied.retain(|&k| before[k][0] <= held_tolerance);
        if self.held.len() == held {
            return self.sim.set_state(q, v, e);
        }
        // What the rows left hold is to be found anew, as after a release.
        self.implied.clear();
        self.restart(q, v, true)
    }

    /// The address of the system, which tells runs apart.
    fn address(&self) -> usize {
        std::ptr::from_ref(&*self.system).cast::<()>() as usize
    }
}
