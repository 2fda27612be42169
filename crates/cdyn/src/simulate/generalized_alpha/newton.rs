//! The Newton system of a step: its right-hand side and its matrix.

use super::*;

/// The Newton right-hand side at the iterate, into `w.rhs`; the dropped
/// rows' equations are `Δμ_r = 0`.
pub(super) fn residual(model: &Model, d: &Dynamics, w: &mut Work, c_q: f64, gamma_prime: f64) {
    let n = model.n();
    let (top, rows) = w.rhs.split_at_mut(n);
    d.mass(model).mul(&w.acc_new, top);
    d.add_jt(model, &w.lambda_new, top);
    for (x, g) in top.iter_mut().zip(d.force()) {
        *x = -c_q * (*x - g);
    }
    for (r, x) in rows.iter_mut().enumerate() {
        *x = if w.dropped[r] {
            0.0
        } else if w.holonomic[r] {
            -d.phi()[r]
        } else {
            -d.phi_dot()[r] / gamma_prime
        };
    }
}

/// The Newton matrix's values at the iterate, into `w.values`.
#[allow(clippy::too_many_arguments)]
pub(super) fn newton_matrix(
    model: &Model,
    d: &Dynamics,
    q: &[f64],
    v: &[f64],
    t: f64,
    c_q: f64,
    c_v: f64,
    w: &mut Work,
) {
    let (mass, rest) = w.values.split_at_mut(w.mass_entries);
    d.mass(model).entry_values(mass);
    let (elements, rest) = rest.split_at_mut(w.element_entries);
    let (forces, curvatures) = elements.split_at_mut(w.force_entries);
    model.iteration_values(q, v, t, c_q, c_v, forces);
    model.curvature_values(q, t, &w.lambda_new, c_q, curvatures);
    let nnz = model.pattern().nnz();
    let (jac, rest) = rest.split_at_mut(nnz);
    let (jac_t, zeros) = rest.split_at_mut(nnz);
    jac.copy_from_slice(d.jac());
    jac_t.copy_from_slice(d.jac());
    zeros.fill(0.0);
    // A dropped row: `Δμ_r = 0`, and no reaction `Φ_qᵀ` from it.
    if w.any_dropped {
        let pattern = model.pattern();
        for (r, _) in w.dropped.iter().enumerate().filter(|(_, d)| **d) {
            jac[pattern.row(r)].fill(0.0);
            jac_t[pattern.row(r)].fill(0.0);
            zeros[r] = 1.0;
        }
    }
}
