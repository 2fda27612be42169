//! Runs one case and records it with the library's [`Recorder`]: a CSV row
//! per sample, written as the run goes so that a run which fails keeps what
//! it wrote, plus the series and statistics the summary and figures need.

use crate::case::frames::Frames;
use crate::io::interrupt;
use crate::io::output::AtomicFile;
use crate::io::progress;
use anyhow::{Context, Result};
use cdyn::models::Example;
use cdyn::record::{Record, Recorder, Sample, Series, Sink};
use cdyn::simulate::system::System;
use cdyn::simulate::{RankLoss, Stepper, steps_to};
use cdyn::{Settings, Simulation};
use indicatif::ProgressBar;
use serde::Serialize;
use std::io::Write;
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
}

impl Case {
    /// Checks that the case can start: settings valid, initial state consistent.
    pub fn check(&self) -> cdyn::Result<()> {
        Simulation::new(&self.example.model, self.settings, &self.example.q0, &self.example.v0).map(|_| ())
    }
}

/// Largest output a run writes, or memory it keeps, without `--force` (2 GB).
pub const OUTPUT_LIMIT: u64 = 2_000_000_000;

/// Bytes a CSV value takes at most: `-1.2345678901234567e-100,`.
const BYTES_PER_VALUE: u64 = 25;

/// What a run of some cases is expected to write and keep, before it starts.
#[derive(Debug, Clone, Copy, Default)]
pub struct Estimate {
    /// CSV rows.
    pub rows: u64,
    /// Bytes of CSV.
    pub csv_bytes: u64,
    /// Bytes of memory for the series kept for the figures.
    pub memory_bytes: u64,
}

impl Estimate {
    /// Steps of `cases` in all (for a progress bar).
    pub fn steps(cases: &[Case]) -> u64 {
        cases.iter().map(|c| steps_to(c.t_end, c.settings.h).unwrap_or(0)).sum()
    }

    /// The estimate for `cases`: a row at the start, every `every` steps and
    /// at the end; the series a fixed size however long the run
    /// ([`cdyn::record::SERIES_BUCKETS`] buckets of two entries).
    pub fn of(cases: &[Case]) -> Estimate {
        let mut total = Estimate::default();
        for case in cases {
            let steps = steps_to(case.t_end, case.settings.h).unwrap_or(0);
            let rows = steps / case.every.max(1) + 2;
            let columns = 3 + case.example.observables.len() as u64 + u64::from(case.example.reference.is_some());
            let kept = rows.min(2 * cdyn::record::SERIES_BUCKETS as u64);
            total.rows = total.rows.saturating_add(rows);
            total.csv_bytes = total.csv_bytes.saturating_add(rows.saturating_mul(columns * BYTES_PER_VALUE));
            total.memory_bytes = total.memory_bytes.saturating_add(kept * 4 * 8 + (1 << 20));
        }
        total
    }

    /// Refuses a run above [`OUTPUT_LIMIT`] (unless `force`), naming the
    /// scenario `file`, the sizes, and the `every` that would fit.
    pub fn check(&self, file: &str, every: u64, force: bool) -> Result<()> {
        let worst = self.csv_bytes.max(self.memory_bytes);
        if force || worst <= OUTPUT_LIMIT {
            return Ok(());
        }
        let suggest = every_to_fit(every, worst);
        anyhow::bail!(
            "{file}: the run would write about {:.1} GB of CSV ({} rows at [output] every = {every}), above the limit of {} GB; set [output] every = {suggest} or larger, or pass --force",
            self.csv_bytes as f64 / 1e9,
            self.rows,
            OUTPUT_LIMIT / 1_000_000_000
        )
    }
}

/// The `[output] every` that brings `bytes`, written or kept at `every`,
/// under [`OUTPUT_LIMIT`], rounded up to a power of ten (a value a user would write).
pub fn every_to_fit(every: u64, bytes: u64) -> u64 {
    let suggest = (every as f64 * bytes as f64 / OUTPUT_LIMIT as f64).ceil() as u64;
    let power = 10u64.saturating_pow(suggest.max(1).ilog10());
    if power < suggest { power.saturating_mul(10) } else { power }
}

/// What a case produced, as `summary.json` reports it: the case, then the
/// library's record of the run.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    /// The case's name.
    pub name: String,
    /// The observable whose error against the reference is reported.
    pub error_observable: String,
    /// The scheme's name.
    pub scheme: &'static str,
    /// The step size.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub h: f64,
    /// The library's record of the run.
    #[serde(flatten)]
    pub record: Record,
    /// The method as it ran: its automatic gains chosen (`None` if it could not start).
    pub control: Option<cdyn::Control>,
    /// What the automatic gains were chosen from, and the largest rate × h.
    pub tuning: Option<cdyn::control::gains::Tuning>,
    /// Mean Newton iterations per step of the `projection` method.
    pub projection_iterations_per_step: Option<f64>,
    /// Mean iterations per step of RATTLE's position step (`scheme = "rattle"`).
    pub rattle_iterations_per_step: Option<f64>,
    /// Generalized-α's Newton iteration (`scheme = "generalized_alpha"`).
    pub newton: Option<NewtonReport>,
    /// Steps in which constraint rows were dropped as dependent
    /// (`dependent_rows = "tolerate"`): the most rows at once, how many
    /// steps, the first and last; `null` if none were.
    pub dependent_rows: Option<RankLoss>,
    /// `None` when the run finished; the error otherwise.
    pub error: Option<String>,
    /// Whether SIGINT or SIGTERM stopped the run (at `steps`, `t_final`).
    pub interrupted: bool,
    /// Positions at some samples, for the viewer (kept when the case has a drawing).
    #[serde(skip)]
    pub frames: Frames,
}

/// What generalized-α's Newton iteration did over a run.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct NewtonReport {
    /// Mean corrections per step.
    pub corrections_per_step: f64,
    /// The largest `|Δq|∞` a step left uncorrected: below the tolerance
    /// when it converges, what `newton_iterations` reached otherwise.
    pub newton_correction: f64,
}

/// What a run reports of its method besides the record.
#[derive(Default)]
struct Method {
    interrupted: bool,
    control: Option<cdyn::Control>,
    tuning: Option<cdyn::control::gains::Tuning>,
    projection_iterations_per_step: Option<f64>,
    rattle_iterations_per_step: Option<f64>,
    newton: Option<NewtonReport>,
    frames: Frames,
    rank_loss: Option<RankLoss>,
}

/// The series of a run that kept none (sweeps).
static NO_SERIES: Series = Series::new();

impl CaseResult {
    /// The summary of `case` from its record.
    fn new(case: &Case, (record, method): (Record, Method)) -> Self {
        CaseResult {
            name: case.name.clone(),
            error_observable: case.example.observables[0].clone(),
            scheme: case.settings.scheme.info().name,
            h: case.settings.h,
            error: record.error.as_ref().map(|e| {
                let entry = e.row().and_then(|r| case.row_entries.get(r)).map_or(String::new(), |e| format!(" ({e})"));
                format!("case {}: {e}{entry}", case.name)
            }),
            record,
            control: method.control,
            tuning: method.tuning,
            projection_iterations_per_step: method.projection_iterations_per_step,
            rattle_iterations_per_step: method.rattle_iterations_per_step,
            newton: method.newton,
            dependent_rows: method.rank_loss,
            interrupted: method.interrupted,
            frames: method.frames,
        }
    }

    /// Sampled time histories, for the figures (empty for sweeps).
    pub fn series(&self) -> &Series {
        self.record.series.as_ref().unwrap_or(&NO_SERIES)
    }
}

/// The columns of a run's samples: `t`, the observables, `phi`, `psi`, and
/// `err_<first observable>` when there is a reference (the CSV header).
pub fn columns(example: &Example) -> Vec<String> {
    let mut names = vec!["t".to_string()];
    names.extend(example.observables.iter().cloned());
    names.extend(["phi".to_string(), "psi".to_string()]);
    if example.reference.is_some() {
        names.push(format!("err_{}", example.observables[0].to_lowercase()));
    }
    names
}

/// The values of one sample in the order of [`columns`]: the one source of
/// both the CSV rows and the rows kept in memory (Python), so the two agree bit for bit.
pub fn row_values<'s>(s: &'s Sample<'_>) -> impl Iterator<Item = f64> + 's {
    let t = cdyn::error::tidy_time(s.t);
    std::iter::once(t).chain(s.observables.iter().copied()).chain([s.measures.phi, s.measures.psi]).chain(s.error)
}

/// Writes each sample as a CSV row of [`row_values`] under the header [`columns`].
struct CsvRows<'w, W: Write> {
    out: &'w mut W,
}

impl<'w, W: Write> CsvRows<'w, W> {
    /// Writes the header row for `example` and returns the writer of the rows.
    fn start(out: &'w mut W, example: &Example) -> std::io::Result<Self> {
        writeln!(out, "{}", columns(example).join(","))?;
        Ok(CsvRows { out })
    }
}

impl<W: Write> Sink for CsvRows<'_, W> {
    type Error = std::io::Error;
    fn sample(&mut self, s: &Sample<'_>) -> std::io::Result<()> {
        for (i, x) in row_values(s).enumerate() {
            if i > 0 {
                write!(self.out, ",")?;
            }
            write!(self.out, "{x:e}")?;
        }
        writeln!(self.out)
    }
}

/// The samples of a run kept in memory: the rows the CSV would hold, and
/// the coordinates `q` and velocities `v` at each sample.
#[derive(Debug, Clone, Default)]
pub struct Rows {
    /// Column names ([`columns`]).
    pub columns: Vec<String>,
    /// The rows one after another, `columns.len()` values each ([`row_values`]).
    pub values: Vec<f64>,
    /// `q` at each sample, one after another.
    pub q: Vec<f64>,
    /// `v` at each sample, one after another.
    pub v: Vec<f64>,
    /// The time of each sample as the integrator reached it (`t` in the
    /// rows is written as people write it: 0.3, not 0.30000000000000004).
    pub t_exact: Vec<f64>,
}

impl Sink for &mut Rows {
    type Error = std::convert::Infallible;
    fn sample(&mut self, s: &Sample<'_>) -> Result<(), Self::Error> {
        self.values.extend(row_values(s));
        Ok(())
    }
}

/// Runs `case` keeping every sample in memory (no files, no progress bar):
/// the Python package's run. `stop` is asked every few thousand steps
/// whether to stop (Ctrl-C in Python); a stopped run is marked interrupted.
pub fn run_case_in_memory(case: &Case, stop: &dyn Fn() -> bool) -> (CaseResult, Rows) {
    let mut rows = Rows { columns: columns(&case.example), ..Rows::default() };
    let mut states = States::default();
    let recorder = Recorder::example(&case.example).keep_series(false).sink(&mut rows);
    let Ok(record) = simulate(case, recorder, Watch::Asking(stop), Some(&mut states));
    (rows.t_exact, rows.q, rows.v) = (states.t, states.q, states.v);
    (CaseResult::new(case, record), rows)
}

/// Runs `case`, writing `dir/<name>.csv` (under a temporary name until it
/// is complete). A simulation error is recorded in the result (the CSV keeps
/// every row before it); so is an interrupt (SIGINT, SIGTERM), which stops
/// the run after the step it is in. I/O errors are returned, and leave no CSV.
pub fn run_case(case: &Case, dir: &Path, progress: &ProgressBar) -> Result<CaseResult> {
    let path = dir.join(format!("{}.csv", case.name));
    let mut file = AtomicFile::create(&path)?;
    let record = CsvRows::start(file.writer(), &case.example).and_then(|rows| {
        let recorder = Recorder::example(&case.example).keep_series(true).sink(rows);
        simulate(case, recorder, Watch::Interrupts(progress), None)
    });
    let record = record.with_context(|| format!("cannot write {}", path.display()))?;
    file.commit()?;
    Ok(CaseResult::new(case, record))
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
        Watch::Interrupts(_) if ex.drawing.is_some() || ex.sketch.is_some() => Frames::of(ex.model.n()),
        _ => Frames::none(),
    };
    match Simulation::new(&ex.model, case.settings, &ex.q0, &ex.v0) {
        Ok(mut sim) => {
            let (record, interrupted) = drive(&mut sim, recorder, case.t_end, case.every, watch, &mut frames, states)?;
            let method = Method {
                interrupted,
                control: Some(sim.settings().control),
                tuning: Some(*sim.tuning()),
                projection_iterations_per_step: sim
                    .settings()
                    .control
                    .projection
                    .is_some()
                    .then(|| sim.projection_iterations() as f64 / sim.steps().max(1) as f64),
                rattle_iterations_per_step: (case.settings.scheme == cdyn::Scheme::Rattle)
                    .then(|| sim.rattle_iterations() as f64 / sim.steps().max(1) as f64),
                newton: (case.settings.scheme == cdyn::Scheme::GeneralizedAlpha).then(|| NewtonReport {
                    corrections_per_step: sim.newton_iterations() as f64 / sim.steps().max(1) as f64,
                    newton_correction: sim.newton_correction(),
                }),
                frames,
                rank_loss: sim.rank_loss().copied(),
            };
            Ok((record, method))
        }
        Err(e) => Ok((recorder.abandon(e), Method::default())),
    }
}

/// [`Recorder::run`], step by step so that an interrupt stops the run
/// between two steps: the state it stopped at is sampled too (a complete
/// CSV row), and the record says it was interrupted. `frames` is offered
/// every sample, and the state it ends at.
fn drive<S: System, K: Sink>(
    sim: &mut Stepper<S>,
    mut recorder: Recorder<'_, K>,
    t_end: f64,
    every: u64,
    watch: Watch<'_>,
    frames: &mut Frames,
    mut states: Option<&mut States>,
) -> Result<(Record, bool), K::Error> {
    let (error, interrupted) = drive_frames(sim, &mut recorder, t_end, every, watch, frames, &mut states)?;
    frames.end(sim.t(), sim.q());
    let mut record = recorder.finish(sim);
    if error.is_some() {
        record.error = error;
    }
    Ok((record, interrupted))
}

/// [`drive`] until the run ends; returns the simulation's error, if any, and whether it was interrupted.
fn drive_frames<S: System, K: Sink>(
    sim: &mut Stepper<S>,
    recorder: &mut Recorder<'_, K>,
    t_end: f64,
    every: u64,
    watch: Watch<'_>,
    frames: &mut Frames,
    states: &mut Option<&mut States>,
) -> Result<(Option<cdyn::Error>, bool), K::Error> {
    let steps = match steps_to(t_end, sim.settings().h) {
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
fn sample<S: System, K: Sink>(
    recorder: &mut Recorder<'_, K>,
    sim: &mut Stepper<S>,
    frames: &mut Frames,
    states: &mut Option<&mut States>,
) -> Result<(), K::Error> {
    recorder.sample(sim)?;
    frames.push(sim.t(), sim.q());
    if let Some(s) = states.as_deref_mut() {
        s.t.push(sim.t());
        s.q.extend_from_slice(sim.q());
        s.v.extend_from_slice(sim.v());
    }
    Ok(())
}
