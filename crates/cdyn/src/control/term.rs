//! A complete stabilization method ([`Control`]: one law of each kind, where
//! its term is integrated, the projection) and the control term `U(x, t)`
//! it adds to the uncontrolled state equations.

use crate::control::evaluation::Evaluation;
use crate::control::held::Held;
use crate::control::laws::*;
use crate::control::projection::Projection;
use crate::error::{Result, non_negative};
use crate::integrate::Application;
use crate::linalg::mass::MassMatrix;
use crate::model::unit_vector::carry_rate;

/// A complete stabilization method: one row of the table in `equations.md`,
/// plus velocity-level feedback. Built from [`Control::none`],
/// [`Control::robust`] or [`Control::projection`] and the `with_*` setters:
///
/// ```
/// use cdyn::{Application, Control, Energy, EnergyGain, Gain, Geometric};
/// // The paper's CVSGF + energy control, Eq. 51.
/// let paper = Control::none()
///     .with_geometric(Geometric::Gradient(Gain::Rate(40.0)))
///     .with_energy(Energy::Gradient(EnergyGain::Rate { alpha_e: 40.0 }))
///     .with_application(Application::ForwardEuler);
/// assert!(paper.is_active() && paper.projection.is_none());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct Control {
    /// Control of the holonomic constraints.
    pub geometric: Geometric,
    /// Velocity-level feedback on `Φ̇`.
    pub velocity: Velocity,
    /// Control of the energy constraint.
    pub energy: Energy,
    /// Where the control term is integrated.
    pub application: Application,
    /// Exact projection onto the invariants after every step (the
    /// `projection` method), if any.
    pub projection: Option<Projection>,
    /// Whether the corrections keep the system's momenta.
    pub invariants: Invariants,
}

/// Buffers the control laws work in.
pub(crate) struct Workspace<'a> {
    /// Five vectors of length `m`.
    pub rows: [&'a mut [f64]; 5],
    /// Length `n`.
    pub w: &'a mut [f64],
    /// The invariants the projected energy law holds beside the energy,
    /// updated at this state ([`crate::control::held`]).
    pub held: Option<&'a mut Held>,
}

/// Below this `|Ψ_v|²` (or `vᵀMv`) the energy control has no direction to
/// act along — the system is at rest — and is skipped rather than divided by zero.
pub(super) const REST: f64 = 1e-30;

/// With momenta kept, the energy laws act on the kinetic energy relative
/// to them, `2T − pᵀ(EᵀME)⁻¹p`, a difference: below this fraction of `2T`
/// it is round-off (a rigid translation), and the law is skipped.
pub(super) const RELATIVE_REST: f64 = 1e-12;

crate::setters!(Control {
    /// With this control of the holonomic constraints.
    with_geometric => geometric: Geometric,
    /// With this velocity-level feedback.
    with_velocity => velocity: Velocity,
    /// With this control of the energy constraint.
    with_energy => energy: Energy,
    /// With the control term integrated here.
    with_application => application: Application,
    /// With (`Some`) or without an exact projection after every step.
    with_projection => projection: Option<Projection>,
    /// With the corrections keeping the momenta, or free of them.
    with_invariants => invariants: Invariants,
});

impl Control {
    /// No control at all (Eq. 8).
    pub fn none() -> Self {
        Self::default()
    }

    /// The `robust` preset: the combination the method suite shows best
    /// (docs/methods.md, "Choosing a method"), every rate automatic, applied
    /// after the step ([`Application::PostStep`]): CVSGF with the coupled
    /// gain, velocity feedback on `Φ̇`, and energy control that respects the
    /// constraints.
    pub fn robust() -> Self {
        Self {
            geometric: Geometric::Newton(Rate::Auto),
            velocity: Velocity::Gradient(Rate::Auto),
            energy: Energy::Projected { alpha_e: Rate::Auto, position_weight: POSITION_WEIGHT },
            application: Application::PostStep,
            projection: None,
            invariants: Invariants::Keep,
        }
    }

    /// The `projection` method with its default settings: no control
    /// terms, an exact projection onto the invariants after every step.
    pub fn projection() -> Self {
        Self { projection: Some(Projection::default()), ..Self::none() }
    }

    /// Whether its terms hold the angular momenta and declared invariants
    /// beside the energy ([`crate::control::held`]): the projected energy law, or
    /// none with the coupled geometric gain (robust with its energy term
    /// left out).
    pub(crate) fn holds_invariants(&self) -> bool {
        match self.energy {
            Energy::Projected { .. } => true,
            Energy::None => matches!(self.geometric, Geometric::Newton(_)),
            _ => false,
        }
    }

    /// Whether its terms read `Φ_q M⁻¹∇V` (the projected energy law's
    /// position part), which the dynamics then keeps from its right-hand side.
    pub(crate) fn reads_potential_rate(&self) -> bool {
        matches!(self.energy, Energy::Projected { .. })
    }

    /// Whether any control term can be non-zero.
    pub fn is_active(&self) -> bool {
        self.geometric != Geometric::None || self.velocity != Velocity::None || self.energy != Energy::None
    }

    /// Checks every gain is finite and not negative, and the projection's settings.
    pub fn validate(&self) -> Result<()> {
        if let Some(p) = &self.projection {
            p.validate()?;
        }
        match self.geometric {
            Geometric::None => {}
            Geometric::Baumgarte { alpha, beta } => {
                non_negative("alpha", alpha)?;
                non_negative("beta", beta)?;
            }
            Geometric::Gradient(Gain::Fixed(z)) => _ = non_negative("zeta", z)?,
            Geometric::Gradient(Gain::Rate(a)) | Geometric::Newton(Rate::Given(a)) => _ = non_negative("alpha_g", a)?,
            Geometric::Gradient(Gain::Auto) | Geometric::Newton(Rate::Auto) => {}
        }
        if let Velocity::Gradient(Rate::Given(a)) = self.velocity {
            non_negative("alpha_v", a)?;
        }
        match self.energy {
            Energy::None => {}
            Energy::Baumgarte { eta } => _ = non_negative("eta", eta)?,
            Energy::Gradient(EnergyGain::Fixed { rho_q, rho_v }) => {
                non_negative("rho_q", rho_q)?;
                non_negative("rho_v", rho_v)?;
            }
            Energy::Gradient(EnergyGain::Rate { alpha_e }) => _ = non_negative("alpha_e", alpha_e)?,
            Energy::Projected { alpha_e, position_weight } => {
                if let Rate::Given(a) = alpha_e {
                    non_negative("alpha_e", a)?;
                }
                non_negative("position_weight", position_weight)?;
            }
        }
        Ok(())
    }

    /// Writes the control term `U = (U_q, U_v)` at a state whose dynamics
    /// `d` were just evaluated, where `Ψ`, `T = ½vᵀMv` and `Ė` are
    /// `[psi, kinetic, e_dot]` (`T` as `Ψ` took it, not formed again).
    #[inline(always)]
    pub(crate) fn terms<E: Evaluation>(
        &self,
        d: &E,
        v: &[f64],
        [psi, kinetic, e_dot]: [f64; 3],
        u_q: &mut [f64],
        u_v: &mut [f64],
        work: Workspace<'_>,
    ) {
        let [scratch, r_v, y_v, y_w, phi_q_w] = work.rows;
        let projected = matches!(self.energy, Energy::Projected { .. });
        u_q.fill(0.0);
        u_v.fill(0.0);
        let mass = d.mass();
        match self.geometric {
            Geometric::None => {}
            Geometric::Baumgarte { alpha, beta } => {
                // A_B − A for γ_B = γ − α Φ̇ − β Φ.
                for ((b, pd), p) in scratch.iter_mut().zip(d.phi_dot()).zip(d.phi()) {
                    *b = alpha * pd + beta * p;
                }
                d.add_constraint_response(scratch, u_v);
            }
            Geometric::Gradient(gain) => {
                // U_q = −2 Φ_qᵀ Z Φ
                for (r, &phi) in d.phi().iter().enumerate() {
                    let (jac, cols) = d.row(r);
                    let s = 2.0 * gain.zeta(jac.iter().map(|j| j * j).sum()) * phi;
                    for (j, &c) in jac.iter().zip(cols) {
                        u_q[c as usize] -= s * j;
                    }
                }
            }
            // With the projected energy control, below: their solves share one pass.
            Geometric::Newton(_) if projected => {}
            Geometric::Newton(rate) => {
                // U_q = −α_g M⁻¹ Φ_qᵀ S⁻¹ Φ, and the unit vectors' velocities carried along.
                let alpha = rate.value();
                for (b, p) in scratch.iter_mut().zip(d.phi()) {
                    *b = alpha * p;
                }
                d.add_constraint_response(scratch, u_q);
                // `scratch` is now S⁻¹ α Φ.
                carry_rate(d.unit_vectors(), d.phi(), scratch, alpha, v, u_v);
            }
        }
        if let (Velocity::Gradient(rate), false) = (self.velocity, projected) {
            // U_v −= α_v M⁻¹ Φ_qᵀ S⁻¹ Φ̇, before the Baumgarte-type energy control reads U_v.
            let alpha = rate.value();
            for (b, p) in scratch.iter_mut().zip(d.phi_dot()) {
                *b = alpha * p;
            }
            d.add_constraint_response(scratch, u_v);
        }
        // What the terms so far move along the momenta is taken out before
        // the energy laws read U (a no-op where it is M-orthogonal already).
        let momenta = d.momenta();
        momenta.project(u_q);
        momenta.project(u_v);
        match self.energy {
            // Without an energy law (robust's, left out where dampers are
            // stiff) the held invariants decay at the constraints' rate: a
            // damper between bodies changes none of them.
            Energy::None => {
                if let (Some(held), Geometric::Newton(rate)) = (work.held, self.geometric)
                    && !held.is_empty()
                    && rate.value() > 0.0
                {
                    let no_energy = None::<fn(f64, f64) -> bool>;
                    held.hold(d, v, 0.0, rate.value(), 0.0, no_energy, u_q, u_v, [scratch, r_v], work.w);
                }
            }
            Energy::Gradient(gain) if !momenta.is_empty() => {
                // Along P_E Ψ_vᵀ = P_E M v, the rate law's gain set on what that
                // moves Ψ by, so that Ψ̇ = −α_e Ψ still holds.
                let w = work.w;
                mass.mul(v, w);
                momenta.project(w);
                let (rho_q, rho_v) = match gain {
                    EnergyGain::Fixed { rho_q, rho_v } => (rho_q, rho_v),
                    EnergyGain::Rate { alpha_e } => {
                        let g2 = mass.psi_v_dot(v, |i| w[i], |_| 0.0, 0.0);
                        (0.0, if g2 > REST { alpha_e / (2.0 * g2) } else { 0.0 })
                    }
                };
                if rho_q != 0.0 {
                    for (u, g) in u_q.iter_mut().zip(d.grad_potential()) {
                        *u -= 2.0 * rho_q * psi * g;
                    }
                }
                let scale = -(2.0 * rho_v * psi);
                u_v.iter_mut().zip(w.iter()).for_each(|(u, w)| *u += scale * w);
            }
            Energy::Gradient(gain) => {
                // Ψ_v = M v once: the gain and the term both read it.
                let w = work.w;
                let g2 = mass.psi_v(v, w);
                let (rho_q, rho_v) = match gain {
                    EnergyGain::Fixed { rho_q, rho_v } => (rho_q, rho_v),
                    EnergyGain::Rate { alpha_e } => (0.0, if g2 > REST { alpha_e / (2.0 * g2) } else { 0.0 }),
                };
                // U_q −= 2ρ_q Ψ Ψ_q,  U_v −= 2ρ_v Ψ Ψ_v,  Ψ_q = ∇V + ∂T/∂q, Ψ_v = M v
                if rho_q != 0.0 {
                    for (u, g) in u_q.iter_mut().zip(d.grad_potential()) {
                        *u -= 2.0 * rho_q * psi * g;
                    }
                }
                let scale = -(2.0 * rho_v * psi);
                u_v.iter_mut().zip(w.iter()).for_each(|(u, w)| *u += scale * w);
            }
            Energy::Baumgarte { eta } => {
                // μ = [Ψ_v A_geo + Ψ_q v − Ė + η Ψ] / (Ψ_v M⁻¹ Ψ_vᵀ), with
                // A_geo = A + U_v so far and Ψ_v M⁻¹ Ψ_vᵀ = vᵀ M v = 2T (Eqs. 17–19).
                // With momenta kept, μ acts along P_E v, and Ψ_v P_E v = |P_E v|²_M.
                let (along, kept) = momenta.split(v);
                let whole = 2.0 * kinetic;
                let two_t = whole - kept;
                if two_t > REST && (momenta.is_empty() || two_t > RELATIVE_REST * whole) {
                    let (acc, grad) = (d.acc(), d.grad_potential());
                    let geometric = |i: usize| acc[i] + u_v[i];
                    let num = mass.psi_v_dot(v, geometric, |i| grad[i] * v[i], eta * psi - e_dot);
                    let mu = num / two_t;
                    // U_v −= μ M⁻¹ Ψ_vᵀ   (Eq. 19)
                    mass.add_inverse_psi_v(v, -mu, u_v);
                    momenta.add_directions(&along, mu, u_v);
                }
            }
            Energy::Projected { alpha_e, position_weight } => {
                let rows = [scratch, r_v, y_v, y_w, phi_q_w];
                let (alpha_e, held) = (alpha_e.value(), work.held);
                match held.filter(|r| !r.is_empty() && alpha_e > 0.0) {
                    Some(held) => {
                        // The other terms first, then the energy and the
                        // angular momenta held together.
                        let [a, b, r2, r3, r4] = rows;
                        let others = [&mut *a, &mut *b, r2, r3, r4];
                        self.coupled_terms(d, v, [psi, kinetic], 0.0, position_weight, u_q, u_v, others, work.w);
                        let c = position_weight / (alpha_e * alpha_e);
                        let free =
                            |norm: f64, whole: f64| norm > REST && (momenta.is_empty() || norm > RELATIVE_REST * whole);
                        held.hold(d, v, psi, alpha_e, c, Some(free), u_q, u_v, [a, b], work.w);
                    }
                    None => self.coupled_terms(d, v, [psi, kinetic], alpha_e, position_weight, u_q, u_v, rows, work.w),
                }
            }
        }
        // Round-off left along the momenta by terms M-orthogonal to them in exact arithmetic.
        momenta.project(u_q);
        momenta.project(u_v);
    }
}
