//! Exact projection onto the invariants, the yardstick of the stabilization
//! methods: after every step, the positions onto `Φ = 0` by Newton's method
//! (the minimum-norm correction in the kinetic-energy metric, the same code
//! that assembles initial conditions), the velocities onto
//! `Φ_q v + Φ_t = 0` (one linear step), and the energy onto `Ψ = 0` along
//! the constraint-respecting energy direction, `v` along `P v` and `q`
//! along `c P M⁻¹ Ψ_q` as robust's energy term, by Newton steps in the
//! step length, after each of which the positions are projected again.
//! Where damping is stiff against the step, `Ψ` is not projected
//! ([`Projection::energy`]).
//!
//! A multistep scheme keeps its history: each step's first evaluation is
//! taken at the projected state `x_k`, so the history holds `f` at the
//! projected states of the last steps; nothing is re-evaluated (as
//! manifold-projection callbacks of ODE libraries do).

use crate::control::held::Held;
use crate::dynamics::Dynamics;
pub use crate::dynamics::manifold::Failure;
use crate::dynamics::manifold::{Work, positions, velocities};
use crate::dynamics::momentum::Momenta;
use crate::error::{Result, positive};
use crate::linalg::mass::MassMatrix;
use crate::model::Model;

/// What to do when the projection does not converge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum OnFailure {
    /// Stop the run with [`Error::ProjectionFailed`](crate::Error::ProjectionFailed).
    #[default]
    Stop,
    /// Count the failure and go on from the state as the failed stage left
    /// it (positions not converged: the velocities are not projected either,
    /// since projecting them at such positions was measured to diverge
    /// sooner with a long step).
    Continue,
}

/// Settings of the exact projection (the `projection` method).
///
/// After every step of a pendulum by forward Euler, which alone would leave
/// the circle at once, the projection brings `|Φ|` back under its tolerance:
///
/// ```
/// use cdyn::control::projection::Projection;
/// use cdyn::{Constraint, Control, Model, Potential, Scalar, Scheme, Settings, Simulation};
///
/// struct Rod;
/// impl Constraint<2, 1> for Rod {
///     fn eval<D: Scalar>(&self, [x, y]: [D; 2], _t: D) -> [D; 1] {
///         [(x * x + y * y - 1.0) * 0.5]
///     }
/// }
/// struct Weight;
/// impl Potential<1> for Weight {
///     fn energy<D: Scalar>(&self, [y]: [D; 1]) -> D {
///         y
///     }
/// }
///
/// let model = Model::builder(vec![1.0, 1.0]).constrain(Rod, [0, 1]).potential(Weight, [1]).build()?;
/// let projection = Projection::new().with_tolerance(1e-12);
/// let control = Control::none().with_projection(Some(projection));
/// let mut sim = Simulation::new(&model, Settings::new(Scheme::Euler, 0.01, control), &[1.0, 0.0], &[0.0, 2.0])?;
/// sim.run::<cdyn::Error>(1.0, 1, |s| {
///     assert!(s.measure().phi.abs() <= 1e-12);
///     Ok(())
/// })?;
/// # Ok::<(), cdyn::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct Projection {
    /// `|Φ|` and `|Φ̇|` are brought below this, and `|Ψ|` below this times
    /// `max(1, T + |V|)` (`Ψ` is a difference of energies).
    pub tolerance: f64,
    /// Newton iterations allowed per step, for the positions and for the energy.
    pub max_iterations: u32,
    /// Stop or continue when the iterations do not converge.
    pub on_failure: OnFailure,
    /// Whether `Ψ` is projected too. A run turns it off where the damping
    /// is stiff against the step, as it leaves out robust's automatic
    /// energy term ([`STIFF_DISSIPATION_H`](crate::control::gains::STIFF_DISSIPATION_H)):
    /// there the integrated work of the dampers, which `Ψ` holds the
    /// energy to, carries more error than the state.
    pub energy: bool,
    /// How `Ψ`'s error is shared between velocities and positions: as by
    /// [`Energy::Projected`](crate::Energy::Projected), `c α_e²` with
    /// `α_e = 1/h` ([`POSITION_WEIGHT`](crate::dynamics::energy::POSITION_WEIGHT)).
    pub position_weight: f64,
}

impl Default for Projection {
    /// Tolerance 1e-10, at most 10 iterations, stop on failure, `Ψ` projected.
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 10,
            on_failure: OnFailure::Stop,
            energy: true,
            position_weight: crate::dynamics::energy::POSITION_WEIGHT,
        }
    }
}

crate::setters!(Projection {
    /// With this tolerance on `|Φ|`, `|Φ̇|` and the relative `|Ψ|`.
    with_tolerance => tolerance: f64,
    /// With at most this many Newton iterations per step.
    with_max_iterations => max_iterations: u32,
    /// Stopping or continuing when the iterations do not converge.
    with_on_failure => on_failure: OnFailure,
    /// With `Ψ` projected too, or not.
    with_energy => energy: bool,
    /// With `Ψ`'s error shared between velocities and positions by this `c α_e²`.
    with_position_weight => position_weight: f64,
});

impl Projection {
    /// The default settings ([`Projection::default`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// Checks the tolerance is positive and the iteration cap not zero.
    pub fn validate(&self) -> Result<()> {
        positive("tolerance", self.tolerance)?;
        positive("position_weight", self.position_weight)?;
        if self.max_iterations == 0 {
            return Err(crate::Error::InvalidParameter {
                name: "max_iterations",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

/// Projects `(q, v)` onto `Φ = 0`, `Φ̇ = 0` and `Ψ = T + V − E₀ − e = 0`
/// (`e0_plus_e = E₀ + e`), `|Ψ|` to the tolerance times the mechanical
/// energy's magnitude where that exceeds 1. Returns the Newton iterations taken.
#[allow(clippy::too_many_arguments)]
pub(crate) fn invariants(
    model: &Model,
    d: &mut Dynamics,
    momenta: &mut Momenta,
    held: &mut Held,
    q: &mut [f64],
    v: &mut [f64],
    t: f64,
    e0_plus_e: f64,
    h: f64,
    settings: &Projection,
    work: &mut Work,
) -> std::result::Result<u32, Failure> {
    let tol = settings.tolerance;
    let mut iterations = 0;
    let mut energy_steps = 0;
    // `Ψ` before the last energy step, and its length.
    let mut last_step: Option<(f64, f64)> = None;
    loop {
        let remaining = settings.max_iterations.saturating_sub(iterations);
        iterations += positions(model, d, q, v, t, tol, remaining.max(1), work)?;
        velocities(model, d, v, work);
        if momenta.stale() {
            momenta.update(&d.mass(model));
        }
        // The angular momenta held: restored by the velocities alone, along
        // directions the constraints and the linear momenta leave free.
        if !held.is_empty() {
            held.update(model, d, momenta, q, v, false);
            held.restore(v);
        }
        let (kinetic, potential) = (d.mass(model).kinetic(v), d.potential());
        let psi = kinetic + potential - e0_plus_e;
        // Ψ is a difference of energies: its round-off grows with them.
        let psi_tol = tol * (kinetic + potential.abs()).max(1.0);
        // With as many independent constraint rows as coordinates no motion
        // is free (a fully driven mechanism): T and V are fixed by the
        // constraints, and Ψ measures only the quadrature of Ė, which no
        // projection can change. Rows dropped as dependent do not count: the
        // Bricard mechanism has as many rows as coordinates and one degree
        // of freedom.
        if !settings.energy || psi.abs() <= psi_tol || model.m() - d.dependent_rows() >= model.n() {
            return Ok(iterations);
        }
        if energy_steps == settings.max_iterations {
            return Err(Failure::Energy { residual: psi.abs() });
        }
        energy_steps += 1;
        // Along g = (c w, P v), w = P M⁻¹ Ψ_q: the gradient of Ψ in the
        // metric |δv|²_M + |δq|²_M / c, so that each part takes the error
        // in proportion to how well it can (robust's energy direction).
        // Ψ(s) = Ψ − s (c b + a) + ½ a s² + O(s² c), a = |P v|²_M, b = |w|²_M.
        // Only velocities along `P v` would put the whole error into the
        // speed at a turning point, where `a` vanishes: a deficit of 7.5e-11 J
        // in the target became a velocity error of 2e-7 rad/s there, and
        // a phase error that grew (damped pendulum, AB-3, h = 1e-3).
        let c = settings.position_weight * h * h;
        // w = P M⁻¹ Ψ_q and P v, with one solve of both right-hand sides.
        let mass = d.mass(model);
        mass.solve(d.psi_q(), &mut work.correction);
        work.direction.copy_from_slice(v);
        d.jac_mul(model, &work.correction, &mut work.rows);
        d.jac_mul(model, v, &mut work.rows_2);
        d.solve_many(&mut [&mut work.rows, &mut work.rows_2]);
        d.add_weighted_jt_many(model, [&work.rows, &work.rows_2], [&mut work.correction, &mut work.direction]);
        // The velocities move along P_E P v, leaving the momenta the system
        // keeps as they are (P M⁻¹ Ψ_q is M-orthogonal to them already).
        momenta.project(&mut work.direction);
        let free = mass.psi_v_dot(v, |i| work.direction[i], |_| 0.0, 0.0);
        held.orthogonalize(&mut work.direction);
        let b: f64 = d.psi_q().iter().zip(&work.correction).map(|(g, w)| g * w).sum();
        let a = mass.psi_v_dot(v, |i| work.direction[i], |_| 0.0, 0.0);
        let slope = c * b + a;
        // Where every velocity that changes T changes an angular momentum
        // too (a single free body: T = ½ Lᵀ J(q)⁻¹ L at fixed q), Ψ follows
        // from the momenta held and is not projected apart from them: a
        // step of the positions alone, with the velocities then restoring
        // the momenta, moves Ψ against its predicted slope (measured: |Ψ|
        // tripled at each iteration on a free body).
        if !held.is_empty() && a <= 1e-8 * free {
            return Ok(iterations);
        }
        if slope.is_nan() || slope <= 0.0 {
            return Err(Failure::Energy { residual: psi.abs() });
        }
        // The first step: the root nearer zero of the quadratic, written
        // without cancellation (Newton's step where it has none). The next
        // ones are secant steps, with the slope the last step measured: the
        // positions' reprojection also changes the velocities the
        // constraints fix, which the slope above leaves out (a driven
        // four-bar's Newton steps overshot 2.4-fold and diverged).
        let measured = last_step.map(|(psi0, s0)| (psi0 - psi) / s0).filter(|m| m.is_finite() && *m > 0.0);
        let disc = slope * slope - 2.0 * a * psi;
        let s = match measured {
            Some(slope) => psi / slope,
            None if disc >= 0.0 => 2.0 * psi / (slope + disc.sqrt()),
            None => psi / slope,
        };
        last_step = Some((psi, s));
        for (v, g) in v.iter_mut().zip(&work.direction) {
            *v -= s * g;
        }
        // The positions moved: projected again onto Φ = 0 on the next pass.
        for (q, w) in q.iter_mut().zip(&work.correction) {
            *q -= s * c * w;
        }
    }
}
