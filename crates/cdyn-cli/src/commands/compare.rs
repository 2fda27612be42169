//! `cdyn compare`: one model under every method.

use super::{CaseArgs, Ended, ended, output_dir};
use anyhow::Result;
use cdyn_cli::case::{runner, scenario};
use cdyn_cli::io::{interrupt, output, terminal::print};
use cdyn_cli::render::report;
use cdyn_cli::study::compare;

/// Runs the scenario of `args` under every method into its output directory.
pub fn compare(args: CaseArgs) -> Result<Ended> {
    let CaseArgs { scenario, out, force, viewer } = args;
    let parsed = scenario::load(&scenario)?;
    parsed.refuse_sweep(&scenario, "compare")?;
    let mut cases = compare::cases(&parsed, &scenario)?;
    viewer.prepare(&mut cases)?;
    let every = cases.first().map_or(1, |c| c.every);
    runner::Estimate::of(&cases).check(&scenario.display().to_string(), every, force)?;
    output_dir(&out)?;
    output::clear(&out, &report::file_names(&cases, report::RUN_FIGURES))?;
    interrupt::install();
    let results = report::compare(&cases, &scenario, &out)?;
    let stem = scenario.file_stem().map_or("compare".into(), |s| s.to_string_lossy().into_owned());
    viewer.write(&out, &stem, &cases, &results)?;
    print(&report::table(&results))?;
    print(&format!("wrote {}\n", out.display()))?;
    ended(&results, &out)
}
