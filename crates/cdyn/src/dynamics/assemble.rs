//! Consistent initial conditions: project a user's approximate positions
//! onto `Φ(q, t) = 0` by Newton's method, then the velocities onto
//! `Φ_q v + Φ_t = 0` by a least-squares correction.
//!
//! Both corrections are the smallest in the kinetic-energy metric
//! (`Δq = −M⁻¹Φ_qᵀ(Φ_q M⁻¹Φ_qᵀ)⁻¹Φ`), which makes them independent of the
//! units mixed in `q` (lengths and angles) and reuses the factorization
//! the dynamics already need.

use crate::dynamics::manifold::{Failure, Work, positions, velocities};
use crate::dynamics::{Breakdown, DependentRows, Dynamics};
use crate::error::{Part, Problem, Result};
use crate::model::Model;

/// What the assembly changed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Assembly {
    /// Newton iterations of the position projection.
    pub newton_iterations: usize,
    /// Largest `|Φ|` before.
    pub phi_before: f64,
    /// Largest `|Φ|` after.
    pub phi_after: f64,
    /// Largest `|Φ̇|` before.
    pub phi_dot_before: f64,
    /// Largest `|Φ̇|` after.
    pub phi_dot_after: f64,
    /// Largest change of a position.
    pub max_dq: f64,
    /// Largest change of a velocity.
    pub max_dv: f64,
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |a, x| a.max(x.abs()))
}

/// Projects `(q, v)` at time `t` onto the constraints, to `|Φ| ≤ tolerance`;
/// a dependent constraint row is an error.
pub fn assemble(model: &Model, q: &mut [f64], v: &mut [f64], t: f64, tolerance: f64) -> Result<Assembly> {
    assemble_with(model, q, v, t, tolerance, DependentRows::Error)
}

/// As [`assemble`], with dependent constraint rows handled as `dependent`
/// says: tolerated, the Newton steps and the velocity correction are the
/// basic solutions (see `DependentRows::Tolerate`).
pub fn assemble_with(
    model: &Model,
    q: &mut [f64],
    v: &mut [f64],
    t: f64,
    tolerance: f64,
    dependent: DependentRows,
) -> Result<Assembly> {
    const MAX_ITERATIONS: u32 = 50;
    let mut d = Dynamics::new(model);
    d.set_dependent_rows(dependent);
    let (q_start, v_start) = (q.to_vec(), v.to_vec());
    let mut out = Assembly::default();
    let mut work = Work::new(model);
    d.evaluate(model, q, v, t).map_err(|b| singular(b, 0))?;
    out.phi_before = max_abs(d.phi());
    out.phi_dot_before = max_abs(d.phi_dot());
    let iterations = positions(model, &mut d, q, v, t, tolerance, MAX_ITERATIONS, &mut work).map_err(|f| match f {
        Failure::Breakdown(b, iteration) => singular(b, iteration),
        Failure::Positions { residual, iterations, .. } => {
            Problem::NoConvergence { phi: residual, iterations: iterations as usize }.at(Part::Assembly)
        }
        // Not met: assembly does not project the energy.
        Failure::Energy { residual } => Problem::NoConvergence { phi: residual, iterations: 0 }.at(Part::Assembly),
    })?;
    out.newton_iterations = iterations as usize;
    out.phi_after = max_abs(d.phi());
    // Φ_q v + Φ_t = Φ̇ at the assembled positions; remove it in one linear step.
    velocities(model, &d, v, &mut work);
    d.evaluate(model, q, v, t).map_err(|b| singular(b, out.newton_iterations as u32))?;
    out.phi_dot_after = max_abs(d.phi_dot());
    out.max_dq = q.iter().zip(&q_start).fold(0.0, |a, (x, y)| a.max((x - y).abs()));
    out.max_dv = v.iter().zip(&v_start).fold(0.0, |a, (x, y)| a.max((x - y).abs()));
    Ok(out)
}

fn singular(b: Breakdown, iteration: u32) -> crate::Error {
    match b {
        Breakdown::Singular(row) => Problem::SingularAssembly { row, iteration: iteration as usize }.at(Part::Assembly),
        Breakdown::NonFinite => Problem::NonFinitePositions.at(Part::Assembly),
        Breakdown::Mass(coordinate) => Problem::MassNotPositive { coordinate }.at(Part::Assembly),
    }
}
