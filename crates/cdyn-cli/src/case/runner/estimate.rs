//! What a run of some cases is expected to write and keep, before it
//! starts, and the refusal of one too large.

use super::Case;
use anyhow::Result;
use cdyn::simulate::steps_to;

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
