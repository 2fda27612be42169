//! `cdyn paper`: the paper's Example 1, every case.

use super::{Ended, ended, output_dir};
use anyhow::Result;
use cdyn_cli::io::{interrupt, output, terminal::print};
use cdyn_cli::render::report;
use cdyn_cli::study::paper;
use std::path::Path;

/// Runs the paper's cases into `out` and prints its table.
pub fn paper(out: &Path) -> Result<Ended> {
    output_dir(out)?;
    let cases = paper::cases()?;
    output::clear(out, &report::file_names(&cases, report::PAPER_FIGURES))?;
    interrupt::install();
    let results = report::paper(&cases, out)?;
    print(&report::table(&results))?;
    print(&format!("wrote {}\n", out.display()))?;
    ended(&results, out)
}
