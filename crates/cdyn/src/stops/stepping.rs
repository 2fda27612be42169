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
use crate::dynamics::assemble::assemble;
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
        Ok(Self { sim, model, system, settings, held, implied, before, after, hits, dynamics, report })
    }

    /// One step of size `h`, then the stops: those it closed are hit (the
    /// state after the impact is the step's), held ones pulled away from
    /// are released.
    pub fn step(&mut self) -> Result<()> {
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
            let (hits, gaps) = (std::mem::take(&mut self.hits), std::mem::take(&mut self.after));
            let result = self.impact(&hits, &gaps, step, t);
            (self.hits, self.after) = (hits, gaps);
            let (q, v, held_more) = result?;
            return self.restart(&q, &v, held_more);
        }
        if !self.held.is_empty() && self.release(step, t)? {
            let (q, v) = (self.sim.q().to_vec(), self.sim.v().to_vec());
            return self.restart(&q, &v, true);
        }
        std::mem::swap(&mut self.before, &mut self.after);
        Ok(())
    }

    /// Hits the stops `hits` (whose gaps closed in the step to `t`):
    /// Newton's impact and the stops held if plastic. Returns the state
    /// after it and whether more stops are held, for the new segment.
    fn impact(&mut self, hits: &[usize], gaps: &[[f64; 2]], step: u64, t: f64) -> Result<(Vec<f64>, Vec<f64>, bool)> {
        let h = self.settings.h;
        let (mut q, v) = (self.sim.q().to_vec(), self.sim.v().to_vec());
        let (rows, implied) = self.split_implied(hits, &q, &v, t)?;
        // The positions onto every row, stops hit included, and the
        // velocities there with (v̂) and without (v_p) the stops hit
        // moving: v_p is Newton's plastic impact; v̂ + (1 + e)(v_p − v̂)
        // meets the other rows and leaves the stops at −e times v̂'s rate.
        let mut impact = self.system.model_holding(&rows)?;
        let mut plastic = v.clone();
        assemble(&impact, &mut q, &mut plastic, t, ASSEMBLY_TOLERANCE)?;
        let mut free = v;
        assemble(&self.model, &mut q.clone(), &mut free, t, ASSEMBLY_TOLERANCE)?;
        // Only the rates are read from these: a periodic gap's turn does not matter.
        let mut rates = vec![[0.0; 2]; gaps.len()];
        self.system.gaps(&q, &free, &mut rates)?;
        // A stop whose gap is opening again at the stop crossed and turned
        // within the step (a graze): its position is put back, and the
        // impact is of the stops still closing. Held on the sign of ġ
        // alone, Panda's joint 6 lost 0.16 J grazing its lower limit.
        let closing = |k: &usize| rates[*k][1] < 0.0;
        let held = self.held.len();
        let rows: Vec<usize> = rows[..held].iter().chain(rows[held..].iter().filter(|k| closing(k))).copied().collect();
        let implied: Vec<usize> = implied.into_iter().filter(closing).collect();
        if rows.len() < impact.m() - (self.model.m() - held) {
            // M-orthogonal projections nest: onto fewer rows from v̂.
            impact = self.system.model_holding(&rows)?;
            plastic.clone_from(&free);
            assemble(&impact, &mut q.clone(), &mut plastic, t, ASSEMBLY_TOLERANCE)?;
        }
        // One coefficient for stops hit at once: the largest of theirs. A
        // rebound that the load pressing into the stop (g̈ < 0, over the
        // step) would end within a step, `2 e |ġ| < |g̈| h`, is a plastic
        // impact: bounces shrinking by e each would otherwise come at every
        // step without end (Zeno), each a hit.
        // The rebound is from ġ at the crossing, not at the step's end: seen
        // up to h late, the joint has gained speed from the load since, and
        // rebounding with it gave back energy the bounce did not have (a
        // bounce every second step without end, at 7.4e-3 rad/s, seen).
        let crossings: Vec<[f64; 2]> = hits.iter().map(|&k| crossing(self.before[k], gaps[k], h)).collect();
        let bounces = |(k, [_, rate]): (usize, [f64; 2])| {
            let pressing = (self.before[k][1] - gaps[k][1]) / h;
            closing(&k) && 2.0 * self.system.restitution(k) * -rate >= pressing * h
        };
        let bouncing = || hits.iter().copied().zip(crossings.iter().copied()).filter(|&hit| bounces(hit));
        let e = bouncing().map(|(k, _)| self.system.restitution(k)).fold(0.0, f64::max);
        let slower = bouncing().map(|(k, [_, rate])| (rate / rates[k][1]).clamp(0.0, 1.0)).fold(1.0, f64::min);
        // v_p + e r (v_p − v̂): the stops' rate −e r ġ, r = ġ(crossing) / ġ.
        let v: Vec<f64> = free.iter().zip(&plastic).map(|(f, p)| p + e * slower * (p - f)).collect();
        let kinetic_lost = impact.kinetic(&q, &free) - impact.kinetic(&q, &v);
        let held_more = e == 0.0 && rows.len() > held;
        for (&stop, [s, _]) in hits.iter().zip(crossings) {
            let t = t - h + s * h;
            let held = held_more && closing(&stop);
            let change = Change::Impact { rate: rates[stop][1], kinetic_lost, held };
            self.report.events.push(Event { stop, step, t, change });
        }
        if held_more {
            self.held = rows;
            self.implied.extend(implied);
        }
        Ok((q, v, held_more))
    }

    /// The stops to hold as rows after hitting `hits` at `(q, v)` — the
    /// held ones and each hit whose row is independent of the model's rows
    /// and of those before it — and the hits left out, which the rows
    /// already hold: a row that depends on the others would make the
    /// constraints singular. Panda's two fingers, one a `<mimic>` of the
    /// other, reach their lower bound together; with the first finger's
    /// stop and the mimic row held, the second's stop holds nothing more.
    fn split_implied(&self, hits: &[usize], q: &[f64], v: &[f64], t: f64) -> Result<(Vec<usize>, Vec<usize>)> {
        let (mut rows, mut implied) = (self.held.clone(), Vec::new());
        let others = self.model.m() - self.held.len();
        for &stop in hits {
            // More rows than coordinates cannot be independent.
            let independent = others + rows.len() < q.len() && {
                rows.push(stop);
                let model = self.system.model_holding(&rows)?;
                rows.pop();
                !matches!(Dynamics::new(&model).evaluate(&model, q, v, t), Err(Breakdown::Singular(_)))
            };
            if independent { rows.push(stop) } else { implied.push(stop) }
        }
        Ok((rows, implied))
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

/// How closely an impact's projection meets the rows.
const ASSEMBLY_TOLERANCE: f64 = 1e-12;

/// Where in a step of `h` (a fraction of it) the cubic through `(g, ġ)` at
/// both ends crosses zero (`g ≥ 0` at the start, `< 0` at the end), by
/// bisection, and the cubic's rate there.
fn crossing([g0, r0]: [f64; 2], [g1, r1]: [f64; 2], h: f64) -> [f64; 2] {
    let cubic = |s: f64| {
        let (s2, s3) = (s * s, s * s * s);
        g0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + r0 * h * (s3 - 2.0 * s2 + s)
            + g1 * (3.0 * s2 - 2.0 * s3)
            + r1 * h * (s3 - s2)
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if cubic(mid) >= 0.0 { lo = mid } else { hi = mid }
    }
    let s = 0.5 * (lo + hi);
    let slope = g0 * (6.0 * s * s - 6.0 * s)
        + r0 * h * (3.0 * s * s - 4.0 * s + 1.0)
        + g1 * (6.0 * s - 6.0 * s * s)
        + r1 * h * (3.0 * s * s - 2.0 * s);
    [s, slope / h]
}
