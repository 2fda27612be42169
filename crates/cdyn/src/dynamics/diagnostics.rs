//! What a sample reports: the violations `Φ`, `Φ̇`, `Ψ` and the coupling
//! measure `Y_c` (Eq. 47), computed without factorizing anything.

use crate::model::Model;
use crate::model::constraint::ConstraintBuffers;

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
    /// The measures of one state, for general and small systems alike:
    /// `psi` is `Ψ`, `grad_potential` is `Ψ_q` (`∇V + ∂T/∂q`), and constraint row `i`
    /// has `phi[i]`, `phi_dot[i]` and the entries of `Φ_q` that `row(i)`
    /// returns with their coordinates.
    pub(crate) fn of<'a>(
        psi: f64,
        grad_potential: &[f64],
        phi: &[f64],
        phi_dot: &[f64],
        row: impl Fn(usize) -> (&'a [f64], &'a [u32]),
    ) -> Self {
        let mut out = Measures { psi, ..Measures::default() };
        for (r, (&phi, &phi_dot)) in phi.iter().zip(phi_dot).enumerate() {
            let (jac, cols) = row(r);
            let coupling: f64 = jac.iter().zip(cols).map(|(j, &c)| grad_potential[c as usize] * j).sum();
            if phi.abs() > out.phi.abs() {
                out.phi = phi;
            }
            out.phi_dot = out.phi_dot.max(phi_dot.abs());
            out.coupling = out.coupling.max(coupling.abs());
        }
        out
    }
}

/// Buffers for measuring; one per model.
#[derive(Clone)]
pub struct Probe {
    /// Φ, Φ̇, Φ_t, γ and Φ_q of the last pass.
    constraints: ConstraintBuffers,
    grad: Vec<f64>,
    /// The constraint pass also forms `Φ_q a − γ`; here for `a = 0`, unused.
    zeros: Vec<f64>,
    rhs: Vec<f64>,
}

impl Probe {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let m = model.m();
        Self {
            constraints: ConstraintBuffers::new(m, model.pattern().nnz()),
            grad: vec![0.0; model.n()],
            zeros: vec![0.0; model.n()],
            rhs: vec![0.0; m],
        }
    }

    /// Measures the violations at `(q, v, e, t)` for initial energy `e0`.
    pub fn measure(&mut self, model: &Model, q: &[f64], v: &[f64], e: f64, t: f64, e0: f64) -> Measures {
        model.constraints(q, v, t, self.constraints.pass(&self.zeros, &mut self.rhs));
        self.grad.fill(0.0);
        let potential = model.potential(q, Some(&mut self.grad));
        let pattern = model.pattern();
        // Ψ_q = ∇V + ∂T/∂q (nothing added for a constant M).
        let kinetic = model.kinetic_and_gradient(q, v, Some(&mut self.grad));
        let psi = kinetic + potential - e0 - e;
        let jac = &self.constraints.jac;
        Measures::of(psi, &self.grad, &self.constraints.phi, &self.constraints.phi_dot, |r| {
            let range = pattern.row(r);
            (&jac[range.clone()], &pattern.cols[range])
        })
    }
}
