//! The projected energy law (`Energy::Projected`, robust's) with the other
//! terms whose gain matrix is `S⁻¹` — Newton's geometric law and the
//! velocity feedback — solved together and added to `U`.

use crate::control::evaluation::Evaluation;
use crate::control::laws::*;
use crate::control::term::{Control, RELATIVE_REST, REST};
use crate::linalg::dot;
use crate::linalg::mass::MassMatrix;
use crate::model::unit_vector::carry_rate;

impl Control {
    /// [`Energy::Projected`] with the other terms whose gain matrix is
    /// `S⁻¹` — [`Geometric::Newton`], [`Velocity::Gradient`] — added to `U`.
    /// Their right-hand sides are solved together in one pass over `L`, and
    /// each output takes one product with `M⁻¹Φ_qᵀ`, by linearity:
    ///
    /// * `U_q = −M⁻¹Φ_qᵀ(α_g z_Φ − κc y_w) − κc w`, `w = M⁻¹∇V`, and
    /// * `U_v = −M⁻¹Φ_qᵀ(α_v z_Φ̇ − κ y_v) − κ v`,
    ///
    /// with `z_x = S⁻¹x`, `y_v = S⁻¹Φ_q v`, `y_w = S⁻¹Φ_q w`: these are the
    /// laws of docs/methods.md, `P v = v − M⁻¹Φ_qᵀ y_v`, `|Pv|²_M = vᵀMv − (Φ_q v)·y_v`.
    /// Without drives (`Φ_t = 0`) `Φ_q v = Φ̇`, so `y_v = z_Φ̇` and one
    /// right-hand side is saved.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn coupled_terms<E: Evaluation>(
        &self,
        d: &E,
        v: &[f64],
        psi: f64,
        alpha_e: f64,
        position_weight: f64,
        u_q: &mut [f64],
        u_v: &mut [f64],
        [z_q, z_dot, y_v, y_w, phi_q_w]: [&mut [f64]; 5],
        w: &mut [f64],
    ) {
        let alpha_g = match self.geometric {
            Geometric::Newton(rate) => Some(rate.value()),
            _ => None,
        };
        let alpha_v = match self.velocity {
            Velocity::Gradient(rate) => rate.value(),
            Velocity::None => 0.0,
        };
        let mass = d.mass();
        let (phi_dot, phi_t) = (d.phi_dot(), d.phi_t());
        let energy = alpha_e > 0.0;
        let scleronomic = phi_t.iter().all(|&x| x == 0.0);
        // The right-hand sides in use: α_g Φ, Φ̇, and Φ_q v = Φ̇ − Φ_t where it differs from Φ̇.
        if let Some(a) = alpha_g {
            z_q.iter_mut().zip(d.phi()).for_each(|(b, p)| *b = a * p);
        }
        z_dot.copy_from_slice(phi_dot);
        let separate_y_v = energy && !scleronomic;
        if separate_y_v {
            y_v.iter_mut().zip(phi_dot).zip(phi_t).for_each(|((b, pd), pt)| *b = pd - pt);
        }
        let c = if energy { position_weight / (alpha_e * alpha_e) } else { 0.0 };
        let positions = c > 0.0;
        if positions || (energy && alpha_g.is_some()) {
            mass.solve(d.grad_potential(), w);
            d.potential_rate(w, phi_q_w);
        }
        if positions {
            y_w.copy_from_slice(phi_q_w);
        }
        {
            let mut rhs: [&mut [f64]; 4] = Default::default();
            let mut k = 0;
            for (b, used) in
                [(&mut *z_q, alpha_g.is_some()), (&mut *z_dot, true), (&mut *y_v, separate_y_v), (&mut *y_w, positions)]
            {
                if used {
                    rhs[k] = b;
                    k += 1;
                }
            }
            d.solve_many(&mut rhs[..k]);
        }
        // The unit vectors' velocities carried along by U_q (whose energy
        // part moves no unit vector's length), before the energy term
        // reads U_v.
        if let Some(a) = alpha_g {
            carry_rate(d.unit_vectors(), d.phi(), z_q, a, v, u_v);
        }
        let (mut kappa, mut kappa_c) = (0.0, 0.0);
        let momenta = d.momenta();
        let (along, kept) = momenta.split(v);
        if energy {
            let y_v: &[f64] = if separate_y_v { y_v } else { z_dot };
            let phi_q_v = |r: usize| phi_dot[r] - phi_t[r];
            let grad = d.grad_potential();
            // The rate at which the other terms change Ψ (moving q through V,
            // v through T) is cancelled too: the whole control gives Ψ̇ = −α_e Ψ.
            // U so far: CVSGF's gradient in U_q, Baumgarte's term or the
            // unit vectors' carried velocities in U_v (each pass skipped
            // where U is still zero: two passes of robust's step).
            let mut others = 0.0;
            if matches!(self.geometric, Geometric::Gradient(_)) {
                others += dot(grad, u_q);
            }
            if matches!(self.geometric, Geometric::Baumgarte { .. }) || !d.unit_vectors().is_empty() {
                others += mass.psi_v_dot(v, |i| u_v[i], |_| 0.0, 0.0);
            }
            if alpha_g.is_some() {
                // ∇V·(−M⁻¹Φ_qᵀ z_Φ) = −(Φ_q w)·z_Φ
                others -= dot(phi_q_w, z_q);
            }
            // vᵀM(−α_v M⁻¹Φ_qᵀ z_Φ̇) = −α_v (Φ_q v)·z_Φ̇
            let phi_q_v_z_dot = (0..z_dot.len()).map(|r| phi_q_v(r) * z_dot[r]).sum::<f64>();
            others -= alpha_v * phi_q_v_z_dot;
            let target = alpha_e * psi + others;
            // N = c|P M⁻¹∇V|²_M + |P_E P v|²_M, |P_E P v|²_M = vᵀMv − (Φ_q v)·y_v − pᵀ(EᵀME)⁻¹p
            // (P_E and P commute, since Φ_q E = 0).
            let whole = 2.0 * mass.kinetic(v);
            let phi_q_v_y_v =
                if separate_y_v { (0..y_v.len()).map(|r| phi_q_v(r) * y_v[r]).sum::<f64>() } else { phi_q_v_z_dot };
            let mut norm = whole - phi_q_v_y_v - kept;
            if positions {
                norm += c * (dot(grad, w) - dot(phi_q_w, y_w));
            }
            // A correction is a first-order step along the gradient; where the
            // gradient is too short to reach the target without the quadratic
            // terms dominating (N < |target|/α_e: a static equilibrium, or at
            // rest at an extremum of V on the constraint surface) the gain is
            // capped so that |U| stays bounded (docs/methods.md).
            let scale = target / norm.max(target.abs() / alpha_e);
            let relative = momenta.is_empty() || norm > RELATIVE_REST * whole;
            if norm > REST && relative && scale.is_finite() {
                (kappa, kappa_c) = (scale, scale * c);
            }
        }
        // U_q = −M⁻¹Φ_qᵀ(α_g z_Φ − κc y_w) − κc w
        if alpha_g.is_none() {
            z_q.fill(0.0);
        }
        if kappa_c != 0.0 {
            z_q.iter_mut().zip(y_w.iter()).for_each(|(z, y)| *z -= kappa_c * y);
            u_q.iter_mut().zip(w.iter()).for_each(|(u, w)| *u -= kappa_c * w);
        }
        // U_v = −M⁻¹Φ_qᵀ(α_v z_Φ̇ − κ y_v) − κ v
        if separate_y_v {
            z_dot.iter_mut().zip(y_v.iter()).for_each(|(z, y)| *z = alpha_v * *z - kappa * y);
        } else {
            // y_v is z_Φ̇ itself.
            z_dot.iter_mut().for_each(|z| *z *= alpha_v - kappa);
        }
        if kappa != 0.0 {
            mass.add_inverse_psi_v(v, -kappa, u_v);
            momenta.add_directions(&along, kappa, u_v);
        }
        // Both products in one pass over the Jacobian.
        d.add_weighted_jt_pair([z_q, z_dot], [u_q, u_v]);
    }
}
