//! The named cases of the paper's comparison and of `cdyn compare` and
//! `cdyn suite`, with the gains they draw from.

use crate::control::{Control, Energy, EnergyGain, Gain, Geometric};
use crate::integrate::Application;

/// The gains every case draws from.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MethodGains {
    /// CVSGF gain: fixed `ζ` or target rate `α_g`.
    pub cvsgf: Gain,
    /// Gradient energy control gains.
    pub energy: EnergyGain,
    /// Baumgarte `α`.
    pub baumgarte_alpha: f64,
    /// Baumgarte `β`.
    pub baumgarte_beta: f64,
}

crate::setters!(MethodGains {
    /// With this CVSGF gain.
    with_cvsgf => cvsgf: Gain,
    /// With these gradient energy control gains.
    with_energy => energy: EnergyGain,
    /// With Baumgarte's `α`.
    with_baumgarte_alpha => baumgarte_alpha: f64,
    /// With Baumgarte's `β`.
    with_baumgarte_beta => baumgarte_beta: f64,
});

impl MethodGains {
    /// The paper's test: `α_g = α_e = 40` (`ζ = 20`, `ρ_v` set every step so
    /// that `2ρ_v|Ψ_v|² = 40`, `ρ_q = 0`), Baumgarte `β = 40` critically
    /// damped, `α = 2√40`.
    pub fn paper() -> Self {
        Self {
            cvsgf: Gain::Fixed(20.0),
            energy: EnergyGain::Rate { alpha_e: 40.0 },
            baumgarte_alpha: 2.0 * 40f64.sqrt(),
            baumgarte_beta: 40.0,
        }
    }

    /// The paper's proposed method with these gains: CVSGF + energy control
    /// (Eq. 51) applied by forward Euler (Eq. 58), the `cvsgf_energy` case
    /// of [`redundant_cases`]. Benchmarks time this one.
    pub fn cvsgf_energy(&self) -> Control {
        Control {
            geometric: Geometric::Gradient(self.cvsgf),
            energy: Energy::Gradient(self.energy),
            application: Application::ForwardEuler,
            ..Control::none()
        }
    }
}

/// The cases of the paper's comparison for a model in redundant
/// coordinates, by name: the four controls with the control inside the
/// right-hand side, CVSGF + energy (Eq. 51) with forward and with backward
/// Euler control.
pub fn redundant_cases(g: &MethodGains) -> Vec<(&'static str, Control)> {
    let baumgarte = Geometric::Baumgarte { alpha: g.baumgarte_alpha, beta: g.baumgarte_beta };
    let cvsgf = Geometric::Gradient(g.cvsgf);
    let energy = Energy::Gradient(g.energy);
    let c = |geometric, energy, application| Control { geometric, energy, application, ..Control::none() };
    vec![
        ("none", Control::none()),
        ("baumgarte", c(baumgarte, Energy::None, Application::InRhs)),
        ("cvsgf", c(cvsgf, Energy::None, Application::InRhs)),
        ("energy", c(Geometric::None, energy, Application::InRhs)),
        ("baumgarte_energy", c(baumgarte, energy, Application::InRhs)),
        ("cvsgf_energy", g.cvsgf_energy()),
        ("cvsgf_energy_backward", c(cvsgf, energy, Application::BackwardEuler)),
    ]
}

/// The cases for a model in independent coordinates: without and with
/// energy control (in the right-hand side, as the `energy` case).
pub fn independent_cases(g: &MethodGains) -> Vec<(&'static str, Control)> {
    vec![
        ("theta", Control::none()),
        ("theta_energy", Control { energy: Energy::Gradient(g.energy), ..Control::none() }),
    ]
}

/// The `robust` preset ([`Control::robust`]).
pub fn robust() -> Control {
    Control::robust()
}

/// The `projection` method with its default settings ([`Control::projection`]).
pub fn projection() -> Control {
    Control::projection()
}

/// The cases of `cdyn compare` and `cdyn suite`: the paper's comparison
/// ([`redundant_cases`], or [`independent_cases`] without constraints),
/// then `robust` and `projection`.
pub fn compare_cases(g: &MethodGains, constrained: bool) -> Vec<(&'static str, Control)> {
    let mut cases = if constrained { redundant_cases(g) } else { independent_cases(g) };
    cases.push(("robust", robust()));
    cases.push(("projection", projection()));
    cases
}
