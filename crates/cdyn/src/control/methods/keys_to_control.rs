//! A method's keys turned into a [`Control`]: the gains each named law
//! takes, the defaults of a comparison, and one-line refusals of keys the
//! named laws do not use.

use super::cases::MethodGains;
use super::keys::{EnergyKind, GeometricKind, MethodKeys, Preset, RateKey, VelocityKind};
use crate::control::projection::Projection;
use crate::control::{Control, Energy, EnergyGain, Gain, Geometric, POSITION_WEIGHT, Rate, Velocity, baumgarte_gains};
use crate::error::{Error, KeyProblem, Result, non_negative};

const CVSGF: &str = "geometric = \"cvsgf\"";
const VELOCITY: &str = "velocity = \"gradient\"";
const PROJECTED: &str = "energy = \"projected\"";
const PROJECTION: &str = "preset = \"projection\"";
const BAUMGARTE: &str = "geometric = \"baumgarte\"";
const GRADIENT: &str = "energy = \"gradient\"";
const ENERGY_BAUMGARTE: &str = "energy = \"baumgarte\"";

impl MethodKeys {
    /// The CVSGF gain given, if any: `zeta` (fixed) or `alpha_g` (rate).
    fn cvsgf_gain(&self) -> Result<Option<Gain>> {
        Ok(match (self.zeta, self.alpha_g) {
            (Some(_), Some(_)) => return Err(KeyProblem::Both("zeta", "alpha_g").into()),
            (Some(z), None) => Some(Gain::Fixed(non_negative("zeta", z)?)),
            (None, Some(RateKey::Value(a))) => Some(Gain::Rate(non_negative("alpha_g", a)?)),
            (None, Some(RateKey::Auto)) => Some(Gain::Auto),
            (None, None) => None,
        })
    }

    /// The gradient energy gains given, if any: `alpha_e`, or `rho_v` (and `rho_q`).
    fn energy_gain(&self) -> Result<Option<EnergyGain>> {
        Ok(match (self.alpha_e, self.rho_q, self.rho_v) {
            (Some(RateKey::Value(a)), None, None) => Some(EnergyGain::Rate { alpha_e: non_negative("alpha_e", a)? }),
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
        if let Some(preset) = self.preset {
            return self.preset_control(preset);
        }
        for (key, given) in [
            ("tolerance", self.tolerance.is_some()),
            ("max_iterations", self.max_iterations.is_some()),
            ("on_failure", self.on_failure.is_some()),
        ] {
            if given {
                return Err(KeyProblem::Unused { key, method: PROJECTION }.into());
            }
        }
        let unused = |key: &'static str, value: Option<f64>, used: bool, method: &'static str| {
            if value.is_some() && !used { Err(Error::from(KeyProblem::Unused { key, method })) } else { Ok(()) }
        };
        let (g, e) = (self.geometric, self.energy);
        unused("zeta", self.zeta, g == GeometricKind::Cvsgf, CVSGF)?;
        let used = matches!(g, GeometricKind::Cvsgf | GeometricKind::Newton);
        unused("alpha_g", self.alpha_g.map(|_| 0.0), used, "geometric = \"cvsgf\" or \"newton\"")?;
        unused("alpha_v", self.alpha_v.map(|_| 0.0), self.velocity == VelocityKind::Gradient, VELOCITY)?;
        unused("position_weight", self.position_weight, e == EnergyKind::Projected, PROJECTED)?;
        for (key, value) in
            [("alpha", self.alpha), ("beta", self.beta), ("omega", self.omega), ("damping_ratio", self.damping_ratio)]
        {
            unused(key, value, g == GeometricKind::Baumgarte, BAUMGARTE)?;
        }
        let used = matches!(e, EnergyKind::Gradient | EnergyKind::Projected);
        unused("alpha_e", self.alpha_e.map(|_| 0.0), used, "energy = \"gradient\" or \"projected\"")?;
        for (key, value) in [("rho_q", self.rho_q), ("rho_v", self.rho_v)] {
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
            GeometricKind::Newton => Geometric::Newton(self.alpha_g.map_or(Ok(Rate::Auto), |r| r.rate("alpha_g"))?),
        };
        let velocity = match self.velocity {
            VelocityKind::None => Velocity::None,
            VelocityKind::Gradient => Velocity::Gradient(self.alpha_v.map_or(Ok(Rate::Auto), |r| r.rate("alpha_v"))?),
        };
        let energy = match e {
            EnergyKind::None => Energy::None,
            EnergyKind::Baumgarte => {
                let eta = self.eta.ok_or_else(|| missing(ENERGY_BAUMGARTE, "eta"))?;
                Energy::Baumgarte { eta: non_negative("eta", eta)? }
            }
            EnergyKind::Gradient => {
                if self.alpha_e == Some(RateKey::Auto) {
                    return Err(KeyProblem::Gains { method: GRADIENT, takes: TAKES_ENERGY }.into());
                }
                Energy::Gradient(self.energy_gain()?.ok_or_else(|| missing(GRADIENT, TAKES_ENERGY))?)
            }
            EnergyKind::Projected => Energy::Projected {
                alpha_e: self.alpha_e.map_or(Ok(Rate::Auto), |r| r.rate("alpha_e"))?,
                position_weight: non_negative("position_weight", self.position_weight.unwrap_or(POSITION_WEIGHT))?,
            },
        };
        Ok(Control {
            geometric,
            velocity,
            energy,
            application: self.apply.unwrap_or_default(),
            projection: None,
            invariants: self.invariants.unwrap_or_default(),
        })
    }

    /// The control of a preset, refusing every key the preset sets itself.
    fn preset_control(&self, preset: Preset) -> Result<Control> {
        let name = match preset {
            Preset::Robust => "preset = \"robust\"",
            Preset::Projection => PROJECTION,
        };
        let mut keys = vec![
            ("geometric", self.geometric != GeometricKind::None),
            ("velocity", self.velocity != VelocityKind::None),
            ("energy", self.energy != EnergyKind::None),
            ("apply", self.apply.is_some()),
            ("zeta", self.zeta.is_some()),
            ("alpha_g", self.alpha_g.is_some()),
            ("alpha_v", self.alpha_v.is_some()),
            ("alpha", self.alpha.is_some()),
            ("beta", self.beta.is_some()),
            ("omega", self.omega.is_some()),
            ("damping_ratio", self.damping_ratio.is_some()),
            ("alpha_e", self.alpha_e.is_some()),
            ("position_weight", self.position_weight.is_some()),
            ("rho_q", self.rho_q.is_some()),
            ("rho_v", self.rho_v.is_some()),
            ("eta", self.eta.is_some()),
        ];
        if preset == Preset::Robust {
            keys.extend([
                ("tolerance", self.tolerance.is_some()),
                ("max_iterations", self.max_iterations.is_some()),
                ("on_failure", self.on_failure.is_some()),
            ]);
        }
        if let Some((key, _)) = keys.into_iter().find(|(_, set)| *set) {
            return Err(KeyProblem::Preset { preset: name, key }.into());
        }
        let invariants = self.invariants.unwrap_or_default();
        Ok(match preset {
            Preset::Robust => Control { invariants, ..Control::robust() },
            Preset::Projection => {
                let d = Projection::default();
                let p = Projection {
                    tolerance: self.tolerance.unwrap_or(d.tolerance),
                    max_iterations: self.max_iterations.unwrap_or(d.max_iterations),
                    on_failure: self.on_failure.unwrap_or(d.on_failure),
                    ..d
                };
                p.validate()?;
                Control { projection: Some(p), invariants, ..Control::none() }
            }
        })
    }
}

const TAKES_BAUMGARTE: &str = "alpha and beta, or omega (and damping_ratio, default 1)";
const TAKES_ENERGY: &str = "alpha_e, or rho_v (and rho_q, default 0)";
