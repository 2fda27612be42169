//! What a run hands out as it goes: each [`Sample`] to a [`Sink`] (a CSV
//! writer, say), so that a run which fails keeps what it recorded.

use crate::dynamics::diagnostics::Measures;
use std::convert::Infallible;

/// One sample of a run, as a [`Sink`] sees it.
#[derive(Debug, Clone, Copy)]
pub struct Sample<'a> {
    /// Steps taken.
    pub step: u64,
    /// Time.
    pub t: f64,
    /// The observables: an [`Example`](crate::models::Example)'s named quantities, or the coordinates `q`.
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
