//! RATTLE (Andersen 1983): velocity Verlet with constraint forces, so that
//! `Φ = 0` holds to round-off and `Φ̇ = 0` exactly after every step.
//!
//! From `(q_k, v_k)` with `A_k = M⁻¹(G_k − Φ_qᵀλ_k)` evaluated there:
//!
//! ```text
//! v_{k+½} = v_k + h/2 M⁻¹(G_k − Φ_q(q_k)ᵀ Λ)        Λ such that Φ(q_{k+1}, t_{k+1}) = 0
//! q_{k+1} = q_k + h v_{k+½}
//! v_{k+1} = v_{k+½} + h/2 M⁻¹(G_{k+1} − Φ_q(q_{k+1})ᵀ μ)   μ such that Φ̇(q_{k+1}, v_{k+1}) = 0
//! ```
//!
//! The position step (SHAKE) starts from `Λ = λ_k`, which leaves `Φ` at
//! `O(h³)`, and corrects along the fixed directions `M⁻¹Φ_q(q_k)ᵀ` with
//! `(Φ_q M⁻¹ Φ_qᵀ)(q_k)` — the factorization the evaluation at `q_k` made —
//! in place of the exact `Φ_q(q) M⁻¹ Φ_q(q_k)ᵀ`: a quasi-Newton iteration
//! that gains a factor `O(h |v| / ℓ)` per iteration for a length scale
//! `ℓ` of the constraints, and needs `Φ` alone at each. The velocity step
//! is linear and exact in one solve with the factorization at `q_{k+1}`,
//! which the evaluation there makes for the next step as well: one
//! evaluation of the dynamics per step, as AB-3.
//!
//! Any part of `M⁻¹Φ_qᵀ(…)` in the kicks is absorbed by `Λ` and `μ`, so
//! the constrained `A` serves where RATTLE writes `M⁻¹G`. With a constant
//! `M` and forces that do not depend on `v`, this is the symplectic scheme
//! and keeps the energy within a bounded band for all time. Forces that
//! depend on `v` (dampers) and a configuration-dependent `M(q)` (whose
//! Lagrange terms depend on `v`) are evaluated at `q_{k+1}` with the
//! predicted `v_k + h A_k`, an `O(h²)` velocity that keeps the scheme of
//! order 2 and constraint-exact but not symplectic. Nonholonomic rows,
//! which have no position-level value, are held at the velocity level:
//! the position step leaves their part of the correction at zero and the
//! velocity step makes `A v + b = 0` exact.

use crate::dynamics::manifold::worst;
use crate::dynamics::{Breakdown, Dynamics};
use crate::model::Model;

/// Iterations of the position step before it gives up.
pub const MAX_ITERATIONS: u32 = 50;

/// `|Φ|` the position step aims at, relative to the largest coordinate (at
/// least 1): a few hundred units of round-off of `Φ`'s terms.
const TOLERANCE: f64 = 256.0 * f64::EPSILON;

/// `|Φ|` below which the position step stops once it no longer halves:
/// the round-off floor of `Φ` of large coordinates, far below any drift.
const FLOOR: f64 = 1e-11;

/// Why a RATTLE step failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Failure {
    /// The dynamics could not be evaluated at `q_k` or `q_{k+1}`.
    Breakdown(Breakdown, f64),
    /// The position step did not reach `Φ = 0`.
    Positions { row: usize, residual: f64, iterations: u32 },
}

/// Buffers of the steps, allocated once per model.
#[derive(Clone)]
pub(crate) struct Work {
    v_half: Vec<f64>,
    rows: Vec<f64>,
    correction: Vec<f64>,
    /// Whether the dynamics is evaluated at the current state, as the
    /// previous step leaves it (false at the start and after a projection).
    evaluated: bool,
    /// `Ė` at the state of that evaluation.
    power: f64,
}

impl Work {
    pub(crate) fn new(model: &Model) -> Self {
        Self {
            v_half: vec![0.0; model.n()],
            rows: vec![0.0; model.m()],
            correction: vec![0.0; model.n()],
            evaluated: false,
            power: 0.0,
        }
    }

    /// The dynamics no longer holds the current state's evaluation.
    pub(crate) fn forget(&mut self) {
        self.evaluated = false;
    }
}

/// One step of `(q, v, e)` from `t` to `t + h`; returns the iterations of
/// the position step and counts the evaluations of the dynamics in
/// `evaluations`. `d` is left evaluated at `q_{k+1}` (with the predicted
/// velocity) for the next step.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step(
    model: &Model,
    d: &mut Dynamics,
    q: &mut [f64],
    v: &mut [f64],
    e: &mut f64,
    t: f64,
    h: f64,
    work: &mut Work,
    evaluations: &mut u64,
) -> Result<u32, Failure> {
    if !std::mem::take(&mut work.evaluated) {
        *evaluations += 1;
        d.evaluate(model, q, v, t).map_err(|b| Failure::Breakdown(b, t))?;
        work.power = d.energy_input();
    }
    let power_start = work.power;
    // The kick and drift with Λ = λ_k; v becomes the predicted v_k + h A_k.
    for (((q, v), vh), a) in q.iter_mut().zip(v.iter_mut()).zip(&mut work.v_half).zip(d.acc()) {
        *vh = *v + 0.5 * h * a;
        *q += h * *vh;
        *v = *vh + 0.5 * h * a;
    }
    let iterations = positions(model, d, q, v, t + h, h, work)?;
    *evaluations += 1;
    d.evaluate(model, q, v, t + h).map_err(|b| Failure::Breakdown(b, t + h))?;
    // The second kick, then the velocity constraints exactly.
    for ((v, vh), a) in v.iter_mut().zip(&work.v_half).zip(d.acc()) {
        *v = vh + 0.5 * h * a;
    }
    d.jac_mul(model, v, &mut work.rows);
    for (r, phi_t) in work.rows.iter_mut().zip(d.phi_t()) {
        *r += phi_t;
    }
    work.correction.fill(0.0);
    d.add_constraint_response(model, &mut work.rows, &mut work.correction);
    for (v, c) in v.iter_mut().zip(&work.correction) {
        *v += c;
    }
    work.power = d.energy_input();
    *e += 0.5 * h * (power_start + work.power);
    work.evaluated = true;
    Ok(iterations)
}

/// SHAKE: `q −= M⁻¹Φ_q(q_k)ᵀ S(q_k)⁻¹ Φ(q, t)` until `Φ = 0`, with the
/// half-step velocity (and the predicted one in `v`) moved along.
fn positions(
    model: &Model,
    d: &Dynamics,
    q: &mut [f64],
    v: &mut [f64],
    t: f64,
    h: f64,
    work: &mut Work,
) -> Result<u32, Failure> {
    let scale = q.iter().fold(1.0_f64, |a, q| a.max(q.abs()));
    let (mut previous, mut iterations) = (f64::INFINITY, 0);
    loop {
        model.constraint_values(q, t, &mut work.rows);
        let (row, residual) = worst(&work.rows);
        let stalled = residual > 0.5 * previous && residual <= FLOOR * scale;
        if residual <= TOLERANCE * scale || stalled {
            return Ok(iterations);
        }
        if iterations == MAX_ITERATIONS || !residual.is_finite() {
            return Err(Failure::Positions { row, residual, iterations });
        }
        previous = residual;
        work.correction.fill(0.0);
        d.add_constraint_response(model, &mut work.rows, &mut work.correction);
        for (((q, v), vh), c) in q.iter_mut().zip(v.iter_mut()).zip(&mut work.v_half).zip(&work.correction) {
            *q += c;
            *vh += c / h;
            *v += c / h;
        }
        iterations += 1;
    }
}
