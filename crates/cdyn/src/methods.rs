//! Stabilization methods by name: the flat table of keys in which scenario
//! files write a method (`geometric = "cvsgf"`, `zeta = 20.0`, …), and the
//! named cases of the paper's comparison, for `cdyn paper`, `compare`,
//! `bench` and benchmarks. A simulation itself needs only a [`Control`].

use crate::control::{Control, Energy, EnergyGain, Gain, Geometric, baumgarte_gains};
use crate::error::{Error, KeyProblem, Result, non_negative};
use crate::integrate::Application;

/// The geometric control a [`MethodKeys`] names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum GeometricKind {
    /// No geometric control.
    #[default]
    None,
    /// Baumgarte's method: `alpha` and `beta`, or `omega` (and `damping_ratio`).
    Baumgarte,
    /// CVSGF: `zeta` or `alpha_g`.
    Cvsgf,
}

/// The energy control a [`MethodKeys`] names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum EnergyKind {
    /// No energy control.
    #[default]
    None,
    /// Gradient feedback: `alpha_e`, or `rho_v` (and `rho_q`).
    Gradient,
    /// Baumgarte-type: `eta`.
    Baumgarte,
}

/// A stabilization method as scenario files write it: one flat table whose
/// gains are optional, so that `cdyn compare` can fill in the missing ones.
/// [`MethodKeys::control`] turns it into a [`Control`], refusing gains the
/// named methods do not use. A sweep axis is one of the gain keys.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct MethodKeys {
    /// `none`, `baumgarte` or `cvsgf`.
    pub geometric: GeometricKind,
    /// `none`, `gradient` or `baumgarte`.
    pub energy: EnergyKind,
    /// `rhs`, `forward_euler` or `backward_euler`.
    pub apply: Application,
    /// CVSGF: fixed gain `ζ`.
    pub zeta: Option<f64>,
    /// CVSGF: target rate `α_g`, `ζᵢ = α_g / (2|∇Φᵢ|²)` every step (Eq. 40).
    pub alpha_g: Option<f64>,
    /// Baumgarte: `α`.
    pub alpha: Option<f64>,
    /// Baumgarte: `β`.
    pub beta: Option<f64>,
    /// Baumgarte: natural frequency `ω` (`β = ω²`).
    pub omega: Option<f64>,
    /// Baumgarte: damping ratio (`α = 2·ratio·ω`), default 1.
    pub damping_ratio: Option<f64>,
    /// Gradient energy control: target rate `α_e` (Eq. 27).
    pub alpha_e: Option<f64>,
    /// Gradient energy control: fixed `ρ_q` (default 0, with `rho_v`).
    pub rho_q: Option<f64>,
    /// Gradient energy control: fixed `ρ_v`.
    pub rho_v: Option<f64>,
    /// Baumgarte-type energy control: `Ψ̇ + ηΨ = 0` (Eq. 19).
    pub eta: Option<f64>,
}

const CVSGF: &str = "geometric = \"cvsgf\"";
const BAUMGARTE: &str = "geometric = \"baumgarte\"";
const GRADIENT: &str = "energy = \"gradient\"";
const ENERGY_BAUMGARTE: &str = "energy = \"baumgarte\"";

impl MethodKeys {
    /// The CVSGF gain given, if any: `zeta` (fixed) or `alpha_g` (rate).
    fn cvsgf_gain(&self) -> Result<Option<Gain>> {
        Ok(match (self.zeta, self.alpha_g) {
            (Some(_), Some(_)) => return Err(KeyProblem::Both("zeta", "alpha_g").into()),
            (Some(z), None) => Some(Gain::Fixed(non_negative("zeta", z)?)),
            (None, Some(a)) => Some(Gain::Rate(non_negative("alpha_g", a)?)),
            (None, None) => None,
        })
    }

    /// The gradient energy gains given, if any: `alpha_e`, or `rho_v` (and `rho_q`).
    fn energy_gain(&self) -> Result<Option<EnergyGain>> {
        Ok(match (self.alpha_e, self.rho_q, self.rho_v) {
            (Some(a), None, None) => Some(EnergyGain::Rate { alpha_e: non_negative("alpha_e", a)? }),
            (None, q, Some(v)) => Some(EnergyGain::Fixed {
                rho_q: non_negative("rho_q", q.unwrap_or(0.0))?,
                rho_v: non_negative("rho_v", v)?,
            }),
            (None, None, None) => None,
            _ => return Err(KeyProblem::Gains { method: GRADIENT, takes: TAKES_ENERGY }.into()),
        })
    }

    /// Baumgarte's `(α, β)` given, if any: `alpha` and `beta`, or `omega` (and `damping_ratio`).
    fn baumgarte_gains(&self) -> Result<Option<(f64, f64)>> {
        Ok(match (self.alpha, self.beta, self.omega, self.damping_ratio) {
            (Some(a), Some(b), None, None) => Some((non_negative("alpha", a)?, non_negative("beta", b)?)),
            (None, None, Some(w), ratio) => Some(baumgarte_gains(w, ratio.unwrap_or(1.0))?),
            (None, None, None, None) => None,
            _ => return Err(KeyProblem::Gains { method: BAUMGARTE, takes: TAKES_BAUMGARTE }.into()),
        })
    }

    /// Gains for a comparison of every method (`cdyn compare`): those given,
    /// else target rates `α_g = α_e = 0.2/h` (half the paper's `hα = 0.4`:
    /// coupled constraints raise the effective rate of CVSGF above `α_g`) and
    /// Baumgarte `β = 0.2/h`, critically damped.
    pub fn gains(&self, h: f64) -> Result<MethodGains> {
        let rate = 0.2 / h;
        let (alpha, beta) = self.baumgarte_gains()?.unwrap_or((2.0 * rate.sqrt(), rate));
        Ok(MethodGains {
            cvsgf: self.cvsgf_gain()?.unwrap_or(Gain::Rate(rate)),
            energy: self.energy_gain()?.unwrap_or(EnergyGain::Rate { alpha_e: rate }),
            baumgarte_alpha: alpha,
            baumgarte_beta: beta,
        })
    }

    /// The control law, refusing gains that the selected methods do not use.
    pub fn control(&self) -> Result<Control> {
        let unused = |key: &'static str, value: Option<f64>, used: bool, method: &'static str| {
            if value.is_some() && !used { Err(Error::from(KeyProblem::Unused { key, method })) } else { Ok(()) }
        };
        let (g, e) = (self.geometric, self.energy);
        for (key, value) in [("zeta", self.zeta), ("alpha_g", self.alpha_g)] {
            unused(key, value, g == GeometricKind::Cvsgf, CVSGF)?;
        }
        for (key, value) in
            [("alpha", self.alpha), ("beta", self.beta), ("omega", self.omega), ("damping_ratio", self.damping_ratio)]
        {
            unused(key, value, g == GeometricKind::Baumgarte, BAUMGARTE)?;
        }
        for (key, value) in [("alpha_e", self.alpha_e), ("rho_q", self.rho_q), ("rho_v", self.rho_v)] {
            unused(key, value, e == EnergyKind::Gradient, GRADIENT)?;
        }
        unused("eta", self.eta, e == EnergyKind::Baumgarte, ENERGY_BAUMGARTE)?;
        let missing = |method, takes| Error::from(KeyProblem::Gains { method, takes });
        let geometric = match g {
            GeometricKind::None => Geometric::None,
            GeometricKind::Cvsgf => {
                Geometric::Gradient(self.cvsgf_gain()?.ok_or_else(|| missing(CVSGF, "one of zeta, alpha_g"))?)
            }
            GeometricKind::Baumgarte => {
                let (alpha, beta) = self.baumgarte_gains()?.ok_or_else(|| missing(BAUMGARTE, TAKES_BAUMGARTE))?;
                Geometric::Baumgarte { alpha, beta }
            }
        };
        let energy = match e {
            EnergyKind::None => Energy::None,
            EnergyKind::Baumgarte => {
                let eta = self.eta.ok_or_else(|| missing(ENERGY_BAUMGARTE, "eta"))?;
                Energy::Baumgarte { eta: non_negative("eta", eta)? }
            }
            EnergyKind::Gradient => {
                Energy::Gradient(self.energy_gain()?.ok_or_else(|| missing(GRADIENT, TAKES_ENERGY))?)
            }
        };
        Ok(Control { geometric, energy, application: self.apply })
    }
}

const TAKES_BAUMGARTE: &str = "alpha and beta, or omega (and damping_ratio, default 1)";
const TAKES_ENERGY: &str = "alpha_e, or rho_v (and rho_q, default 0)";

/// The gains every case draws from.
#[derive(Debug, Clone, Copy, PartialEq)]
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
    let c = |geometric, energy, application| Control { geometric, energy, application };
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
