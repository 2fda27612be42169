//! [`StopSimulation`]: a run with stops taken one step at a time, for a
//! caller that records or steers it between steps (`cdyn run`'s recorder,
//! [`run_with_stops`](super::run_with_stops)). It owns the current
//! segment — the model of the stops held and the [`Simulation`] of it —
//! and after each step hits, holds and releases stops as the module's
//! head says, starting the next segment where the last one ended.
//!
//! A step that hits and releases nothing allocates nothing (with a system
//! whose [`Unilateral::gaps`] and [`Unilateral::overspeed`] do not): the
//! gaps, the stops hit and the report's velocity entries live in buffers
//! kept here. A hit or a release builds the model of the stops held then,
//! and allocates.

use super::start::{START_SLACK, refuse_passed};
use super::turns::read_following;
use super::unilateral::{Change, Event, Report, Unilateral};
use crate::dynamics::{Breakdown, Dynamics};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::simulate::{Settings, Simulation, steps_to};
use std::ops::Deref;
use std::sync::Arc;

/// A [`Simulation`] of a system with stops, stepped by the caller; the
/// stops are hit, held and released between steps.
///
/// `S` holds the system: borrowed (`&U`), or shared (`Arc<U>`) by a run
/// that must own what it steps.
///
/// The simulation of the current segment is lent out by
/// [`StopSimulation::simulation`] and [`StopSimulation::simulation_mut`]
/// (to sample it, say); its state is the run's state.
pub struct StopSimulation<S: Deref<Target: Unilateral>> {
    // Declared before `model`, so dropped before it: it borrows the model.
    pub(super) sim: Simulation<'static>,
    pub(super) model: Arc<Model>,
    pub(super) system: S,
    pub(super) settings: Settings,
    /// The stops held, in the order of the model's last rows.
    pub(super) held: Vec<usize>,
    /// Stops at their bound that the held rows already hold, so not rows
    /// of their own (see [`StopSimulation::split_implied`]); not hit again
    /// until a release changes what is held.
    pub(super) implied: Vec<usize>,
    /// Each stop's `(g, ġ)` at the start of the step being taken: a
    /// periodic gap as followed from the start ([`read_following`]).
    pub(super) before: Vec<[f64; 2]>,
    /// Each stop's `(g, ġ)` at the end of the step just taken, or a new
    /// reading on its way to `before`.
    pub(super) after: Vec<[f64; 2]>,
    /// The stops the step just taken closed.
    hits: Vec<usize>,
    /// `(q, v, ∫Ė)` at the start of the step being taken: where a step
    /// that closed a stop steps again from, to the crossing.
    pub(super) start: Vec<f64>,
    /// Evaluates the multipliers of the held stops' rows.
    pub(super) dynamics: Dynamics,
    pub(super) report: Report,
}

impl<S: Deref<Target: Unilateral>> StopSimulation<S> {
    /// Starts `system` at `t = 0` from `(q0, v0)` (no stop passed), no
    /// stop held, as [`Simulation::new`] starts a model.
    pub fn new(system: S, settings: Settings, q0: &[f64], v0: &[f64]) -> Result<Self> {
        let mut before = vec![[0.0; 2]; system.stops()];
        system.gaps(q0, v0, &mut before)?;
        refuse_passed(&*system, &before)?;
        let model = Arc::new(system.model_holding(&[])?);
        let sim = start(&model, settings, q0, v0)?;
        let dynamics = Dynamics::new(&model);
        let (after, hits) = (before.clone(), Vec::with_capacity(before.len()));
        let mut report = Report::default();
        // A velocity bound first exceeded in an ordinary step finds its place.
        report.overspeed.reserve_exact(system.speed_bounds());
        let (held, implied) = (Vec::with_capacity(before.len()), Vec::with_capacity(before.len()));
        let start = [q0, v0, &[0.0]].concat();
        Ok(Self { sim, model, system, settings, held, implied, before, after, hits, start, dynamics, report })
    }

    /// One step of size `h`, then the stops: where it closed some, it is
    /// taken again in parts, to the first crossing, the impact there, and
    /// on to the step's end (see [`crate::stops`]); held stops pulled
    /// away from are released.
    pub fn step(&mut self) -> Result<()> {
        let n = self.model.n();
        self.start[..n].copy_from_slice(self.sim.q());
        self.start[n..2 * n].copy_from_slice(self.sim.v());
        self.start[2 * n] = self.sim.energy_input();
        self.sim.step()?;
        let (step, t) = (self.sim.steps(), self.sim.t());
        let (q, v) = (self.sim.q(), self.sim.v());
        read_following(&*self.system, q, v, &self.before, &mut self.after)?;
        let overspeed = &mut self.report.overspeed;
        self.system.overspeed(q, v, &mut |index, ratio| match overspeed.binary_search_by_key(&index, |o| o.0) {
            Ok(k) => overspeed[k].1 = overspeed[k].1.max(ratio),
            Err(k) => overspeed.insert(k, (index, ratio, t)),
        })?;
        let (held, implied, after) = (&self.held, &self.implied, &self.after);
        self.hits.clear();
        self.hits.extend(
            (0..after.len()).filter(|k| !held.contains(k) && !implied.contains(k) && after[*k][0] < -START_SLACK),
        );
        if !self.hits.is_empty() {
            let hits = std::mem::take(&mut self.hits);
            let result = self.hit_within(&hits, step, t);
            self.hits = hits;
            return result;
        }
        if !self.held.is_empty() && self.release(step, t)? {
            let (q, v) = (self.sim.q().to_vec(), self.sim.v().to_vec());
            return self.restart(&q, &v, true);
        }
        std::mem::swap(&mut self.before, &mut self.after);
        Ok(())
    }

    /// Releases the held stops whose multiplier turned to pulling at the
    /// current state; whether any was.
    fn release(&mut self, step: u64, t: f64) -> Result<bool> {
        let (q, v) = (self.sim.q(), self.sim.v());
        self.dynamics.evaluate(&self.model, q, v, t).map_err(|b| breakdown(b, step, t))?;
        let all = self.dynamics.lambda();
        // A stop's multiplier is pulling when it is more than round-off of
        // the forces the rows carry: a joint resting on its stop with no
        // load along it (Panda's fingers, horizontal) has λ ≈ ±1e-18, and
        // releasing it on the sign alone re-hits it a step later, over and
        // over (4 259 impacts and 2 651 releases in Panda's first second).
        let floor = RELEASE_THRESHOLD * all.iter().fold(0.0, |m: f64, l| m.max(l.abs()));
        let lambda = &all[self.model.m() - self.held.len()..];
        let before = self.report.events.len();
        for (&stop, &multiplier) in self.held.iter().zip(lambda) {
            if multiplier > floor {
                self.report.events.push(Event { stop, step, t, change: Change::Release { multiplier } });
            }
        }
        let released = &self.report.events[before..];
        self.held.retain(|k| !released.iter().any(|event| event.stop == *k));
        if self.report.events.len() > before {
            // What the rows left hold is to be found anew: a stop implied
            // by one released is hit again if its gap closes.
            self.implied.clear();
        }
        Ok(self.report.events.len() > before)
    }

    /// Starts the next segment at `(q, v)`, with the model of the stops
    /// held now if they changed: the scheme afresh, the energy reference
    /// the energy there (see the module's head).
    pub(super) fn restart(&mut self, q: &[f64], v: &[f64], held_changed: bool) -> Result<()> {
        let model =
            if held_changed { Arc::new(self.system.model_holding(&self.held)?) } else { Arc::clone(&self.model) };
        self.restart_with(q, v, model, held_changed)
    }

    /// [`restart`](Self::restart) with `model`, that of the stops held now.
    pub(super) fn restart_with(&mut self, q: &[f64], v: &[f64], model: Arc<Model>, held_changed: bool) -> Result<()> {
        // The run's state need not meet the start's tolerance: it is the
        // run's, as consistent as its method keeps it.
        let settings = Settings { consistency_tolerance: None, ..self.settings };
        let mut sim = start(&model, settings, q, v)?;
        sim.continue_from(&self.sim);
        // The old simulation goes first, then the model it borrowed.
        self.sim = sim;
        if held_changed {
            self.dynamics = Dynamics::new(&model);
        }
        self.model = model;
        // A restart is up to a step (an impact's projection) from the
        // step's start: `before` still tells the turns.
        read_following(&*self.system, q, v, &self.before, &mut self.after)?;
        std::mem::swap(&mut self.before, &mut self.after);
        Ok(())
    }

    /// Lends the current segment's simulation to `f`: the run's state,
    /// time, steps and counts (which cover the whole run). Lent to a
    /// closure rather than returned, as its model is the run's to replace.
    pub fn simulation<R>(&self, f: impl FnOnce(&Simulation<'_>) -> R) -> R {
        f(&self.sim)
    }

    /// Lends the current segment's simulation to `f`, mutably (a recorder
    /// samples it so); a state `f` sets is the run's from then on.
    pub fn simulation_mut<R>(&mut self, f: impl FnOnce(&mut Simulation<'_>) -> R) -> R {
        f(&mut self.sim)
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.sim.steps()
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.sim.t()
    }

    /// Current positions.
    pub fn q(&self) -> &[f64] {
        self.sim.q()
    }

    /// Current velocities.
    pub fn v(&self) -> &[f64] {
        self.sim.v()
    }

    /// The stops held now as rows (indices, see [`Unilateral::stops`]);
    /// a stop the held rows already hold is not among them.
    pub fn held(&self) -> &[usize] {
        &self.held
    }

    /// The stops hit and released so far, and the velocity bounds exceeded.
    pub fn report(&self) -> &Report {
        &self.report
    }

    /// The report of the run.
    pub fn into_report(self) -> Report {
        self.report
    }
}

/// Steps `system` from `(q0, v0)` to `t_end` with `settings`, its stops
/// hit, held and released as they come; `observe(t, q, v)` sees the
/// start, every `every`-th step and the last (after a change made at that
/// step). Returns the changes and the velocity bounds exceeded. A
/// [`StopSimulation`] steps the same run one step at a time.
pub fn run_with_stops<U: Unilateral + ?Sized, E: From<Error>>(
    system: &U,
    settings: Settings,
    q0: &[f64],
    v0: &[f64],
    t_end: f64,
    every: u64,
    mut observe: impl FnMut(f64, &[f64], &[f64]) -> std::result::Result<(), E>,
) -> std::result::Result<Report, E> {
    let (steps, every) = (steps_to(t_end, settings.h)?, every.max(1));
    let mut run = StopSimulation::new(system, settings, q0, v0)?;
    observe(0.0, run.q(), run.v())?;
    while run.steps() < steps {
        run.step()?;
        let step = run.steps();
        if step.is_multiple_of(every) || step == steps {
            observe(run.t(), run.q(), run.v())?;
        }
    }
    Ok(run.into_report())
}

/// A simulation of the model in `model`'s allocation.
fn start(model: &Arc<Model>, settings: Settings, q: &[f64], v: &[f64]) -> Result<Simulation<'static>> {
    // SAFETY: the model lives in the `Arc`'s allocation, which neither
    // moves nor changes while the `StopSimulation` holds the `Arc`; the
    // simulation borrowing it is dropped before it (field order, and
    // `restart` replaces the simulation before the model), and no
    // reference with the made-up lifetime leaves the type: `simulation`
    // and `simulation_mut` lend it to closures that take any lifetime, so
    // keep nothing of it.
    let model: &'static Model = unsafe { &*Arc::as_ptr(model) };
    Simulation::new(model, settings, q, v)
}

fn breakdown(b: Breakdown, step: u64, t: f64) -> Error {
    match b {
        Breakdown::Singular(row) => Error::SingularConstraints { step, t, row },
        Breakdown::NonFinite => Error::Diverged { step, t },
        Breakdown::Mass(coordinate) => Error::MassNotPositive { step, t, coordinate },
    }
}

/// The multiplier a held stop's row must exceed, relative to the largest
/// the rows carry, to be released: far above round-off (1e-19 relative seen
/// on Panda), far below a real load (a release delayed by this fraction of
/// the load's rise time).
const RELEASE_THRESHOLD: f64 = 1e-10;
