//! `cdyn bench`: the cost of a step, into bench.json.

use super::output_dir;
use anyhow::Result;
use cdyn_cli::io::{output, terminal::print};
use cdyn_cli::study::bench;
use std::path::Path;

/// Measures, writes `out/bench.json` and prints its table.
pub fn bench(out: &Path, light: bool) -> Result<()> {
    output_dir(out)?;
    let report = bench::run(light)?;
    let path = out.join("bench.json");
    output::write(&path, (serde_json::to_string_pretty(&report)? + "\n").as_bytes())?;
    print(&bench::table(&report))?;
    print(&format!("wrote {}\n", path.display()))
}
