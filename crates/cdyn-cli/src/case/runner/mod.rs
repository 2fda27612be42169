//! Runs one case and records it with the library's [`Recorder`]: a CSV row
//! per sample, written as the run goes so that a run which fails keeps what
//! it wrote, plus the series and statistics the summary and figures need.
//!
//! Here the [`Case`] and the runs (to a CSV file, in memory, quietly);
//! `estimate` what a run will write before it starts; `result` what a case
//! produced, as `summary.json` reports it; `rows` the samples as CSV rows;
//! `joint_stats` a spatial run's joint space over its samples; `limits` the
//! joint limits a run holds; `stiffness` a step too long for its damping.
//!
//! May import: `io` (and `case`'s frames).

mod estimate;
mod joint_stats;
pub mod limits;
mod result;
mod rows;
pub mod stiffness;

pub use estimate::{Estimate, OUTPUT_LIMIT, every_to_fit};
pub use joint_stats::{ActuatorStats, JointColumn, JointColumns, JointStats};
pub use result::{CaseResult, NewtonReport};
pub use rows::{Rows, columns, row_values};

use crate::case::frames::Frames;
use crate::io::interrupt;
use crate::io::output::AtomicFile;
use crate::io::progress;
use anyhow::{Context, Result};
use cdyn::models::Example;
use cdyn::record::{Record, Recorder, Sink};
use cdyn::simulate::system::System;
use cdyn::simulate::{Stepper, steps_to};
use cdyn::stops::StopSimulation;
use cdyn::{Settings, Simulation};
use indicatif::ProgressBar;
use joint_stats::Watching;
use result::Method;
use rows::CsvRows;
use std::path::Path;

/// One case to run.
pub struct Case {
    /// Its name: the CSV file's stem.
    pub name: String,
    /// The model and its initial state.
    pub example: Example,
    /// Scheme, step and method.
    pub settings: Settings,
    /// End time, a whole number of steps.
    pub t_end: f64,
    /// Write a sample every this many steps.
    pub every: u64,
    /// What projecting the initial state onto the constraints changed, if it was done.
    pub assembly: Option<cdyn::dynamics::assemble::Assembly>,
    /// The scenario entry behind each constraint row (`joints[2] (revolute)`),
    /// where the model comes from entries; errors name it instead of the row.
    pub row_entries: Vec<String>,
    /// What the model's files hold that is not modelled (a URDF's
    /// collisions, transmissions), one line each, for the run to say.
    pub notes: Vec<String>,
    /// The scenario entry behind each force element of the model (a
    /// joint's damping, a damper), where known: a step too long for it names it.
    pub force_entries: Vec<String>,
    /// The joint limits the run holds, if any: it then steps the model of
    /// the limits held ([`cdyn::stops::StopSimulation`]).
    pub limits: Option<limits::Limits>,
    /// Where a spatial run's joint columns are among the observables, for
    /// `summary.json`'s `joint_space`.
    pub joint_columns: Option<JointColumns>,
    /// A spatial run in joint coordinates: the reader of the bodies' poses
    /// its drawings show (its own `q` are the joints').
    pub poses: Option<cdyn::spatial::BodyPoses>,
}

impl Case {
    /// Empty statistics of its joint columns (none without them).
    fn joint_stats(&self) -> JointStats {
        let at = self.joint_columns.as_ref();
        at.map_or_else(JointStats::default, |at| JointStats::new(&self.example.observables, at))
    }

    /// Checks that the case can start: settings valid, initial state
    /// consistent, and an explicit step within its scheme's stability limit
    /// on the damping and springs ([`stiffness::refusal`]): past it, a run
    /// diverges or, worse, ends with a wrong answer.
    pub fn check(&self) -> Result<()> {
        let sim = Simulation::new(&self.example.model, self.settings, &self.example.q0, &self.example.v0)?;
        let (scheme, h) = (self.settings.scheme, self.settings.h);
        if let Some(refusal) = stiffness::refusal(scheme, h, sim.tuning(), &self.force_entries) {
            anyhow::bail!("case {}: {refusal}", self.name);
        }
        Ok(())
    }
}

/// Runs `case` keeping every sample in memory (no files, no progress bar):
/// the Python package's run. `stop` is asked every few thousand steps
/// whether to stop (Ctrl-C in Python); a stopped run is marked interrupted.
pub fn run_case_in_memory(case: &Case, stop: &dyn Fn() -> bool) -> (CaseResult, Rows) {
    let mut rows = Rows { columns: columns(&case.example), ..Rows::default() };
    let mut states = States::default();
    let mut stats = case.joint_stats();
    let sink = Watching { inner: &mut rows, stats: &mut stats };
    let recorder = Recorder::example(&case.example).keep_series(false).sink(sink);
    let Ok(record) = simulate(case, recorder, Watch::Asking(stop), Some(&mut states));
    (rows.t_exact, rows.q, rows.v) = (states.t, states.q, states.v);
    (CaseResult::new(case, record).with_joint_space(case, stats), rows)
}

/// Runs `case`, writing `dir/<name>.csv` (under a temporary name until it
/// is complete). A simulation error is recorded in the result (the CSV keeps
/// every row before it); so is an interrupt (SIGINT, SIGTERM), which stops
/// the run after the step it is in. I/O errors are returned, and leave no CSV.
pub fn run_case(case: &Case, dir: &Path, progress: &ProgressBar) -> Result<CaseResult> {
    let path = dir.join(format!("{}.csv", case.name));
    let mut file = AtomicFile::create(&path)?;
    let mut stats = case.joint_stats();
    let record = CsvRows::start(file.writer(), &case.example).and_then(|rows| {
        let sink = Watching { inner: rows, stats: &mut stats };
        let recorder = Recorder::example(&case.example).keep_series(true).sink(sink);
        simulate(case, recorder, Watch::Interrupts(progress), None)
    });
    let record = record.with_context(|| format!("cannot write {}", path.display()))?;
    file.commit()?;
    Ok(CaseResult::new(case, record).with_joint_space(case, stats))
}

/// Runs `case` keeping only its statistics (for sweeps).
pub fn run_case_quietly(case: &Case) -> CaseResult {
    let Ok(record) = simulate(case, Recorder::example(&case.example), Watch::Nothing, None);
    CaseResult::new(case, record)
}

/// Whether a run stops when an interrupt was asked for, and shows its progress.
#[derive(Clone, Copy)]
enum Watch<'p> {
    Nothing,
    Interrupts(&'p ProgressBar),
    /// Stops when this says so, asked every [`progress::STEPS_PER_TICK`] steps.
    Asking(&'p dyn Fn() -> bool),
}

/// The time, `q` and `v` of each sample, one after another.
#[derive(Default)]
struct States {
    t: Vec<f64>,
    q: Vec<f64>,
    v: Vec<f64>,
}

/// Runs `case` into `recorder` (and `states`); an error of the simulation,
/// also one starting it, is kept in the record, an error of the sink returned.
fn simulate<K: Sink>(
    case: &Case,
    recorder: Recorder<'_, K>,
    watch: Watch<'_>,
    states: Option<&mut States>,
) -> Result<(Record, Method), K::Error> {
    let ex = &case.example;
    let mut frames = match watch {
        Watch::Interrupts(_) if ex.drawing.is_some() || ex.sketch.is_some() => match &case.poses {
            Some(poses) => Frames::of_poses(poses.clone()),
            None => Frames::of(ex.model.n()),
        },
        _ => Frames::none(),
    };
    if let Some(limits) = &case.limits {
        return match StopSimulation::new(&*limits.system, case.settings, &ex.q0, &ex.v0) {
            Ok(mut run) => {
                let (record, interrupted) =
                    drive(&mut run, recorder, case.t_end, case.every, watch, &mut frames, states)?;
                let mut method = run.simulation(|sim| Method::of(sim, interrupted, frames));
                method.limits = Some(limits.report(run.report()));
                Ok((record, method))
            }
            Err(e) => Ok((recorder.abandon(e), Method::default())),
        };
    }
    match Simulation::new(&ex.model, case.settings, &ex.q0, &ex.v0) {
        Ok(mut sim) => {
            let (record, interrupted) = drive(&mut sim, recorder, case.t_end, case.every, watch, &mut frames, states)?;
            Ok((record, Method::of(&sim, interrupted, frames)))
        }
        Err(e) => Ok((recorder.abandon(e), Method::default())),
    }
}

/// What the runner steps: a simulation, or a run with stops.
trait Stepped {
    fn step(&mut self) -> cdyn::Result<()>;
    fn steps(&self) -> u64;
    fn t(&self) -> f64;
    fn q(&self) -> &[f64];
    fn v(&self) -> &[f64];
    fn h(&self) -> f64;
    fn sample<K: Sink>(&mut self, recorder: &mut Recorder<'_, K>) -> Result<(), K::Error>;
    fn finish<K: Sink>(&self, recorder: Recorder<'_, K>) -> Record;
}

impl<S: System> Stepped for Stepper<S> {
    fn step(&mut self) -> cdyn::Result<()> {
        Stepper::step(self)
    }
    fn steps(&self) -> u64 {
        Stepper::steps(self)
    }
    fn t(&self) -> f64 {
        Stepper::t(self)
    }
    fn q(&self) -> &[f64] {
        Stepper::q(self)
    }
    fn v(&self) -> &[f64] {
        Stepper::v(self)
    }
    fn h(&self) -> f64 {
        self.settings().h
    }
    fn sample<K: Sink>(&mut self, recorder: &mut Recorder<'_, K>) -> Result<(), K::Error> {
        recorder.sample(self)
    }
    fn finish<K: Sink>(&self, recorder: Recorder<'_, K>) -> Record {
        recorder.finish(self)
    }
}

impl<U: std::ops::Deref<Target: cdyn::stops::Unilateral>> Stepped for StopSimulation<U> {
    fn step(&mut self) -> cdyn::Result<()> {
        StopSimulation::step(self)
    }
    fn steps(&self) -> u64 {
        StopSimulation::steps(self)
    }
    fn t(&self) -> f64 {
        StopSimulation::t(self)
    }
    fn q(&self) -> &[f64] {
        StopSimulation::q(self)
    }
    fn v(&self) -> &[f64] {
        StopSimulation::v(self)
    }
    fn h(&self) -> f64 {
        self.simulation(|sim| sim.settings().h)
    }
    fn sample<K: Sink>(&mut self, recorder: &mut Recorder<'_, K>) -> Result<(), K::Error> {
        self.simulation_mut(|sim| recorder.sample(sim))
    }
    fn finish<K: Sink>(&self, recorder: Recorder<'_, K>) -> Record {
        self.simulation(|sim| recorder.finish(sim))
    }
}

/// [`Recorder::run`], step by step so that an interrupt stops the run
/// between two steps: the state it stopped at is sampled too (a complete
/// CSV row), and the record says it was interrupted. `frames` is offered
/// every sample, and the state it ends at.
fn drive<S: Stepped, K: Sink>(
    sim: &mut S,
    mut recorder: Recorder<'_, K>,
    t_end: f64,
    every: u64,
    watch: Watch<'_>,
    frames: &mut Frames,
    mut states: Option<&mut States>,
) -> Result<(Record, bool), K::Error> {
    let (error, interrupted) = drive_frames(sim, &mut recorder, t_end, every, watch, frames, &mut states)?;
    frames.end(sim.t(), sim.q());
    let mut record = sim.finish(recorder);
    if error.is_some() {
        record.error = error;
    }
    Ok((record, interrupted))
}

/// [`drive`] until the run ends; returns the simulation's error, if any, and whether it was interrupted.
fn drive_frames<S: Stepped, K: Sink>(
    sim: &mut S,
    recorder: &mut Recorder<'_, K>,
    t_end: f64,
    every: u64,
    watch: Watch<'_>,
    frames: &mut Frames,
    states: &mut Option<&mut States>,
) -> Result<(Option<cdyn::Error>, bool), K::Error> {
    let steps = match steps_to(t_end, sim.h()) {
        Ok(n) => n,
        Err(e) => return Ok((Some(e), false)),
    };
    let every = every.max(1);
    // Where this case's steps start on a bar shared by several cases.
    let start = match watch {
        Watch::Interrupts(progress) => progress.position(),
        Watch::Nothing | Watch::Asking(_) => 0,
    };
    sample(recorder, sim, frames, states)?;
    let mut sampled = sim.steps();
    while sim.steps() < steps {
        if let Watch::Interrupts(progress) = watch
            && sim.steps().is_multiple_of(progress::STEPS_PER_TICK)
        {
            progress.set_position(start + sim.steps());
        }
        let stop = match watch {
            Watch::Nothing => false,
            Watch::Interrupts(_) => interrupt::requested().is_some(),
            Watch::Asking(stop) => sim.steps().is_multiple_of(progress::STEPS_PER_TICK) && stop(),
        };
        if stop {
            if sampled != sim.steps() {
                sample(recorder, sim, frames, states)?;
            }
            return Ok((None, true));
        }
        if let Err(e) = sim.step() {
            return Ok((Some(e), false));
        }
        let n = sim.steps();
        if n.is_multiple_of(every) || n == steps {
            sample(recorder, sim, frames, states)?;
            sampled = n;
        }
    }
    if let Watch::Interrupts(progress) = watch {
        progress.set_position(start + steps);
    }
    Ok((None, false))
}

/// Samples `sim` into `recorder`, offers its positions to `frames`, and
/// keeps its time, `q` and `v` in `states` where they are kept.
fn sample<S: Stepped, K: Sink>(
    recorder: &mut Recorder<'_, K>,
    sim: &mut S,
    frames: &mut Frames,
    states: &mut Option<&mut States>,
) -> Result<(), K::Error> {
    sim.sample(recorder)?;
    frames.push(sim.t(), sim.q());
    if let Some(s) = states.as_deref_mut() {
        s.t.push(sim.t());
        s.q.extend_from_slice(sim.q());
        s.v.extend_from_slice(sim.v());
    }
    Ok(())
}
