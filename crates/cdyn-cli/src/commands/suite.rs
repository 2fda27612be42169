//! `cdyn suite`: every method on many models, with verdicts.

use super::output_dir;
use anyhow::Result;
use cdyn_cli::io::terminal::print;
use cdyn_cli::render::suite_plot;
use cdyn_cli::study::suite;
use std::path::{Path, PathBuf};

/// Runs the suite (the shipped models and `scenarios`), writes suite.json and suite.png into `out`.
pub fn suite(scenarios: &[PathBuf], out: &Path, light: bool) -> Result<()> {
    let start = std::time::Instant::now();
    let result = suite::run(scenarios, light)?;
    for (model, seconds) in &result.seconds {
        print(&format!("  {model}: {seconds:.1} s\n"))?;
    }
    print(&format!("suite: {} models in {:.1} s\n", result.seconds.len(), start.elapsed().as_secs_f64()))?;
    output_dir(out)?;
    suite_plot::write(&result, out)?;
    suite::write(&result, out)?;
    print(&suite::table(&result))?;
    print(&suite::summary(&result))?;
    print(&format!("wrote {}\n", out.join("suite.json").display()))
}
