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
        [psi, kinetic]: [f64; 2],
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
        // Every row vector cut to the same length, so that the row loops
        // below index them without bounds checks.
        let m = z_dot.len();
        let (phi, phi_dot, phi_t) = (&d.phi()[..m], &d.phi_dot()[..m], &d.phi_t()[..m]);
        let (z_q, y_v, y_w) = (&mut z_q[..m], &mut y_v[..m], &mut y_w[..m]);
        let energy = alpha_e > 0.0;
        let c = if energy { position_weight / (alpha_e * alpha_e) } else { 0.0 };
        let positions = c > 0.0;
        let reads_w = positions || (energy && alpha_g.is_some());
        if reads_w {
            mass.solve(d.grad_potential(), w);
        }
        // Φ_q w, read off the evaluation where it kept it. Where `w` is not
        // needed, the buffer's old values are copied below and never read.
        let phi_q_w: &[f64] = match d.kept_potential_rate() {
            Some(rate) if reads_w => &rate[..m],
            _ => {
                if reads_w {
                    d.jac_mul(w, phi_q_w);
                }
                &phi_q_w[..m]
            }
        };
        // The right-hand sides, in one pass over the rows (each pass has a
        // fixed cost that is most of a small model's): α_g Φ, Φ̇, Φ_q w, and
        // Φ_q v = Φ̇ − Φ_t, solved apart from Φ̇ only where they differ.
        let mut scleronomic = true;
        for r in 0..m {
            z_q[r] = alpha_g.map_or(0.0, |a| a * phi[r]);
            z_dot[r] = phi_dot[r];
            y_v[r] = phi_dot[r] - phi_t[r];
            scleronomic &= phi_t[r] == 0.0;
            y_w[r] = phi_q_w[r];
        }
        let separate_y_v = energy && !scleronomic;
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
        if let Some(a) = alpha_g
            && !d.unit_vectors().is_empty()
        {
            carry_rate(d.unit_vectors(), phi, z_q, a, v, u_v);
        }
        let (mut kappa, mut kappa_c) = (0.0, 0.0);
        let momenta = d.momenta();
        let split = (!momenta.is_empty()).then(|| momenta.split(v));
        let kept = split.map_or(0.0, |(_, kept)| kept);
        if energy {
            let y_v: &[f64] = if separate_y_v { y_v } else { z_dot };
            // The sums over the rows, in one pass: (Φ_q w)·z_Φ, (Φ_q v)·z_Φ̇,
            // (Φ_q v)·y_v and (Φ_q w)·y_w.
            let (mut w_z_q, mut v_z_dot, mut v_y_v, mut w_y_w) = (0.0, 0.0, 0.0, 0.0);
            for r in 0..m {
                let phi_q_v = phi_dot[r] - phi_t[r];
                w_z_q += phi_q_w[r] * z_q[r];
                v_z_dot += phi_q_v * z_dot[r];
                v_y_v += phi_q_v * y_v[r];
                w_y_w += phi_q_w[r] * y_w[r];
            }
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
                others -= w_z_q;
            }
            // vᵀM(−α_v M⁻¹Φ_qᵀ z_Φ̇) = −α_v (Φ_q v)·z_Φ̇
            others -= alpha_v * v_z_dot;
            let target = alpha_e * psi + others;
            // N = c|P M⁻¹∇V|²_M + |P_E P v|²_M, |P_E P v|²_M = vᵀMv − (Φ_q v)·y_v − pᵀ(EᵀME)⁻¹p
            // (P_E and P commute, since Φ_q E = 0).
            let whole = 2.0 * kinetic;
            let mut norm = whole - v_y_v - kept;
            if positions {
                norm += c * (dot(grad, w) - w_y_w);
            }
            // A correction is a first-order step along the gradient; where the
            // gradient is too short to reach the target without the quadratic
            // terms dominating (N < |target|/α_e: a static equilibrium, or at
            // rest at an extremum of V on the constraint surface) the gain is
            // capped so that |U| stays bounded (docs/methods.md). The test
            // multiplies instead of dividing: the common case then waits on
            // one division, not two in a row (Example 1's step is short
            // enough for that to show).
            let scale = if norm * alpha_e >= target.abs() { target / norm } else { target / (target.abs() / alpha_e) };
            let relative = momenta.is_empty() || norm > RELATIVE_REST * whole;
            if norm > REST && relative && scale.is_finite() {
                (kappa, kappa_c) = (scale, scale * c);
            }
        }
        // U_q = −M⁻¹Φ_qᵀ(α_g z_Φ − κc y_w) − κc w and U_v = −M⁻¹Φ_qᵀ(α_v z_Φ̇ − κ y_v) − κ v:
        // their weights on the rows in one pass (y_v is z_Φ̇ itself where not solved apart).
        for r in 0..m {
            if kappa_c != 0.0 {
                z_q[r] -= kappa_c * y_w[r];
            }
            z_dot[r] = if separate_y_v { alpha_v * z_dot[r] - kappa * y_v[r] } else { z_dot[r] * (alpha_v - kappa) };
        }
        if kappa_c != 0.0 {
            u_q.iter_mut().zip(w.iter()).for_each(|(u, w)| *u -= kappa_c * w);
        }
        if kappa != 0.0 {
            mass.add_inverse_psi_v(v, -kappa, u_v);
            if let Some((along, _)) = &split {
                momenta.add_directions(along, kappa, u_v);
            }
        }
        // Both products in one pass over the Jacobian.
        d.add_weighted_jt_pair([z_q, z_dot], [u_q, u_v]);
    }
}
