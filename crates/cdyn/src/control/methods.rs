//! Stabilization methods by name: the flat table of keys in which scenario
//! files write a method (`geometric = "cvsgf"`, `zeta = 20.0`, …), and the
//! named cases of the paper's comparison, for `cdyn paper`, `compare`,
//! `bench` and benchmarks. A simulation itself needs only a [`Control`].

use crate::control::projection::{OnFailure, Projection};
use crate::control::{
    Control, Energy, EnergyGain, Gain, Geometric, Invariants, POSITION_WEIGHT, Rate, Velocity, baumgarte_gains,
};
use crate::error::{Error, KeyProblem, Result, non_negative};
use crate::integrate::Application;

/// A whole method by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Preset {
    /// [`robust`]: the combination the method suite shows best, with automatic gains.
    Robust,
    /// [`projection`]: exact projection onto the invariants after every step.
    Projection,
}

/// A rate as scenario files write it: a number (1/s), or `"auto"`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum RateKey {
    /// This rate.
    Value(f64),
    /// Chosen when the simulation starts ([`crate::control::gains`]).
    Auto,
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for RateKey {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = RateKey;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a number or \"auto\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> std::result::Result<RateKey, E> {
                Ok(RateKey::Value(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<RateKey, E> {
                Ok(RateKey::Value(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<RateKey, E> {
                Ok(RateKey::Value(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> std::result::Result<RateKey, E> {
                match v {
                    "auto" => Ok(RateKey::Auto),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for RateKey {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            RateKey::Value(v) => s.serialize_f64(*v),
            RateKey::Auto => s.serialize_str("auto"),
        }
    }
}

impl RateKey {
    fn rate(self, key: &'static str) -> Result<Rate> {
        Ok(match self {
            RateKey::Value(a) => Rate::Given(non_negative(key, a)?),
            RateKey::Auto => Rate::Auto,
        })
    }
}

/// The geometric control a [`MethodKeys`] names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum GeometricKind {
    /// No geometric control.
    #[default]
    None,
    /// Baumgarte's method: `alpha` and `beta`, or `omega` (and `damping_ratio`).
    Baumgarte,
    /// CVSGF: `zeta` or `alpha_g` (a number or `"auto"`).
    Cvsgf,
    /// CVSGF with the coupled gain in the kinetic-energy metric
    /// ([`Geometric::Newton`]): `alpha_g`, automatic when not given.
    Newton,
}

/// The velocity-level feedback a [`MethodKeys`] names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum VelocityKind {
    /// None.
    #[default]
    None,
    /// Gradient feedback on `Φ̇` ([`Velocity::Gradient`]): `alpha_v`, automatic when not given.
    Gradient,
}

/// The energy control a [`MethodKeys`] names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum EnergyKind {
    /// No energy control.
    #[default]
    None,
    /// Gradient feedback: `alpha_e`, or `rho_v` (and `rho_q`).
    Gradient,
    /// Baumgarte-type: `eta`.
    Baumgarte,
    /// Gradient feedback that respects the constraints ([`Energy::Projected`]):
    /// `alpha_e` (automatic when not given) and `position_weight`.
    Projected,
}

/// A stabilization method as scenario files write it: one flat table whose
/// gains are optional, so that `cdyn compare` can fill in the missing ones.
/// [`MethodKeys::control`] turns it into a [`Control`], refusing gains the
/// named methods do not use. A sweep axis is one of the gain keys.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct MethodKeys {
    /// A whole method by name: `robust` or `projection`; then only the
    /// projection's settings may be given besides.
    pub preset: Option<Preset>,
    /// `none`, `baumgarte`, `cvsgf` or `newton`.
    pub geometric: GeometricKind,
    /// `none` or `gradient`.
    pub velocity: VelocityKind,
    /// `none`, `gradient`, `baumgarte` or `projected`.
    pub energy: EnergyKind,
    /// `rhs` (the default), `forward_euler` or `backward_euler`.
    pub apply: Option<Application>,
    /// CVSGF: fixed gain `ζ`.
    pub zeta: Option<f64>,
    /// CVSGF: target rate `α_g`, `ζᵢ = α_g / (2|∇Φᵢ|²)` every step (Eq. 40);
    /// Newton: the exact rate. `"auto"` chooses it ([`crate::control::gains`]).
    pub alpha_g: Option<RateKey>,
    /// Velocity feedback: its rate `α_v`, or `"auto"`.
    pub alpha_v: Option<RateKey>,
    /// Baumgarte: `α`.
    pub alpha: Option<f64>,
    /// Baumgarte: `β`.
    pub beta: Option<f64>,
    /// Baumgarte: natural frequency `ω` (`β = ω²`).
    pub omega: Option<f64>,
    /// Baumgarte: damping ratio (`α = 2·ratio·ω`), default 1.
    pub damping_ratio: Option<f64>,
    /// Gradient energy control: target rate `α_e` (Eq. 27); projected: its
    /// rate, or `"auto"`.
    pub alpha_e: Option<RateKey>,
    /// Projected energy control: `c α_e²` (default [`POSITION_WEIGHT`]).
    pub position_weight: Option<f64>,
    /// Gradient energy control: fixed `ρ_q` (default 0, with `rho_v`).
    pub rho_q: Option<f64>,
    /// Gradient energy control: fixed `ρ_v`.
    pub rho_v: Option<f64>,
    /// Baumgarte-type energy control: `Ψ̇ + ηΨ = 0` (Eq. 19).
    pub eta: Option<f64>,
    /// Projection: tolerance on `|Φ|`, `|Φ̇|`, `|Ψ|` (default 1e-10).
    pub tolerance: Option<f64>,
    /// Projection: Newton iterations allowed per step (default 10).
    pub max_iterations: Option<u32>,
    /// Projection: `stop` (default) or `continue` when it does not converge.
    pub on_failure: Option<OnFailure>,
    /// `keep` (default): corrections keep the momenta the system keeps;
    /// `free`: the laws as written (the paper's, as published).
    pub invariants: Option<Invariants>,
}

crate::setters!(MethodKeys {
    /// With a whole method by name.
    with_preset => preset(Some): Preset,
    /// With this geometric control.
    with_geometric => geometric: GeometricKind,
    /// With this velocity-level feedback.
    with_velocity => velocity: VelocityKind,
    /// With this energy control.
    with_energy => energy: EnergyKind,
    /// With the control term integrated here.
    with_apply => apply(Some): Application,
    /// With CVSGF's fixed gain `ζ`.
    with_zeta => zeta(Some): f64,
    /// With CVSGF's or Newton's rate `α_g`.
    with_alpha_g => alpha_g(Some): RateKey,
    /// With the velocity feedback's rate `α_v`.
    with_alpha_v => alpha_v(Some): RateKey,
    /// With Baumgarte's `α`.
    with_alpha => alpha(Some): f64,
    /// With Baumgarte's `β`.
    with_beta => beta(Some): f64,
    /// With Baumgarte's natural frequency `ω`.
    with_omega => omega(Some): f64,
    /// With Baumgarte's damping ratio.
    with_damping_ratio => damping_ratio(Some): f64,
    /// With the energy control's rate `α_e`.
    with_alpha_e => alpha_e(Some): RateKey,
    /// With the projected energy control's `c α_e²`.
    with_position_weight => position_weight(Some): f64,
    /// With the gradient energy control's fixed `ρ_q`.
    with_rho_q => rho_q(Some): f64,
    /// With the gradient energy control's fixed `ρ_v`.
    with_rho_v => rho_v(Some): f64,
    /// With the Baumgarte-type energy control's `η`.
    with_eta => eta(Some): f64,
    /// With the projection's tolerance.
    with_tolerance => tolerance(Some): f64,
    /// With the projection's Newton iterations allowed per step.
    with_max_iterations => max_iterations(Some): u32,
    /// With the projection stopping or continuing when it does not converge.
    with_on_failure => on_failure(Some): OnFailure,
    /// With the corrections keeping the momenta, or free of them.
    with_invariants => invariants(Some): Invariants,
});

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
            Preset::Robust => Control { invariants, ..robust() },
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
