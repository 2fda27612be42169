//! A run's samples as rows: the columns, the values of one sample, and
//! the two sinks that take them (a CSV file, memory).

use anyhow::Result;
use cdyn::models::Example;
use cdyn::record::{Sample, Sink};
use std::io::Write;

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
pub(super) struct CsvRows<'w, W: Write> {
    out: &'w mut W,
}

impl<'w, W: Write> CsvRows<'w, W> {
    /// Writes the header row for `example` and returns the writer of the rows.
    pub(super) fn start(out: &'w mut W, example: &Example) -> std::io::Result<Self> {
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
