//! The control laws one can choose, as plain data: the geometric laws
//! (Eqs. 13, 19, 20–27), velocity feedback, the energy laws (Eqs. 28–40,
//! 48–53), their gains and rates, and whether they keep the momenta.

use crate::error::{Result, non_negative, positive};

/// A gain either fixed, or set at every evaluation from a target decay rate.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Gain {
    /// The gain itself (`ζ` for CVSGF).
    Fixed(f64),
    /// A target linearized decay rate (`α_g`, Eq. 40): `ζᵢ = α_g / (2|∇Φᵢ|²)`.
    Rate(f64),
    /// A rate chosen when the simulation starts (see [`crate::control::gains`]): the
    /// largest that keeps the most strongly coupled mode of the constraints
    /// inside the scheme's stability interval.
    Auto,
}

/// A target decay rate, given or chosen when the simulation starts from
/// the scheme, the step and how the control is applied (see [`crate::control::gains`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Rate {
    /// This rate (1/s).
    Given(f64),
    /// Chosen at the start of the simulation.
    Auto,
}

impl Rate {
    /// The rate; an unresolved `Auto` acts as no control.
    #[inline(always)]
    pub fn value(self) -> f64 {
        match self {
            Rate::Given(a) => a,
            Rate::Auto => 0.0,
        }
    }
}

/// Control of the holonomic constraints.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Geometric {
    /// No geometric control (Eq. 8).
    #[default]
    None,
    /// Baumgarte's `Φ̈ + α Φ̇ + β Φ = 0` (Eqs. 13, 48).
    Baumgarte {
        /// Velocity gain `α`.
        alpha: f64,
        /// Position gain `β`.
        beta: f64,
    },
    /// CVSGF: `dq/dt = v − 2 Φ_qᵀ Z Φ` (Eqs. 28, 49).
    Gradient(Gain),
    /// CVSGF in the kinetic-energy metric with the coupled gain matrix
    /// `Z = α_g (Φ_q M⁻¹ Φ_qᵀ)⁻¹`: `dq/dt = v − α_g M⁻¹ Φ_qᵀ (Φ_q M⁻¹ Φ_qᵀ)⁻¹ Φ`.
    /// It is the gradient of `½ Φᵀ Z Φ` (with `Z` frozen) in the metric `M`,
    /// so `Φ_q U_q = −α_g Φ` exactly: every constraint mode, coupled or
    /// not, decays at the rate `α_g`. One solve with the factorization of `λ`.
    /// With an Euler step and `h α_g = 1` it is one Gauss–Newton step of the
    /// minimum-norm projection that assembly does.
    Newton(Rate),
}

/// Velocity-level gradient feedback on `Φ̇ = Φ_q v + Φ_t`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Velocity {
    /// None.
    #[default]
    None,
    /// `dv/dt = … − α_v M⁻¹ Φ_qᵀ (Φ_q M⁻¹ Φ_qᵀ)⁻¹ Φ̇`: the gradient of
    /// `½ Φ̇ᵀ Z_v Φ̇` with respect to `v` in the metric `M`, with
    /// `Z_v = α_v (Φ_q M⁻¹ Φ_qᵀ)⁻¹`, so `Φ_q U_v = −α_v Φ̇` exactly. In the
    /// right-hand side it is Baumgarte's damping term `α Φ̇` alone; applied
    /// by an Euler step, next to CVSGF, it removes the equilibria off the
    /// constraint manifold that position feedback alone leaves.
    Gradient(Rate),
}

impl Gain {
    /// `ζᵢ` for a row with `|∇Φᵢ|² = g2`.
    #[inline(always)]
    pub(super) fn zeta(self, g2: f64) -> f64 {
        match self {
            Gain::Fixed(z) => z,
            Gain::Rate(alpha_g) if g2 > 0.0 => alpha_g / (2.0 * g2),
            Gain::Rate(_) | Gain::Auto => 0.0,
        }
    }
}

impl Geometric {
    /// Baumgarte gains from a natural frequency `ω` and damping ratio:
    /// `α = 2 ratio ω`, `β = ω²`. Critical damping is ratio 1.
    pub fn baumgarte_from(omega: f64, damping_ratio: f64) -> Result<Self> {
        let (alpha, beta) = baumgarte_gains(omega, damping_ratio)?;
        Ok(Geometric::Baumgarte { alpha, beta })
    }
}

/// Baumgarte's `(α, β)` from a natural frequency and damping ratio.
pub(crate) fn baumgarte_gains(omega: f64, damping_ratio: f64) -> Result<(f64, f64)> {
    let omega = positive("omega", omega)?;
    let ratio = non_negative("damping_ratio", damping_ratio)?;
    Ok((2.0 * ratio * omega, omega * omega))
}

/// Gains of the gradient energy control.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum EnergyGain {
    /// `ρ_q`, `ρ_v` as given (Eq. 20).
    Fixed {
        /// Gain `ρ_q` of the position correction along `Ψ_q`.
        rho_q: f64,
        /// Gain `ρ_v` of the velocity correction along `Ψ_v`.
        rho_v: f64,
    },
    /// `ρ_q = 0` and `ρ_v = α_e / (2|Ψ_v|²)` at every evaluation (Eqs. 27, 44).
    Rate {
        /// Target linearized decay rate `α_e` of `Ψ`.
        alpha_e: f64,
    },
}

/// Control of the energy constraint `Ψ`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Energy {
    /// No energy control.
    #[default]
    None,
    /// Baumgarte-type `Ψ̇ + η Ψ = 0` through a second multiplier (Eqs. 14–19).
    Baumgarte {
        /// Decay rate `η` of `Ψ`.
        eta: f64,
    },
    /// Steepest descent on `Ψ²` (Eqs. 20, 22, 44).
    Gradient(EnergyGain),
    /// Gradient feedback that respects the constraints (docs/methods.md, "Energy
    /// control that respects the constraints"): along `g_v = P v` and
    /// `g_q = c P M⁻¹ ∇V`, with `P = I − M⁻¹Φ_qᵀ(Φ_q M⁻¹ Φ_qᵀ)⁻¹Φ_q`, scaled
    /// so that `Ψ̇ = −α_e Ψ`. `Φ_q U_q = Φ_q U_v = 0` exactly, and the gain
    /// stays bounded when the kinetic energy passes through zero because
    /// the position part takes over there. `c = position_weight / α_e²`.
    Projected {
        /// Target decay rate `α_e` of `Ψ`.
        alpha_e: Rate,
        /// `c α_e²`, dimensionless: how early the position part takes over
        /// near a turning point. 0 gives the paper's direction (projected).
        position_weight: f64,
    },
}

/// What the corrections do to the momenta the system keeps
/// ([`crate::dynamics::momentum`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Invariants {
    /// Every correction is made M-orthogonal to the momentum directions the
    /// run finds or is told of, so that what the uncontrolled scheme keeps
    /// (a linear momentum, a cyclic rate) stays kept. Where there are none
    /// — the paper's examples — the laws are exactly as published.
    #[default]
    Keep,
    /// The corrections as the laws write them, whatever they do to the
    /// momenta: the paper's methods as published on any model.
    Free,
}

pub use crate::dynamics::energy::POSITION_WEIGHT;
