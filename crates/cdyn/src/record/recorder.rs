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

use crate::dynamics::diagnostics::Measures;
use crate::error::Error;
use crate::models::Example;
use crate::simulate::Stepper;
use crate::simulate::system::System;
use std::convert::Infallible;

/// One sample of a run, as a [`Sink`] sees it.
#[derive(Debug, Clone, Copy)]
pub struct Sample<'a> {
    /// Steps taken.
    pub step: u64,
    /// Time.
    pub t: f64,
    /// The observables: an [`Example`]'s named quantities, or the coordinates `q`.
    pub observables: &'a [f64],
    /// Violations `Φ`, `Φ̇`, `Ψ` and the coupling measure.
    pub measures: Measures,
    /// Error of the first observable against the reference, when there is one.
    pub error: Option<f64>,
}

/// Where samples go as they are taken.
///
/// Any closure `FnMut(&Sample) -> Result<(), E>` is a sink; an error stops the run.
pub trait Sink {
    /// What taking in a sample can fail with (I/O, for a writer).
    type Error;
    /// Takes in one sample.
    fn sample(&mut self, sample: &Sample<'_>) -> Result<(), Self::Error>;
}

impl<E, F: FnMut(&Sample<'_>) -> Result<(), E>> Sink for F {
    type Error = E;
    fn sample(&mut self, sample: &Sample<'_>) -> Result<(), E> {
        self(sample)
    }
}

/// A sink that drops every sample: only the statistics are kept.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoSink;

impl Sink for NoSink {
    type Error = Infallible;
    fn sample(&mut self, _: &Sample<'_>) -> Result<(), Infallible> {
        Ok(())
    }
}

/// Most buckets a [`Series`] keeps: about three per pixel of a 1200-pixel-wide figure.
pub const SERIES_BUCKETS: usize = 4096;

/// Sampled time histories, for figures, of a size that does not grow with
/// the length of the run.
///
/// Up to [`SERIES_BUCKETS`] samples are kept as they are (one entry each).
/// Beyond that, consecutive samples are gathered into at most that many
/// buckets of equal count (the count doubles whenever the buckets run out),
/// and a bucket of more than one sample keeps two entries: at its first and
/// its last time, the smallest and largest value of each quantity, in the
/// order they occurred. A spike therefore stays in the figure however long
/// the run; only its position within its bucket (less than a pixel) is lost.
/// The statistics of a [`Record`] are kept exactly, from every sample.
///
/// The four vectors hold the entries of the complete buckets; a partly
/// filled last bucket joins them when the recording ends.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Times.
    pub t: Vec<f64>,
    /// The constraint value of largest magnitude, with its sign.
    pub phi: Vec<f64>,
    /// The energy constraint `Ψ`.
    pub psi: Vec<f64>,
    /// Error of the first observable against the reference; empty without one.
    pub error: Vec<f64>,
    /// The complete buckets, the vectors' source when buckets merge.
    buckets: Vec<Bucket>,
    /// The bucket being filled.
    open: Option<Bucket>,
    /// Samples per bucket (a power of two).
    width: u64,
    /// Samples taken so far, which orders the extremes within a bucket.
    samples: u64,
    /// Whether any sample had an error (then every entry has one, NaN where missing).
    has_error: bool,
}

/// The smallest and largest value of one quantity over a bucket, with the
/// sample index of each (to draw them in the order they occurred).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Extent {
    min: f64,
    min_at: u64,
    max: f64,
    max_at: u64,
}

impl Extent {
    /// The extent of no value yet.
    const EMPTY: Extent = Extent { min: f64::NAN, min_at: 0, max: f64::NAN, max_at: 0 };

    /// Takes in `v`, sample `at`; NaN only where nothing else is.
    fn add(&mut self, v: f64, at: u64) {
        if v < self.min || self.min.is_nan() {
            (self.min, self.min_at) = (v, at);
        }
        if v > self.max || self.max.is_nan() {
            (self.max, self.max_at) = (v, at);
        }
    }

    /// The extent of `self` followed by `later`.
    fn merge(self, later: Extent) -> Extent {
        let mut e = self;
        e.add(later.min, later.min_at);
        e.add(later.max, later.max_at);
        e
    }

    /// The two values in the order they occurred.
    fn ordered(&self) -> [f64; 2] {
        if self.max_at < self.min_at { [self.max, self.min] } else { [self.min, self.max] }
    }
}

/// Consecutive samples gathered: their first and last time and the extent of each quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bucket {
    count: u64,
    t: [f64; 2],
    /// Φ, Ψ and the error.
    values: [Extent; 3],
}

impl Bucket {
    /// `later` appended to `self`.
    fn merge(self, later: Bucket) -> Bucket {
        Bucket {
            count: self.count + later.count,
            t: [self.t[0], later.t[1]],
            values: [0, 1, 2].map(|i| self.values[i].merge(later.values[i])),
        }
    }
}

impl Series {
    /// An empty series.
    pub const fn new() -> Self {
        Series {
            t: Vec::new(),
            phi: Vec::new(),
            psi: Vec::new(),
            error: Vec::new(),
            buckets: Vec::new(),
            open: None,
            width: 1,
            samples: 0,
            has_error: false,
        }
    }

    /// Takes in one sample.
    pub fn push(&mut self, t: f64, phi: f64, psi: f64, error: Option<f64>) {
        let at = self.samples;
        self.samples += 1;
        self.has_error |= error.is_some();
        let width = self.width.max(1);
        let bucket = self.open.get_or_insert(Bucket { count: 0, t: [t, t], values: [Extent::EMPTY; 3] });
        bucket.count += 1;
        bucket.t[1] = t;
        for (extent, v) in bucket.values.iter_mut().zip([Some(phi), Some(psi), error]) {
            if let Some(v) = v {
                extent.add(v, at);
            }
        }
        if bucket.count >= width {
            let bucket = *bucket;
            self.open = None;
            self.close(bucket);
        }
    }

    /// Samples taken in.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Adds a complete bucket; when the buckets run out, merges them in pairs.
    fn close(&mut self, bucket: Bucket) {
        self.buckets.push(bucket);
        self.emit(bucket);
        if self.buckets.len() >= SERIES_BUCKETS {
            let merged: Vec<Bucket> =
                self.buckets.chunks(2).map(|p| p.iter().copied().reduce(Bucket::merge).unwrap_or(p[0])).collect();
            self.width = self.width.max(1) * 2;
            self.buckets.clear();
            for v in [&mut self.t, &mut self.phi, &mut self.psi, &mut self.error] {
                v.clear();
            }
            for b in merged {
                self.buckets.push(b);
                self.emit(b);
            }
        }
    }

    /// Appends the entries of `bucket` to the vectors.
    fn emit(&mut self, b: Bucket) {
        let n = if b.count > 1 { 2 } else { 1 };
        self.t.extend(&b.t[..n]);
        self.phi.extend(&b.values[0].ordered()[..n]);
        self.psi.extend(&b.values[1].ordered()[..n]);
        if self.has_error {
            // Entries from before the first error get none (NaN: not drawn).
            self.error.resize(self.t.len() - n, f64::NAN);
            self.error.extend(&b.values[2].ordered()[..n]);
        }
    }

    /// Ends the recording: the partly filled last bucket joins the vectors.
    pub fn finish(&mut self) {
        if let Some(b) = self.open.take() {
            self.buckets.push(b);
            self.emit(b);
        }
    }
}

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
                (example.observe)(q, v, values);
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
            for j in 0..self.record.momenta.len() {
                let p = sim.momentum(j);
                let m = &mut self.record.momenta[j];
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
