//! Newton projections onto the constraint manifold — positions onto
//! `Φ = 0` with the minimum-norm correction in the kinetic-energy metric,
//! velocities onto `Φ_q v + Φ_t = 0` — shared by assembly
//! ([`crate::dynamics::assemble`]), the `projection` method ([`crate::control::projection`])
//! and the random consistent states of symmetry detection
//! ([`crate::dynamics::momentum`]).

use crate::dynamics::{Breakdown, Dynamics};
use crate::model::Model;
use crate::model::unit_vector::carry_step;

/// Why a projection did not converge.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Failure {
    /// `Φ_q M⁻¹ Φ_qᵀ` could not be factored.
    Breakdown(Breakdown, u32),
    /// The positions are still off `Φ = 0`: the worst row and its `|Φ|`.
    Positions {
        /// The worst constraint row.
        row: usize,
        /// Its `|Φ|`.
        residual: f64,
        /// Newton iterations taken.
        iterations: u32,
    },
    /// The energy is still off `Ψ = 0`.
    Energy {
        /// `|Ψ|`.
        residual: f64,
    },
}

/// Buffers of a projection: allocated once per model.
#[derive(Clone)]
pub(crate) struct Work {
    pub(crate) rows: Vec<f64>,
    /// A second right-hand side in the rows (the energy step's two projections).
    pub(crate) rows_2: Vec<f64>,
    pub(crate) correction: Vec<f64>,
    pub(crate) direction: Vec<f64>,
}

impl Work {
    pub(crate) fn new(model: &Model) -> Self {
        Self {
            rows: vec![0.0; model.m()],
            rows_2: vec![0.0; model.m()],
            correction: vec![0.0; model.n()],
            direction: vec![0.0; model.n()],
        }
    }
}

/// The row of largest `|x|`, and that value.
pub(crate) fn worst(x: &[f64]) -> (usize, f64) {
    x.iter().enumerate().fold((0, 0.0), |(r, a), (i, x)| if x.abs() > a { (i, x.abs()) } else { (r, a) })
}

/// Newton's method for `Φ(q, t) = 0` with the minimum-norm correction
/// `Δq = −M⁻¹Φ_qᵀ(Φ_q M⁻¹Φ_qᵀ)⁻¹Φ`, each carrying the unit vectors'
/// velocities along ([`crate::model::unit_vector`]). Returns the iterations taken;
/// `d` is left evaluated at the final `(q, v)`. Stops early when `|Φ|` is
/// not finite.
#[allow(clippy::too_many_arguments)]
pub(crate) fn positions(
    model: &Model,
    d: &mut Dynamics,
    q: &mut [f64],
    v: &mut [f64],
    t: f64,
    tolerance: f64,
    max_iterations: u32,
    work: &mut Work,
) -> std::result::Result<u32, Failure> {
    let mut iterations = 0;
    loop {
        d.evaluate(model, q, v, t).map_err(|b| Failure::Breakdown(b, iterations))?;
        let (row, residual) = worst(d.phi());
        if residual <= tolerance {
            return Ok(iterations);
        }
        if iterations == max_iterations || !residual.is_finite() {
            return Err(Failure::Positions { row, residual, iterations });
        }
        work.rows.copy_from_slice(d.phi());
        work.correction.fill(0.0);
        d.add_constraint_response(model, &mut work.rows, &mut work.correction);
        carry_step(model.unit_vectors(), q, &work.correction, v);
        for (q, c) in q.iter_mut().zip(&work.correction) {
            *q += c;
        }
        iterations += 1;
    }
}

/// `v −= M⁻¹Φ_qᵀ(Φ_q M⁻¹Φ_qᵀ)⁻¹Φ̇`: exact in one step, since `Φ̇` is linear in
/// `v`. `d` must be evaluated at this `(q, v)`.
pub(crate) fn velocities(model: &Model, d: &Dynamics, v: &mut [f64], work: &mut Work) {
    work.rows.copy_from_slice(d.phi_dot());
    work.correction.fill(0.0);
    d.add_constraint_response(model, &mut work.rows, &mut work.correction);
    for (v, c) in v.iter_mut().zip(&work.correction) {
        *v += c;
    }
}
