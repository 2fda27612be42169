//! The energy constraint `Ψ = T + V − E₀ − ∫Ė dτ` (Eq. 14 ff.).
//!
//! `∫Ė` is carried as one extra state `e` with `de/dt = Ė`. `Ė` comes from
//! the model, not from the user: the power of the non-conservative forces,
//! plus the power that rheonomic (driving) constraints put in, `λᵀ Φ_t`
//! (the constraint force `−Φ_qᵀ λ` times `v`, with `Φ_q v = −Φ_t`). For a
//! scleronomic system `Φ_t = 0` exactly, so drift off `Φ̇ = 0` is not
//! mistaken for an energy input.
//!
//! The kinetic energy `T = ½ vᵀ M v` and `Ψ_v = (M v)ᵀ` are products with the
//! mass matrix, so they live with it ([`crate::linalg::mass::MassMatrix`]).

use crate::linalg::mass::MassMatrix;

/// `Ψ(q, v, e) = T(v) + V(q) − E₀ − e`, with `V` evaluated elsewhere.
#[inline(always)]
pub fn psi(mass: &impl MassMatrix, v: &[f64], potential: f64, e: f64, e0: f64) -> f64 {
    psi_from(mass.kinetic(v), potential, e, e0)
}

/// `Ψ` from the kinetic energy `T` already formed (the control laws read `T` too).
#[inline(always)]
pub fn psi_from(kinetic: f64, potential: f64, e: f64, e0: f64) -> f64 {
    kinetic + potential - e0 - e
}

/// `Ė = F·v + λᵀ Φ_t` from its parts.
#[inline(always)]
pub fn power(force_power: f64, lambda: &[f64], phi_t: &[f64]) -> f64 {
    force_power + lambda.iter().zip(phi_t).map(|(l, p)| l * p).sum::<f64>()
}

/// The default `position_weight` of [`Energy::Projected`](crate::control::Energy::Projected): `c = 16/α_e²`,
/// the suite's choice (docs/methods.md).
pub const POSITION_WEIGHT: f64 = 16.0;
