//! What a sample reports: the violations `Φ`, `Φ̇`, `Ψ` and the coupling
//! measure `Y_c` (Eq. 47), computed without factorizing anything.

use crate::constraint::ConstraintValues;
use crate::energy;
use crate::model::Model;

/// Violations at one state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Measures {
    /// The constraint value of largest magnitude, with its sign.
    pub phi: f64,
    /// The largest `|Φ̇|`.
    pub phi_dot: f64,
    /// The energy constraint `Ψ`.
    pub psi: f64,
    /// `max_i |Y_ci|`, `Y_ci = ∇_(q,v)Ψ · ∇_(q,v)Φ_i = Ψ_q · ∇Φ_i`.
    pub coupling: f64,
}

impl Measures {
    /// Takes in one constraint row: its `Φᵢ`, `Φ̇ᵢ` and `Y_ci`.
    pub(crate) fn add_row(&mut self, phi: f64, phi_dot: f64, coupling: f64) {
        if phi.abs() > self.phi.abs() {
            self.phi = phi;
        }
        self.phi_dot = self.phi_dot.max(phi_dot.abs());
        self.coupling = self.coupling.max(coupling.abs());
    }
}

/// Buffers for measuring; one per model.
pub struct Probe {
    phi: Vec<f64>,
    phi_dot: Vec<f64>,
    phi_t: Vec<f64>,
    gamma: Vec<f64>,
    jac: Vec<f64>,
    grad: Vec<f64>,
    /// The constraint pass also forms `Φ_q a − γ`; here for `a = 0`, unused.
    zeros: Vec<f64>,
    rhs: Vec<f64>,
}

impl Probe {
    pub fn new(model: &Model) -> Self {
        let m = model.m();
        Self {
            phi: vec![0.0; m],
            phi_dot: vec![0.0; m],
            phi_t: vec![0.0; m],
            gamma: vec![0.0; m],
            jac: vec![0.0; model.pattern().nnz()],
            grad: vec![0.0; model.n()],
            zeros: vec![0.0; model.n()],
            rhs: vec![0.0; m],
        }
    }

    /// Measures the violations at `(q, v, e, t)` for initial energy `e0`.
    pub fn measure(&mut self, model: &Model, q: &[f64], v: &[f64], e: f64, t: f64, e0: f64) -> Measures {
        let values = ConstraintValues {
            free_acc: &self.zeros,
            rhs: &mut self.rhs,
            phi: &mut self.phi,
            phi_dot: &mut self.phi_dot,
            phi_t: &mut self.phi_t,
            gamma: &mut self.gamma,
            jac: &mut self.jac,
        };
        model.constraints(q, v, t, values);
        self.grad.fill(0.0);
        let potential = model.potential(q, Some(&mut self.grad));
        let pattern = model.pattern();
        let mut out = Measures { psi: energy::psi(model.mass(), v, potential, e, e0), ..Measures::default() };
        for r in 0..model.m() {
            let y: f64 = pattern.row(r).map(|j| self.grad[pattern.cols[j] as usize] * self.jac[j]).sum();
            out.add_row(self.phi[r], self.phi_dot[r], y);
        }
        out
    }
}
