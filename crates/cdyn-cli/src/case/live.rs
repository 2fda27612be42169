//! A case stepped from outside — by Python's `Simulation`, the C API or an
//! FMU's instance — instead of run to its end: inputs set and outputs read
//! between steps, the state read, written, saved and restored.
//!
//! The outputs are the CSV columns of `cdyn run` ([`columns`], one list),
//! the ones `[output] select` names, computed as a CSV row is
//! ([`row_values`]): a stepped run and `cdyn run` agree to the bit.
//!
//! Each [`Live`] owns its case, and so its model and the values of the
//! model's inputs: two of them never share an input.
//!
//! A case with joint limits is stepped as `cdyn run` steps it, by the
//! library's [`StopSimulation`]: the limits are hit, held and released
//! between steps, a snapshot saves the limits held and the segment's model
//! with the state, and the models it builds at a hit or a release share the
//! case's inputs. A step that hits or releases no limit allocates nothing;
//! one that does builds the model of the limits held then, and allocates.

use crate::case::inputs::selected;
use crate::case::runner::limits::LimitsReport;
use crate::case::runner::{Case, columns, row_values};
use crate::case::scenario::Scenario;
use anyhow::{Result, anyhow};
use cdyn::Simulation;
use cdyn::models::Example;
use cdyn::record::Sample;
use cdyn::simulate::Snapshot;
use cdyn::stops::{StopSimulation, StopSnapshot, Unilateral};
use std::path::Path;
use std::sync::Arc;

/// A case being stepped.
pub struct Live {
    // Declared first, so dropped first: `run` borrows the model in `case`.
    run: Run,
    outputs: Outputs,
    case: Arc<Case>,
}

/// What a [`Live`] steps: the case's model, or its joint limits' run.
enum Run {
    // Both boxed: kilobytes each, of different sizes.
    Free(Box<Simulation<'static>>),
    Limited(Box<StopSimulation<Arc<dyn Unilateral + Send + Sync>>>),
}

/// A saved [`Live`]: it keeps the case alive, so it stays valid after the
/// `Live` it was taken of is gone, and restores only into that one.
#[derive(Clone)]
pub struct LiveSnapshot {
    snapshot: Saved,
    _case: Arc<Case>,
}

#[derive(Clone)]
enum Saved {
    Free(Snapshot<'static>),
    Limited(StopSnapshot),
}

/// The selected columns and the buffers their values are computed in.
struct Outputs {
    selected: Vec<usize>,
    names: Vec<String>,
    row: Vec<f64>,
    observed: Vec<f64>,
    /// The reference state and its observables, where there is a reference.
    reference: (Vec<f64>, Vec<f64>, Vec<f64>),
}

impl Live {
    /// The case `scenario` describes (as `cdyn run` would run it), started
    /// at its initial state; `path` names the scenario in errors.
    pub fn from_scenario(scenario: &Scenario, path: &Path) -> Result<Self> {
        scenario.refuse_sweep(path, "run")?;
        let case = scenario.case(path)?;
        Live::new(case, scenario.output.select.as_deref(), &path.display().to_string())
    }

    /// `case` started at its initial state, with the outputs `select` names
    /// (every column without it); `file` names the scenario in errors.
    pub fn new(case: Case, select: Option<&[String]>, file: &str) -> Result<Self> {
        let all = columns(&case.example);
        let selected = selected(select, &all, file)?;
        let case = Arc::new(case);
        // SAFETY: the model lives in the `Arc`'s allocation, which neither
        // moves nor changes while a `Live` or a `LiveSnapshot` holds the
        // `Arc`; `sim` and every snapshot of it are dropped before the last
        // of them, and no reference with the made-up lifetime leaves here.
        let model: &'static cdyn::Model = unsafe { &*std::ptr::from_ref(&case.example.model) };
        let ex = &case.example;
        let run = match &case.limits {
            Some(limits) => StopSimulation::new(Arc::clone(&limits.system), case.settings, &ex.q0, &ex.v0)
                .map(|run| Run::Limited(Box::new(run))),
            None => Simulation::new(model, case.settings, &ex.q0, &ex.v0).map(|sim| Run::Free(Box::new(sim))),
        };
        let run = run.map_err(|e| anyhow!("{file}: {e}"))?;
        let (n, observables) = (model.n(), ex.observables.len());
        let outputs = Outputs {
            names: selected.iter().map(|&i| all[i].clone()).collect(),
            selected,
            row: Vec::with_capacity(all.len()),
            observed: vec![0.0; observables],
            reference: (vec![0.0; n], vec![0.0; n], vec![0.0; observables]),
        };
        let mut live = Live { run, outputs, case };
        live.warm_up().map_err(|e| anyhow!("{file}: {e}"))?;
        Ok(live)
    }

    /// Takes a step, reads the outputs and goes back to the start (a
    /// snapshot restores to the bit): the code and the buffers a step uses
    /// are touched here, out of a real-time loop. `cdyn bench --realtime
    /// --light`, the pendulum's first co-simulation step in three runs
    /// each: 16.2, 6.9, 6.3 µs without this, 2.6, 5.8, 3.7 µs with it
    /// (the median step: 1.1 µs). A step that fails here fails again when
    /// taken.
    fn warm_up(&mut self) -> cdyn::Result<()> {
        let start = self.snapshot();
        let mut outputs = vec![0.0; self.outputs.names.len()];
        if self.step(1).is_ok() {
            self.outputs(&mut outputs);
        }
        self.restore(&start)
    }

    /// The case stepped.
    pub fn case(&self) -> &Case {
        &self.case
    }

    /// Lends the simulation being stepped (of the current segment, with limits) to `f`.
    fn simulation<R>(&self, f: impl FnOnce(&Simulation<'_>) -> R) -> R {
        match &self.run {
            Run::Free(sim) => f(sim),
            Run::Limited(run) => run.simulation(f),
        }
    }

    /// Lends the simulation being stepped to `f`, mutably.
    fn simulation_mut<R>(&mut self, f: impl FnOnce(&mut Simulation<'_>) -> R) -> R {
        match &mut self.run {
            Run::Free(sim) => f(sim),
            Run::Limited(run) => run.simulation_mut(f),
        }
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.simulation(|sim| sim.t())
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.simulation(|sim| sim.steps())
    }

    /// The step size.
    pub fn h(&self) -> f64 {
        self.simulation(|sim| sim.settings().h)
    }

    /// Current positions.
    pub fn q(&self) -> &[f64] {
        match &self.run {
            Run::Free(sim) => sim.q(),
            Run::Limited(run) => run.q(),
        }
    }

    /// Current velocities.
    pub fn v(&self) -> &[f64] {
        match &self.run {
            Run::Free(sim) => sim.v(),
            Run::Limited(run) => run.v(),
        }
    }

    /// `∫Ė` so far: with `q` and `v`, the full state. With joint limits,
    /// since the last hit or release (where the energy reference starts
    /// afresh, see [`cdyn::stops`]).
    pub fn energy_input(&self) -> f64 {
        self.simulation(|sim| sim.energy_input())
    }

    /// The current value of input `index`.
    pub fn input(&self, index: usize) -> cdyn::Result<f64> {
        self.simulation(|sim| sim.input(index))
    }

    /// Takes `n` steps; stops at the first that fails.
    pub fn step(&mut self, n: u64) -> cdyn::Result<()> {
        for _ in 0..n {
            match &mut self.run {
                Run::Free(sim) => sim.step()?,
                Run::Limited(run) => run.step()?,
            }
        }
        Ok(())
    }

    /// What the case's joint limits did so far (the report `cdyn run`
    /// writes to `summary.json`'s `limits`), if it has limits.
    pub fn limits(&self) -> Option<LimitsReport> {
        match (&self.run, &self.case.limits) {
            (Run::Limited(run), Some(limits)) => Some(limits.report(run.report())),
            _ => None,
        }
    }

    /// How many limits were hit and released so far (0 without limits).
    pub fn limit_events(&self) -> usize {
        match &self.run {
            Run::Limited(run) => run.report().events.len(),
            Run::Free(_) => 0,
        }
    }

    /// The inputs' names, in order.
    pub fn input_names(&self) -> Vec<&str> {
        self.case.example.model.inputs().iter().map(|u| u.name()).collect()
    }

    /// Sets input `index` (see [`Simulation::set_input`]).
    pub fn set_input(&mut self, index: usize, value: f64) -> cdyn::Result<()> {
        self.simulation_mut(|sim| sim.set_input(index, value))
    }

    /// Sets the input called `name`.
    pub fn set_input_named(&mut self, name: &str, value: f64) -> cdyn::Result<()> {
        self.simulation_mut(|sim| sim.set_input_named(name, value))
    }

    /// The outputs' names, in order.
    pub fn output_names(&self) -> &[String] {
        &self.outputs.names
    }

    /// The outputs at the current state, into `out` (as many as names).
    pub fn outputs(&mut self, out: &mut [f64]) {
        let (o, ex) = (&mut self.outputs, &self.case.example);
        match &mut self.run {
            Run::Free(sim) => o.read(sim, ex, out),
            Run::Limited(run) => run.simulation_mut(|sim| o.read(sim, ex, out)),
        }
    }

    /// Puts the state at `(q, v, ∫Ė)` (see [`Simulation::set_state`]; with
    /// joint limits, [`StopSimulation::set_state`]: a limit passed there is
    /// an error, a held one the state is away from is let go).
    pub fn set_state(&mut self, q: &[f64], v: &[f64], e: f64) -> cdyn::Result<()> {
        match &mut self.run {
            Run::Free(sim) => sim.set_state(q, v, e),
            Run::Limited(run) => run.set_state(q, v, e),
        }
    }

    /// Everything needed to come back to this point.
    pub fn snapshot(&self) -> LiveSnapshot {
        let snapshot = match &self.run {
            Run::Free(sim) => Saved::Free(sim.snapshot()),
            Run::Limited(run) => Saved::Limited(run.snapshot()),
        };
        LiveSnapshot { snapshot, _case: Arc::clone(&self.case) }
    }

    /// Goes back to `snapshot`, taken of this `Live`.
    pub fn restore(&mut self, snapshot: &LiveSnapshot) -> cdyn::Result<()> {
        match (&mut self.run, &snapshot.snapshot) {
            (Run::Free(sim), Saved::Free(saved)) => sim.restore(saved),
            (Run::Limited(run), Saved::Limited(saved)) => run.restore(saved),
            _ => Err(cdyn::Error::Unsupported("a snapshot restores the simulation it was taken of")),
        }
    }
}

impl Outputs {
    /// The selected outputs of `sim`'s current state, computed as a CSV row is, into `out`.
    fn read(&mut self, sim: &mut Simulation<'_>, ex: &Example, out: &mut [f64]) {
        let measures = sim.measure();
        let t = sim.t();
        (ex.observe)(t, sim.q(), sim.v(), &mut self.observed);
        let (qr, vr, at_ref) = &mut self.reference;
        let first = self.observed.first().copied().unwrap_or(0.0);
        let error = ex.error_of(first, t, qr, vr, at_ref);
        let sample = Sample { step: sim.steps(), t, observables: &self.observed, measures, error };
        self.row.clear();
        self.row.extend(row_values(&sample));
        for (out, &i) in out.iter_mut().zip(&self.selected) {
            *out = self.row[i];
        }
    }
}
