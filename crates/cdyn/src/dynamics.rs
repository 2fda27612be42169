//! What the system does, uncontrolled: `Φ`, `Φ_q`, `γ`, the multipliers
//! `λ` and the accelerations `A` (Eqs. 4–8), at one state.

use crate::constraint::ConstraintValues;
use crate::linalg::Schur;
pub use crate::linalg::{Breakdown, LinearSolver, SPARSE_FROM};
use crate::model::{Model, Pattern};

/// Workspace holding one evaluation of the dynamics. Allocated once per
/// model; `evaluate` never allocates.
pub struct Dynamics {
    /// `Φ(q, t)`
    pub phi: Vec<f64>,
    /// `Φ̇ = Φ_q v + Φ_t`
    pub phi_dot: Vec<f64>,
    /// `Φ_t`, as `Φ̇ − Φ_q v` (zero up to round-off without drives).
    pub phi_t: Vec<f64>,
    /// `γ` of Eq. 5
    pub gamma: Vec<f64>,
    /// Values of `Φ_q` in the model's [`Pattern`] order.
    pub jac: Vec<f64>,
    /// Generalized applied force `G = −∇V + F`.
    pub force: Vec<f64>,
    /// `∇V`, which is also `Ψ_q`.
    pub grad_potential: Vec<f64>,
    /// `V(q)`
    pub potential: f64,
    /// Power of the non-conservative forces, `F·v`.
    pub force_power: f64,
    /// `λ` of Eq. 7.
    pub lambda: Vec<f64>,
    /// `A = M⁻¹ (G − Φ_qᵀ λ)` of Eq. 8.
    pub acc: Vec<f64>,
    schur: Schur,
}

impl Dynamics {
    pub fn new(model: &Model) -> Self {
        Self::with_solver(model, LinearSolver::Auto)
    }

    /// With a chosen factorization of `Φ_q M⁻¹ Φ_qᵀ`.
    pub fn with_solver(model: &Model, solver: LinearSolver) -> Self {
        let (n, m) = (model.n(), model.m());
        Self {
            phi: vec![0.0; m],
            phi_dot: vec![0.0; m],
            phi_t: vec![0.0; m],
            gamma: vec![0.0; m],
            jac: vec![0.0; model.pattern().nnz()],
            force: vec![0.0; n],
            grad_potential: vec![0.0; n],
            potential: 0.0,
            force_power: 0.0,
            lambda: vec![0.0; m],
            acc: vec![0.0; n],
            schur: Schur::new(model.pattern(), model.inv_mass(), solver),
        }
    }

    /// Evaluates everything at `(q, v, t)`: constraints, forces, the
    /// factorization of `Φ_q M⁻¹ Φ_qᵀ`, `λ` and `A`.
    pub fn evaluate(&mut self, model: &Model, q: &[f64], v: &[f64], t: f64) -> Result<(), Breakdown> {
        self.grad_potential.fill(0.0);
        self.potential = model.potential(q, Some(&mut self.grad_potential));
        for (f, g) in self.force.iter_mut().zip(&self.grad_potential) {
            *f = -g;
        }
        self.force_power = model.add_forces(q, v, t, &mut self.force);
        let w = model.inv_mass();
        for ((a, f), w) in self.acc.iter_mut().zip(&self.force).zip(w) {
            *a = f * w;
        }
        // λ starts as the right-hand side of (Φ_q M⁻¹ Φ_qᵀ) λ = Φ_q M⁻¹ G − γ   (Eqs. 6–7)
        let out = ConstraintValues {
            free_acc: &self.acc,
            rhs: &mut self.lambda,
            phi: &mut self.phi,
            phi_dot: &mut self.phi_dot,
            phi_t: &mut self.phi_t,
            gamma: &mut self.gamma,
            jac: &mut self.jac,
        };
        model.constraints(q, v, t, out);
        if model.m() == 0 {
            return Ok(());
        }
        self.schur.factor_and_solve(&self.jac, &mut self.lambda)?;
        // A = M⁻¹ (G − Φ_qᵀ λ)   (Eq. 8)
        add_weighted_jt(model.pattern(), &self.jac, &self.lambda, w, -1.0, &mut self.acc);
        Ok(())
    }

    /// For a change `b` of the constraint right-hand side (`Φ_q q̈ = γ − b`),
    /// adds the resulting change of acceleration, `−M⁻¹ Φ_qᵀ S⁻¹ b`, to
    /// `out`. `b` is overwritten with the multiplier change `S⁻¹ b`.
    /// Uses the factorization of the last [`evaluate`](Self::evaluate).
    pub fn add_constraint_response(&self, model: &Model, b: &mut [f64], out: &mut [f64]) {
        self.schur.solve(b);
        add_weighted_jt(model.pattern(), &self.jac, b, model.inv_mass(), -1.0, out);
    }
}

/// `out = Φ_q x`
pub fn jac_mul(pattern: &Pattern, jac: &[f64], x: &[f64], out: &mut [f64]) {
    for (r, o) in out.iter_mut().enumerate() {
        *o = pattern.row(r).map(|j| jac[j] * x[pattern.cols[j] as usize]).sum();
    }
}

/// `out += scale · diag(weight) Φ_qᵀ y`
pub fn add_weighted_jt(pattern: &Pattern, jac: &[f64], y: &[f64], weight: &[f64], scale: f64, out: &mut [f64]) {
    for (r, &yr) in y.iter().enumerate() {
        let s = scale * yr;
        for j in pattern.row(r) {
            let c = pattern.cols[j] as usize;
            out[c] += s * weight[c] * jac[j];
        }
    }
}
