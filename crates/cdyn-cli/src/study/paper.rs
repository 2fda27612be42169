//! `cdyn paper`: the test of the paper's Example 1 (AB-3, h = 0.01,
//! t ∈ [0, 20], α_g = α_e = 40, Baumgarte β = 40 critically damped).

use crate::case::runner::Case;
use anyhow::Result;
use cdyn::control::methods::{MethodGains, independent_cases, redundant_cases};
use cdyn::models::{Example, PendulumParams, cartesian_pendulum, theta_pendulum};
use cdyn::{Scheme, Settings};

/// The paper's step size.
pub const H: f64 = 0.01;
/// The paper's end time.
pub const T_END: f64 = 20.0;

/// Every case of the paper's test, by name: the Cartesian pendulum under
/// each method, then the pendulum in θ without and with energy control.
pub fn cases() -> Result<Vec<Case>> {
    let gains = MethodGains::paper();
    let params = PendulumParams::default();
    type Build = fn(PendulumParams) -> cdyn::Result<cdyn::models::Example>;
    let models: [(Vec<_>, Build); 2] =
        [(redundant_cases(&gains), cartesian_pendulum), (independent_cases(&gains), theta_pendulum)];
    let mut cases = Vec::new();
    for (methods, model) in models {
        for (name, control) in methods {
            cases.push(Case {
                name: name.into(),
                // The paper's figures are plots: no frames kept for a viewer.
                example: Example { drawing: None, ..model(params)? },
                settings: Settings::new(Scheme::AdamsBashforth3, H, control),
                t_end: T_END,
                every: 1,
                assembly: None,
                row_entries: Vec::new(),
                notes: Vec::new(),
                force_entries: Vec::new(),
                limits: None,
                joint_columns: None,
                poses: None,
            });
        }
    }
    Ok(cases)
}
