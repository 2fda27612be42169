//! `cdyn run`: one scenario file.

use super::{CaseArgs, Ended, ended, output_dir};
use anyhow::Result;
use cdyn_cli::case::{runner, scenario};
use cdyn_cli::io::{interrupt, output, terminal::print};
use cdyn_cli::render::{report, view3d};

/// Runs the scenario of `args` into its output directory.
pub fn run(args: CaseArgs) -> Result<Ended> {
    let CaseArgs { scenario, out, force, viewer } = args;
    let parsed = scenario::load(&scenario)?;
    parsed.refuse_sweep(&scenario, "run")?;
    let mut case = parsed.case(&scenario)?;
    case.check().map_err(|e| anyhow::anyhow!("{}: {e}", scenario.display()))?;
    viewer.prepare(std::slice::from_mut(&mut case))?;
    runner::Estimate::of(std::slice::from_ref(&case)).check(&scenario.display().to_string(), case.every, force)?;
    for note in &case.notes {
        print(&format!("note: {note}\n"))?;
    }
    if let Some(a) = &case.assembly {
        print(&format!("{}\n", report::assembly_line(a)))?;
    }
    output_dir(&out)?;
    output::clear(&out, &report::file_names(std::slice::from_ref(&case), report::RUN_FIGURES))?;
    interrupt::install();
    let results = report::run_cases(std::slice::from_ref(&case), &out)?;
    let extra = serde_json::json!({
        "scenario": scenario.display().to_string(),
        "assembly": case.assembly.as_ref().map(report::assembly_json),
    });
    report::write_summary(&out, &results, extra)?;
    report::write_figures(&out, &results[0].name, &results, report::RUN_FIGURES)?;
    if let Some(sketch) = &case.example.sketch {
        view3d::write(&out, &results[0].name, sketch, &results[0].frames)?;
    }
    viewer.write(&out, &results[0].name, std::slice::from_ref(&case), &results)?;
    if let Some(limits) = &results[0].limits {
        print(&format!("{}\n", limits.line()))?;
    }
    print(&report::table(&results))?;
    print(&format!("wrote {}\n", out.display()))?;
    ended(&results, &out)
}
