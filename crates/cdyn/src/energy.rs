//! The energy constraint `Ψ = T + V − E₀ − ∫Ė dτ` (Eq. 14 ff.).
//!
//! `∫Ė` is carried as one extra state `e` with `de/dt = Ė`. `Ė` comes from
//! the model, not from the user: the power of the non-conservative forces,
//! plus the power that rheonomic (driving) constraints put in, `λᵀ Φ_t`
//! (the constraint force `−Φ_qᵀ λ` times `v`, with `Φ_q v = −Φ_t`). For a
//! scleronomic system `Φ_t = 0` exactly, so drift off `Φ̇ = 0` is not
//! mistaken for an energy input.

/// `Ψ(q, v, e) = T(v) + V(q) − E₀ − e` for the diagonal `mass`, with `V` evaluated elsewhere.
#[inline(always)]
pub fn psi(mass: &[f64], v: &[f64], potential: f64, e: f64, e0: f64) -> f64 {
    kinetic(mass, v) + potential - e0 - e
}

/// Kinetic energy `½ vᵀ M v` for the diagonal `mass`.
#[inline(always)]
pub fn kinetic(mass: &[f64], v: &[f64]) -> f64 {
    0.5 * mass.iter().zip(v).map(|(m, v)| m * v * v).sum::<f64>()
}

/// `Ė = F·v + λᵀ Φ_t` from its parts.
#[inline(always)]
pub fn power(force_power: f64, lambda: &[f64], phi_t: &[f64]) -> f64 {
    force_power + lambda.iter().zip(phi_t).map(|(l, p)| l * p).sum::<f64>()
}

/// `|Ψ_v|² = |M v|²` for the diagonal `mass`.
#[inline(always)]
pub fn psi_v_norm2(mass: &[f64], v: &[f64]) -> f64 {
    mass.iter().zip(v).map(|(m, v)| (m * v) * (m * v)).sum()
}
