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

use crate::case::inputs::selected;
use crate::case::runner::{Case, columns, row_values};
use crate::case::scenario::Scenario;
use anyhow::{Result, anyhow};
use cdyn::Simulation;
use cdyn::record::Sample;
use cdyn::simulate::Snapshot;
use std::path::Path;
use std::sync::Arc;

/// A case being stepped.
pub struct Live {
    // Declared first, so dropped first: `sim` borrows the model in `case`.
    sim: Simulation<'static>,
    outputs: Outputs,
    case: Arc<Case>,
}

/// A saved [`Live`]: it keeps the case alive, so it stays valid after the
/// `Live` it was taken of is gone, and restores only into that one.
#[derive(Clone)]
pub struct LiveSnapshot {
    snapshot: Snapshot<'static>,
    _case: Arc<Case>,
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
        if let Some(limits) = &case.limits {
            return Err(anyhow!(
                "{file}: joint {}: limit: joint limits are held by cdyn run (and cdyn.run), not yet by a case stepped from outside (cdyn.Simulation, the C API, the FMU)",
                limits.first_joint()
            ));
        }
        let all = columns(&case.example);
        let selected = selected(select, &all, file)?;
        let case = Arc::new(case);
        // SAFETY: the model lives in the `Arc`'s allocation, which neither
        // moves nor changes while a `Live` or a `LiveSnapshot` holds the
        // `Arc`; `sim` and every snapshot of it are dropped before the last
        // of them, and no reference with the made-up lifetime leaves here.
        let model: &'static cdyn::Model = unsafe { &*std::ptr::from_ref(&case.example.model) };
        let ex = &case.example;
        let sim = Simulation::new(model, case.settings, &ex.q0, &ex.v0).map_err(|e| anyhow!("{file}: {e}"))?;
        let (n, observables) = (model.n(), ex.observables.len());
        let outputs = Outputs {
            names: selected.iter().map(|&i| all[i].clone()).collect(),
            selected,
            row: Vec::with_capacity(all.len()),
            observed: vec![0.0; observables],
            reference: (vec![0.0; n], vec![0.0; n], vec![0.0; observables]),
        };
        let mut live = Live { sim, outputs, case };
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
        let start = self.sim.snapshot();
        let mut outputs = vec![0.0; self.outputs.names.len()];
        if self.sim.step().is_ok() {
            self.outputs(&mut outputs);
        }
        self.sim.restore(&start)
    }

    /// The case stepped.
    pub fn case(&self) -> &Case {
        &self.case
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.sim.t()
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.sim.steps()
    }

    /// The step size.
    pub fn h(&self) -> f64 {
        self.sim.settings().h
    }

    /// Current positions.
    pub fn q(&self) -> &[f64] {
        self.sim.q()
    }

    /// Current velocities.
    pub fn v(&self) -> &[f64] {
        self.sim.v()
    }

    /// `∫Ė` so far: with `q` and `v`, the full state.
    pub fn energy_input(&self) -> f64 {
        self.sim.energy_input()
    }

    /// The current value of input `index`.
    pub fn input(&self, index: usize) -> cdyn::Result<f64> {
        self.sim.input(index)
    }

    /// Takes `n` steps; stops at the first that fails.
    pub fn step(&mut self, n: u64) -> cdyn::Result<()> {
        for _ in 0..n {
            self.sim.step()?;
        }
        Ok(())
    }

    /// The inputs' names, in order.
    pub fn input_names(&self) -> Vec<&str> {
        self.case.example.model.inputs().iter().map(|u| u.name()).collect()
    }

    /// Sets input `index` (see [`Simulation::set_input`]).
    pub fn set_input(&mut self, index: usize, value: f64) -> cdyn::Result<()> {
        self.sim.set_input(index, value)
    }

    /// Sets the input called `name`.
    pub fn set_input_named(&mut self, name: &str, value: f64) -> cdyn::Result<()> {
        self.sim.set_input_named(name, value)
    }

    /// The outputs' names, in order.
    pub fn output_names(&self) -> &[String] {
        &self.outputs.names
    }

    /// The outputs at the current state, into `out` (as many as names).
    pub fn outputs(&mut self, out: &mut [f64]) {
        let (sim, o, ex) = (&mut self.sim, &mut self.outputs, &self.case.example);
        let measures = sim.measure();
        let t = sim.t();
        (ex.observe)(t, sim.q(), sim.v(), &mut o.observed);
        let (qr, vr, at_ref) = &mut o.reference;
        let first = o.observed.first().copied().unwrap_or(0.0);
        let error = ex.error_of(first, t, qr, vr, at_ref);
        let sample = Sample { step: sim.steps(), t, observables: &o.observed, measures, error };
        o.row.clear();
        o.row.extend(row_values(&sample));
        for (out, &i) in out.iter_mut().zip(&o.selected) {
            *out = o.row[i];
        }
    }

    /// Puts the state at `(q, v, ∫Ė)` (see [`Simulation::set_state`]).
    pub fn set_state(&mut self, q: &[f64], v: &[f64], e: f64) -> cdyn::Result<()> {
        self.sim.set_state(q, v, e)
    }

    /// Everything needed to come back to this point.
    pub fn snapshot(&self) -> LiveSnapshot {
        LiveSnapshot { snapshot: self.sim.snapshot(), _case: Arc::clone(&self.case) }
    }

    /// Goes back to `snapshot`, taken of this `Live`.
    pub fn restore(&mut self, snapshot: &LiveSnapshot) -> cdyn::Result<()> {
        self.sim.restore(&snapshot.snapshot)
    }
}
