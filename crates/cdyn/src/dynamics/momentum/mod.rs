//! Momenta the system keeps, and corrections that leave them alone.
//!
//! A constant direction `e` in the coordinates is a symmetry when moving
//! the whole state along it changes nothing the dynamics reads: the
//! constraints (`Φ_q e = 0`, and `A e = 0` for nonholonomic rows), the
//! energy (`∇V·e = 0`, `∂T/∂q·e = 0`) and the applied and damping forces
//! (`Q·e = 0`). Its generalized momentum `p = eᵀ M v` is then conserved:
//! `d/dt (∂T/∂v·e) = ∂T/∂q·e − ∇V·e + Q·e − λᵀΦ_q e = 0`. Rigid
//! translations of a free-floating system (its linear momentum) and cyclic
//! coordinates (a sled's heading rate) are such directions.
//!
//! Where `M e` is constant (`M` constant on the coordinates `e` moves)
//! `p` is linear in the state, `dp/dt = eᵀ M f_v(x) = 0` at every state,
//! and every explicit scheme keeps it to round-off; so does `eᵀ M q − p t`
//! (the centre of mass moves on a straight line). A control term `U`
//! keeps them too exactly when `Eᵀ M U_q = 0` and `Eᵀ M U_v = 0`: it is
//! M-orthogonal to the momentum directions. `Momenta::project` applies
//! the M-orthogonal projector `P_E = I − E (EᵀME)⁻¹ EᵀM` onto that
//! complement. Since `Φ_q E = 0`, `Φ_q P_E U = Φ_q U`: projecting a
//! correction changes nothing of what it does to the constraints.
//! The energy laws move the velocities along `P_E` of their direction,
//! with their gain set on what is left (`|P_E v|²_M = 2T − pᵀ(EᵀME)⁻¹p`,
//! the kinetic energy of the motion relative to the momenta), so that `Ψ`
//! still decays at its rate (docs: "Corrections that keep the momenta").
//!
//! May import: `linalg`, `model`, `random`, and the rest of `dynamics`.

use crate::model::Model;
use crate::model::angular::Generator;

mod detect;
mod project;

pub use detect::detect;
pub(crate) use project::Momenta;
#[cfg(test)]
use project::invert;

/// The most momentum directions a run holds.
pub const MAX_MOMENTA: usize = 12;

/// Relative size below which a symmetry condition counts as met: `|r·e|`
/// against `|r| |e|` for a constraint row `r`, `|Ψ_q·e|` and `|Q·e|`
/// against `(|Ψ_q| + |Q|) |e|`.
pub const TOLERANCE: f64 = 1e-9;

/// How far a linear momentum may drift, relative to its [`Momentum::scale`],
/// and still count as kept to round-off: `10³ ε`.
pub const ROUND_OFF: f64 = 1e3 * f64::EPSILON;

pub use crate::model::Direction;

/// The most invariants a run holds beside the energy.
pub const MAX_HELD: usize = 6;

/// A momentum the system keeps, found when a run starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Momentum {
    /// Its name: the direction's, or `momentum of sled.angle` for a cyclic
    /// coordinate by its name (`momentum of coordinate i` for a model
    /// without names).
    pub name: String,
    /// The direction `e`, one entry per coordinate.
    pub direction: Vec<f64>,
    /// The cyclic coordinate it is, if it is one.
    pub coordinate: Option<usize>,
    /// Declared by the user.
    pub declared: bool,
    /// `p = eᵀ M v` is linear in the state (`M e` constant): every explicit
    /// scheme keeps it to round-off. Otherwise it drifts at the scheme's
    /// truncation error, and the controls only do not add to that.
    pub linear: bool,
    /// `|e|_M |v₀|_M`: the largest `|p|` the initial kinetic energy allows,
    /// the size against which round-off in `p` is judged.
    pub scale: f64,
    /// What it is: a constant direction's momentum, a rotation's angular
    /// momentum (`direction` is then `ξ(q₀)`), or a declared invariant
    /// (`direction` is `M⁻¹ ∂I/∂v` at the initial state).
    pub kind: Kind,
    /// Its value at the initial state.
    pub initial: f64,
}

/// What a momentum is.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Kind {
    /// `eᵀ M v` along a constant direction `e`.
    Constant,
    /// `ξ(q)ᵀ M v`, the angular momentum of a rigid rotation ([`crate::model::angular`]).
    Rotation(Generator),
    /// The model's declared invariant of this index ([`crate::model::invariant`]).
    Declared(usize),
}

/// A declared direction whose momentum the model does not keep.
#[derive(Debug, Clone, PartialEq)]
pub struct Broken {
    /// The direction's name.
    pub name: String,
    /// What breaks it, in a few words ("constraint row 3", "a force").
    pub reason: String,
    /// The direction `e`, one entry per coordinate (as [`Momentum::direction`]).
    pub direction: Vec<f64>,
    /// What it is.
    pub kind: Kind,
}

/// What [`detect`] found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Symmetries {
    /// The momenta kept, linearly independent, declared ones first.
    pub kept: Vec<Momentum>,
    /// Declared directions the model breaks (not held).
    pub broken: Vec<Broken>,
}

impl Symmetries {
    /// None found.
    pub const NONE: Symmetries = Symmetries { kept: Vec::new(), broken: Vec::new() };

    /// The direction and kind of momentum `j`: the kept ones, then the
    /// broken declared ones.
    pub fn direction(&self, j: usize) -> (&[f64], &Kind) {
        match self.kept.get(j) {
            Some(m) => (&m.direction, &m.kind),
            None => {
                let b = &self.broken[j - self.kept.len()];
                (&b.direction, &b.kind)
            }
        }
    }
}

/// `p = eᵀ M(q) v` for a dense direction `e`: exact for a constant `M`;
/// otherwise `(T(q, v + s e) − T(q, v − s e)) / 2s`, exact for a quadratic
/// `T`, with `s = |v|_M / |e|_M` so both terms are of the size of `T`.
/// `work` has `n` entries.
pub fn value(model: &Model, q: &[f64], v: &[f64], e: &[f64], work: &mut [f64]) -> f64 {
    if let Some(mass) = model.mass() {
        return mass.diagonal().iter().zip(e).zip(v).map(|((m, e), v)| m * e * v).sum();
    }
    let (tv, te) = (model.kinetic(q, v), model.kinetic(q, e));
    if te == 0.0 {
        return 0.0;
    }
    let s = if tv > 0.0 { (tv / te).sqrt() } else { 1.0 };
    let mut at = |sign: f64| {
        work.iter_mut().zip(v).zip(e).for_each(|((w, v), e)| *w = v + sign * s * e);
        model.kinetic(q, work)
    };
    (at(1.0) - at(-1.0)) / (2.0 * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_of_a_small_gram_matrix() {
        let mut a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let original = a;
        let mut inv = [0.0; 9];
        invert(&mut a, 3, &mut inv);
        for i in 0..3 {
            for j in 0..3 {
                let x: f64 = (0..3).map(|l| original[i * 3 + l] * inv[l * 3 + j]).sum();
                assert!((x - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
    }
}
