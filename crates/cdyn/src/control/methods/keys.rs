//! The flat table of keys in which scenario files write a method
//! (`geometric = "cvsgf"`, `zeta = 20.0`, …): which laws, and their gains,
//! all optional.

use crate::control::projection::OnFailure;
use crate::control::{Invariants, Rate};
use crate::error::{Result, non_negative};
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
    pub(super) fn rate(self, key: &'static str) -> Result<Rate> {
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
