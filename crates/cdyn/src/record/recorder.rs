//! Recording a run: the statistics a summary reports (largest violations
//! and error, steps, evaluations, end state), optionally the sampled time
//! series for figures, and each sample handed to a [`Sink`] (a CSV writer,
//! say) as the run goes, so that a run which fails keeps what it recorded.
//!
//! A sample is taken at the start, after every `k`-th step and after the
//! last step (see [`Stepper::run`]).
//!
//! ```
//! use cdyn::models::{PendulumParams, cartesian_pendulum};
//! use cdyn::record::{Recorder, Sample};
//! use cdyn::{Control, Scheme, Settings, Simulation};
//!
//! let example = cartesian_pendulum(PendulumParams::default())?;
//! let settings = Settings::new(Scheme::RungeKutta4, 0.01, Control::none());
//! let mut sim = Simulation::new(&example.model, settings, &example.q0, &example.v0)?;
//! let mut rows = Vec::new();
//! let record = Recorder::example(&example)
//!     .keep_series(true)
//!     .sink(|s: &Sample<'_>| -> Result<(), std::convert::Infallible> {
//!         rows.push((s.t, s.observables[0], s.measures.phi));
//!         Ok(())
//!     })
//!     .run(&mut sim, 1.0, 10)?;
//! assert!(record.error.is_none());
//! assert_eq!(record.steps, 100);
//! assert_eq!(rows.len(), 11); // t = 0, 0.1, …, 1
//! assert!(record.max_abs_phi < 1e-6 && record.max_abs_error.unwrap() < 1e-6);
//! assert_eq!(record.series.unwrap().t.len(), 11);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::sample::{NoSink, Sample, Sink};
use super::series::Series;
use crate::error::Error;
use crate::models::Example;
use crate::simulate::Stepper;
use crate::simulate::system::System;

/// What a recorded run produced. With the `serde` feature it serializes
/// under the names summaries have always used (the paper's error is in `X`:
/// `max_abs_err_x`, `err_x_final`, `rhs_evals`), infinities and NaN as
/// strings (`cdyn::json_float`, with the `serde` feature); the series and the error are left to
/// the caller.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Record {
    /// Largest `|Φ|` over the samples.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub max_abs_phi: f64,
    /// Largest `|Φ̇|` over the samples: the velocity-level violation, and
    /// for nonholonomic rows (whose `Φ` is zero) the only one.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub max_abs_phi_dot: f64,
    /// Largest `|Ψ|` over the samples.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub max_abs_psi: f64,
    /// Largest error of the first observable against the reference; `None` without one.
    #[cfg_attr(feature = "serde", serde(rename = "max_abs_err_x", serialize_with = "crate::json_float::serialize"))]
    pub max_abs_error: Option<f64>,
    /// That error at the last sample; `None` without a reference or a sample.
    #[cfg_attr(feature = "serde", serde(rename = "err_x_final", serialize_with = "crate::json_float::serialize"))]
    pub final_error: Option<f64>,
    /// Largest coupling measure `max_i |Y_ci|` over the samples.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub max_abs_coupling: f64,
    /// Steps taken.
    pub steps: u64,
    /// Time reached.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub t_final: f64,
    /// Right-hand-side evaluations.
    #[cfg_attr(feature = "serde", serde(rename = "rhs_evals"))]
    pub evaluations: u64,
    /// Positions at the end (after a failure: where the run stopped).
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub q_end: Vec<f64>,
    /// Velocities at the end.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub v_end: Vec<f64>,
    /// The sampled series, when asked for with [`Recorder::keep_series`].
    #[cfg_attr(feature = "serde", serde(skip))]
    pub series: Option<Series>,
    /// Why the run stopped early; `None` when it reached the end.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub error: Option<Error>,
    /// The momenta the system keeps, and the declared ones it breaks, over the samples.
    pub momenta: Vec<MomentumRecord>,
}

/// A momentum over a run: its value at the first and last sample and its
/// largest drift from the first.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MomentumRecord {
    /// Its name ("linear momentum x").
    pub name: String,
    /// Whether the system keeps it; a declared one it breaks is measured only.
    pub kept: bool,
    /// What breaks a declared one.
    pub reason: Option<String>,
    /// Linear in the state, so kept to round-off by every explicit scheme.
    pub linear: bool,
    /// `|e|_M |v₀|_M`, the size its round-off is judged against.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub scale: f64,
    /// At the first sample.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub initial: f64,
    /// At the last sample.
    #[cfg_attr(feature = "serde", serde(rename = "final", serialize_with = "crate::json_float::serialize"))]
    pub last: f64,
    /// Largest `|p − p₀|` over the samples.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::json_float::serialize"))]
    pub max_drift: f64,
}

/// What a sample observes besides the violations.
enum Observed<'a> {
    /// The coordinates `q`; no reference.
    Coordinates,
    /// An example's observables, and its reference when it has one.
    Example {
        example: &'a Example,
        /// The observables of the current state.
        values: Vec<f64>,
        /// The reference state and its observables at the current time.
        reference: Option<(Vec<f64>, Vec<f64>, Vec<f64>)>,
    },
}

/// Gathers a [`Record`] from the samples of a run and hands each to a [`Sink`].
///
/// Buffers are allocated once, so a sample allocates nothing beyond
/// growing the series when they are kept.
pub struct Recorder<'a, K: Sink = NoSink> {
    observed: Observed<'a>,
    sink: K,
    record: Record,
}

impl Recorder<'static> {
    /// Records a bare model: the observables are the coordinates, there is no reference.
    pub fn coordinates() -> Self {
        Recorder { observed: Observed::Coordinates, sink: NoSink, record: empty_record(false) }
    }
}

impl<'a> Recorder<'a> {
    /// Records a run of `example`'s model: its observables and, when it has
    /// a reference solution, the error of the first observable against it.
    pub fn example(example: &'a Example) -> Self {
        let n = example.model.n();
        let count = example.observables.len();
        let reference = example.reference.as_ref().map(|_| (vec![0.0; n], vec![0.0; n], vec![0.0; count]));
        let has_reference = reference.is_some();
        Recorder {
            observed: Observed::Example { example, values: vec![0.0; count], reference },
            sink: NoSink,
            record: empty_record(has_reference),
        }
    }
}

/// A record before any sample: zeros, and a zero error when there is a reference.
fn empty_record(has_reference: bool) -> Record {
    Record {
        max_abs_phi: 0.0,
        max_abs_phi_dot: 0.0,
        max_abs_psi: 0.0,
        max_abs_coupling: 0.0,
        max_abs_error: has_reference.then_some(0.0),
        final_error: None,
        steps: 0,
        t_final: 0.0,
        evaluations: 0,
        q_end: Vec::new(),
        v_end: Vec::new(),
        series: None,
        error: None,
        momenta: Vec::new(),
    }
}

/// Why [`Recorder::run`] stopped early: the simulation (recorded) or the sink (returned).
enum Stop<E> {
    Simulation(Error),
    Sink(E),
}

impl<E> From<Error> for Stop<E> {
    fn from(e: Error) -> Self {
        Stop::Simulation(e)
    }
}

impl<'a, K: Sink> Recorder<'a, K> {
    /// Whether to keep the sampled series (figures need them; sweeps do not).
    pub fn keep_series(mut self, keep: bool) -> Self {
        self.record.series = keep.then(Series::default);
        self
    }

    /// Hands every sample to `sink` as well.
    pub fn sink<L: Sink>(self, sink: L) -> Recorder<'a, L> {
        Recorder { observed: self.observed, sink, record: self.record }
    }

    /// Runs `sim` until `t_end`, sampling at the start, after every
    /// `every`-th step and after the last. An error of the simulation stops
    /// the run and is kept in [`Record::error`], with everything sampled
    /// before it; an error of the sink is returned.
    pub fn run<S: System>(mut self, sim: &mut Stepper<S>, t_end: f64, every: u64) -> Result<Record, K::Error> {
        let outcome = sim.run(t_end, every, |sim| self.sample(sim).map_err(Stop::Sink));
        let error = match outcome {
            Ok(()) => None,
            Err(Stop::Simulation(e)) => Some(e),
            Err(Stop::Sink(e)) => return Err(e),
        };
        Ok(Record { error, ..self.finish(sim) })
    }

    /// Samples the current state of `sim`: updates the statistics and
    /// series and hands the sample to the sink.
    pub fn sample<S: System>(&mut self, sim: &mut Stepper<S>) -> Result<(), K::Error> {
        self.track_momenta(sim);
        let measures = sim.measure();
        let (t, q, v) = (sim.t(), sim.q(), sim.v());
        let (observables, error) = match &mut self.observed {
            Observed::Coordinates => (q, None),
            Observed::Example { example, values, reference } => {
                (example.observe)(t, q, v, values);
                let error =
                    reference.as_mut().and_then(|(qr, vr, at_ref)| example.error_of(values[0], t, qr, vr, at_ref));
                (&values[..], error)
            }
        };
        let r = &mut self.record;
        r.max_abs_phi = r.max_abs_phi.max(measures.phi.abs());
        r.max_abs_phi_dot = r.max_abs_phi_dot.max(measures.phi_dot);
        r.max_abs_psi = r.max_abs_psi.max(measures.psi.abs());
        r.max_abs_coupling = r.max_abs_coupling.max(measures.coupling);
        if let Some(e) = error {
            r.max_abs_error = Some(r.max_abs_error.unwrap_or(0.0).max(e.abs()));
            r.final_error = Some(e);
        }
        if let Some(s) = &mut r.series {
            s.push(t, measures.phi, measures.psi, error);
        }
        self.sink.sample(&Sample { step: sim.steps(), t, observables, measures, error })
    }

    /// The momenta of the system at the current sample: set up at the first.
    fn track_momenta<S: System>(&mut self, sim: &mut Stepper<S>) {
        if sim.steps() == 0 && self.record.momenta.is_empty() {
            let symmetries = sim.symmetries();
            let kept = symmetries.kept.iter().map(|m| MomentumRecord {
                name: m.name.clone(),
                kept: true,
                reason: None,
                linear: m.linear,
                scale: m.scale,
                initial: 0.0,
                last: 0.0,
                max_drift: 0.0,
            });
            let broken = symmetries.broken.iter().map(|b| MomentumRecord {
                name: b.name.clone(),
                kept: false,
                reason: Some(b.reason.clone()),
                linear: false,
                scale: 0.0,
                initial: 0.0,
                last: 0.0,
                max_drift: 0.0,
            });
            let momenta: Vec<MomentumRecord> = kept.chain(broken).collect();
            self.record.momenta = momenta;
            for j in 0..self.record.momenta.len() {
                let p = sim.momentum(j);
                (self.record.momenta[j].initial, self.record.momenta[j].last) = (p, p);
            }
        } else {
            for m in &mut self.record.momenta {
                // A run with stops changes its model between steps
                // (`crate::stops`), and with it the momenta it keeps: each
                // is found by its name, one no longer there left as it was.
                let symmetries = sim.symmetries();
                let names = symmetries.kept.iter().map(|k| &k.name).chain(symmetries.broken.iter().map(|b| &b.name));
                let Some(j) = names.into_iter().position(|name| *name == m.name) else { continue };
                let p = sim.momentum(j);
                m.last = p;
                m.max_drift = m.max_drift.max((p - m.initial).abs());
            }
        }
    }

    /// The record so far, with the end state of `sim`.
    pub fn finish<S: System>(mut self, sim: &Stepper<S>) -> Record {
        if let Some(s) = &mut self.record.series {
            s.finish();
        }
        Record {
            steps: sim.steps(),
            // As people write it (0.3, not 0.30000000000000004).
            t_final: crate::error::tidy_time(sim.t()),
            evaluations: sim.evaluations(),
            q_end: sim.q().to_vec(),
            v_end: sim.v().to_vec(),
            ..self.record
        }
    }

    /// The record so far, without an end state: for a run that could not
    /// start, with the reason.
    pub fn abandon(mut self, error: Error) -> Record {
        if let Some(s) = &mut self.record.series {
            s.finish();
        }
        Record { error: Some(error), ..self.record }
    }
}
