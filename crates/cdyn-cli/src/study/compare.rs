//! `cdyn compare`: one model under every stabilization method of the
//! paper's test, with the scenario's gains or target rates, then the
//! `robust` preset and exact `projection`. RATTLE holds the constraints
//! itself and takes no control law in the right-hand side: with it, the
//! comparison is no control against `projection`.

use crate::case::runner::Case;
use crate::case::scenario::Scenario;
use anyhow::Result;
use cdyn::control::methods::compare_cases;
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
    // RATTLE and generalized-α take no right-hand-side control: none and projection.
    let steps_model = base.settings.scheme.steps_model();
    methods
        .into_iter()
        .filter(|(_, control)| !(steps_model && control.is_active()))
        .map(|(name, control)| {
            let mut case = scenario.case(path)?;
            case.name = name.to_string();
            case.settings.control = control;
            case.check().map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
            Ok(case)
        })
        .collect()
}
