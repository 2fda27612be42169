//! `cdyn bench`: the cost of a step, into bench.json.

use super::output_dir;
use anyhow::Result;
use cdyn_cli::io::{output, terminal::print};
use cdyn_cli::study::bench;
use std::path::Path;

/// Measures, writes `out/bench.json` (with `realtime`, only the real-time
/// figures, into `out/realtime.json`) and prints its table.
pub fn bench(out: &Path, light: bool, realtime: bool) -> Result<()> {
    output_dir(out)?;
    let (path, json, table) = if realtime {
        let report = bench::run_realtime(light)?;
        (out.join("realtime.json"), serde_json::to_string_pretty(&report)?, bench::realtime_table(&report))
    } else {
        let report = bench::run(light)?;
        (out.join("bench.json"), serde_json::to_string_pretty(&report)?, bench::table(&report))
    };
    output::write(&path, (json + "\n").as_bytes())?;
    print(&table)?;
    print(&format!("wrote {}\n", path.display()))
}
