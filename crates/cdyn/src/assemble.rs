//! Consistent initial conditions: project a user's approximate positions
//! onto `Φ(q, t) = 0` by Newton's method, then the velocities onto
//! `Φ_q v + Φ_t = 0` by a least-squares correction.
//!
//! Both corrections are the smallest in the kinetic-energy metric
//! (`Δq = −M⁻¹Φ_qᵀ(Φ_q M⁻¹Φ_qᵀ)⁻¹Φ`), which makes them independent of the
//! units mixed in `q` (lengths and angles) and reuses the factorization
//! the dynamics already need.

use crate::dynamics::{Breakdown, Dynamics};
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

/// Projects `(q, v)` at time `t` onto the constraints, to `|Φ| ≤ tolerance`.
pub fn assemble(model: &Model, q: &mut [f64], v: &mut [f64], t: f64, tolerance: f64) -> Result<Assembly> {
    const MAX_ITERATIONS: usize = 50;
    let mut d = Dynamics::new(model);
    let (q_start, v_start) = (q.to_vec(), v.to_vec());
    let mut out = Assembly::default();
    let mut correction = vec![0.0; model.n()];
    let mut rhs = vec![0.0; model.m()];
    let singular = |b: Breakdown, iteration: usize| match b {
        Breakdown::Singular(row) => Problem::SingularAssembly { row, iteration }.at(Part::Assembly),
        Breakdown::NonFinite => Problem::NonFinitePositions.at(Part::Assembly),
    };
    loop {
        d.evaluate(model, q, v, t).map_err(|b| singular(b, out.newton_iterations))?;
        let phi = max_abs(d.phi());
        if out.newton_iterations == 0 {
            out.phi_before = phi;
            out.phi_dot_before = max_abs(d.phi_dot());
        }
        if phi <= tolerance {
            out.phi_after = phi;
            break;
        }
        if out.newton_iterations == MAX_ITERATIONS || !phi.is_finite() {
            return Err(Problem::NoConvergence { phi, iterations: out.newton_iterations }.at(Part::Assembly));
        }
        rhs.copy_from_slice(d.phi());
        correction.fill(0.0);
        d.add_constraint_response(model, &mut rhs, &mut correction);
        for (q, c) in q.iter_mut().zip(&correction) {
            *q += c;
        }
        out.newton_iterations += 1;
    }
    // Φ_q v + Φ_t = Φ̇ at the assembled positions; remove it in one linear step.
    rhs.copy_from_slice(d.phi_dot());
    correction.fill(0.0);
    d.add_constraint_response(model, &mut rhs, &mut correction);
    for (v, c) in v.iter_mut().zip(&correction) {
        *v += c;
    }
    d.evaluate(model, q, v, t).map_err(|b| singular(b, out.newton_iterations))?;
    out.phi_dot_after = max_abs(d.phi_dot());
    out.max_dq = q.iter().zip(&q_start).fold(0.0, |a, (x, y)| a.max((x - y).abs()));
    out.max_dv = v.iter().zip(&v_start).fold(0.0, |a, (x, y)| a.max((x - y).abs()));
    Ok(out)
}
