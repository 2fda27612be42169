//! The stiff flyball governor (IFToMM A05) at the explicit scheme's steps
//! and at generalized-α's.

use super::timed_runs;
use crate::case::scenario;
use anyhow::{Result, anyhow};
use cdyn::{Control, Scheme, Settings, Simulation};
use serde::Serialize;
use std::path::Path;

/// One scheme and step on the flyball governor, no control.
#[derive(Debug, Serialize)]
pub struct FlyballRun {
    /// The scheme's name.
    pub scheme: &'static str,
    /// Step size.
    pub h: f64,
    /// Steps timed (from the start, set-up untimed).
    pub steps: u64,
    /// Time per step.
    pub us_per_step: f64,
    /// Wall-clock milliseconds per simulated second.
    pub ms_per_simulated_second: f64,
    /// Allocations per step (0 expected).
    pub allocations_per_step: f64,
}

/// The schemes and steps timed: RK-4 at the step of the IFToMM files and
/// at about its largest stable one, ABM-4 and RATTLE at about theirs,
/// generalized-α at 1 kHz.
const RUNS: [(Scheme, f64); 5] = [
    (Scheme::RungeKutta4, 5e-5),
    (Scheme::RungeKutta4, 2.5e-4),
    (Scheme::AdamsBashforthMoulton4, 1e-4),
    (Scheme::Rattle, 1e-4),
    (Scheme::GeneralizedAlpha, 1e-3),
];

/// Each of [`RUNS`] over 1 s (`light`: 0.05 s), best of three trials.
pub(super) fn flyball_runs(light: bool) -> Result<Vec<FlyballRun>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/suite/flyball_governor.toml");
    let case = scenario::load(&path)?.case(&path)?;
    let ex = &case.example;
    let t_end = if light { 0.05 } else { 1.0 };
    let trials = if light { 1 } else { 3 };
    RUNS.iter()
        .map(|&(scheme, h)| {
            let steps = cdyn::simulate::steps_to(t_end, h)?;
            let settings = Settings::new(scheme, h, Control::none());
            let start = || Ok(Simulation::new(&ex.model, settings, &ex.q0, &ex.v0)?);
            let (mut best, mut allocations) = (f64::INFINITY, 0);
            for _ in 0..trials {
                let (seconds, allocs) = timed_runs(1, steps, start, |s| Ok(s.step()?))
                    .map_err(|e| anyhow!("flyball, {} at h = {h}: {e}", scheme.info().name))?;
                (best, allocations) = (best.min(seconds), allocations.max(allocs));
            }
            Ok(FlyballRun {
                scheme: scheme.info().name,
                h,
                steps,
                us_per_step: best / steps as f64 * 1e6,
                ms_per_simulated_second: best / t_end * 1e3,
                allocations_per_step: allocations as f64 / steps as f64,
            })
        })
        .collect()
}
