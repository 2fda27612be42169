//! Unit vectors among the coordinates: `x` with `|x|² = 1`, of which only
//! the direction is physical — a spatial body's Euler parameters, where
//! `p` and `s p` are the same rotation. The constraint `|x|² − 1 = 0` is a
//! row like any other; what is particular is what a correction of the
//! positions does to the velocities.
//!
//! A correction that scales `x` by `1 + ε` (the part of it along `x`)
//! scales `ẋ` by the same factor: the derivative of the scaling applied to
//! the velocity, so the rate at which the direction turns, `ẋ/|x|` across
//! `x` (for Euler parameters the angular velocity `2G(p)ṗ/|p|²`), is kept.
//! Without it, a correction that brings a drifted `|p|` back to 1 leaves
//! `ṗ` as it was and so changes the body's angular velocity by the factor
//! it removed, at every step: renormalizing the heavy top's `p` that way
//! after each AB-3 step made its motion 7.6× worse than no control, and
//! carrying `ṗ` along made it 7.5× better (`tests/spatial.rs`).
//!
//! Carried by the corrections that are cdyn's own: [`Geometric::Newton`]
//! (so `robust`) and the `projection` method, including assembly. The
//! paper's laws stay as published.
//!
//! [`Geometric::Newton`]: crate::Geometric::Newton

use crate::ad::scalar::Scalar;
use crate::model::constraint::Constraint;

/// `|x|² − 1 = 0` on `K` coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct UnitNorm;

impl<const K: usize> Constraint<K, 1> for UnitNorm {
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        [x.iter().skip(1).fold(x[0] * x[0], |sum, &x| sum + x * x) - 1.0]
    }
}

/// A unit vector of a model: its constraint row and its coordinates.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct UnitVector {
    /// The row of `|x|² − 1 = 0`.
    pub row: usize,
    /// The coordinates of `x`.
    pub coordinates: Vec<u32>,
}

/// For Newton's law, `U_q = −M⁻¹Φ_qᵀ z` with `z = S⁻¹ α Φ` (plus an
/// energy part that keeps `Φ_q U_q` unchanged): adds the velocities' share,
/// `U_v += ε ẋ` with `ε = xᵀU_q/|x|² = −α Φ / (2|x|²)` — the row's gradient
/// is `2xᵀ`, `(Φ_q U_q)_r = −α Φ_r` and `|x|² = 1 + Φ`. A row dropped as
/// dependent (`z_r = 0`: `DependentRows::Tolerate`) is not held by `U_q`, so
/// that identity does not hold for it and its unit vector is left alone.
pub(crate) fn carry_rate(units: &[UnitVector], phi: &[f64], z: &[f64], alpha: f64, v: &[f64], u_v: &mut [f64]) {
    for unit in units.iter().filter(|u| z[u.row] != 0.0) {
        let phi = phi[unit.row];
        let epsilon = -alpha * phi / (2.0 * (1.0 + phi));
        for &c in &unit.coordinates {
            u_v[c as usize] += epsilon * v[c as usize];
        }
    }
}

/// For a correction `Δq` about to be added to `q`: scales each unit
/// vector's velocities by `1 + xᵀΔx/|x|²`, the factor by which the
/// correction scales `x`.
pub(crate) fn carry_step(units: &[UnitVector], q: &[f64], correction: &[f64], v: &mut [f64]) {
    for unit in units {
        let (mut along, mut norm2) = (0.0, 0.0);
        for &c in &unit.coordinates {
            along += q[c as usize] * correction[c as usize];
            norm2 += q[c as usize] * q[c as usize];
        }
        let factor = 1.0 + along / norm2;
        for &c in &unit.coordinates {
            v[c as usize] *= factor;
        }
    }
}
