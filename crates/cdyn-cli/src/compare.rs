//! `cdyn compare`: one model under every stabilization method of the
//! paper's test, with the scenario's gains or target rates, then the
//! `robust` preset and exact `projection`.

use crate::report;
use crate::runner::{Case, CaseResult};
use crate::scenario::Scenario;
use anyhow::Result;
use cdyn::control::methods::compare_cases;
use serde_json::json;
use std::path::Path;

/// Every method as a case of the scenario's model, integrator and output.
pub fn cases(scenario: &Scenario, path: &Path) -> Result<Vec<Case>> {
    let file = path.display().to_string();
    let base = scenario.case(path)?;
    let gains = scenario
        .method
        .clone()
        .unwrap_or_default()
        .gains(base.settings.h)
        .map_err(|e| anyhow::anyhow!("{file}: [method] {e}"))?;
    // A model without constraints has nothing for geometric control to do.
    let methods = compare_cases(&gains, base.example.model.m() > 0);
    methods
        .into_iter()
        .map(|(name, control)| {
            let mut case = scenario.case(path)?;
            case.name = name.to_string();
            case.settings.control = control;
            case.check().map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
            Ok(case)
        })
        .collect()
}

/// Runs the cases into `dir` (until one is interrupted) with the summary, figures and gains used.
pub fn run(cases: &[Case], path: &Path, dir: &Path) -> Result<Vec<CaseResult>> {
    let results = report::run_cases(cases, dir)?;
    let methods: Vec<_> =
        cases.iter().map(|c| json!({ "name": c.name, "control": format!("{:?}", c.settings.control) })).collect();
    let extra = json!({
        "scenario": path.display().to_string(),
        "methods": methods,
        "assembly": cases.first().and_then(|c| c.assembly.as_ref()).map(report::assembly_json),
    });
    report::write_summary(dir, &results, extra)?;
    let stem = path.file_stem().map_or("compare".into(), |s| s.to_string_lossy().into_owned());
    report::write_figures(dir, &stem, &results, report::RUN_FIGURES)?;
    Ok(results)
}
