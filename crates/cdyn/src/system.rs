//! The controlled state equation `ẋ = f(x, t) + U(x, t)` of a model, with
//! the state laid out as `x = (q, v, e)`, `e = ∫Ė dτ`.

use crate::control::Control;
use crate::dynamics::{Breakdown, Dynamics, LinearSolver};
use crate::energy;
use crate::integrate::Rhs;
use crate::model::Model;

/// A failed evaluation of the right-hand side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EvalError {
    /// `Φ_q M⁻¹ Φ_qᵀ` is singular at a finite state.
    Singular { t: f64, row: usize },
    /// The state handed in was not finite.
    NonFinite { t: f64 },
}

/// Splits a state into `(q, v, e)`.
pub fn split_state(x: &[f64], n: usize) -> (&[f64], &[f64], f64) {
    (&x[..n], &x[n..2 * n], x[2 * n])
}

/// A model with a control law: the right-hand side an [`Integrator`](crate::integrate::Integrator) steps.
pub struct ControlledSystem<'m> {
    model: &'m Model,
    control: Control,
    /// The dynamics of the latest evaluation.
    pub dynamics: Dynamics,
    /// `E₀ = T₀ + V₀`
    pub e0: f64,
    scratch: Vec<f64>,
    /// Right-hand-side evaluations so far.
    pub evaluations: u64,
}

impl<'m> ControlledSystem<'m> {
    pub fn new(model: &'m Model, control: Control, e0: f64) -> Self {
        Self::with_solver(model, control, e0, LinearSolver::Auto)
    }

    /// With a chosen factorization of `Φ_q M⁻¹ Φ_qᵀ`.
    pub fn with_solver(model: &'m Model, control: Control, e0: f64, solver: LinearSolver) -> Self {
        Self {
            model,
            control,
            dynamics: Dynamics::with_solver(model, solver),
            e0,
            scratch: vec![0.0; model.m()],
            evaluations: 0,
        }
    }

    pub fn model(&self) -> &'m Model {
        self.model
    }

    pub fn control(&self) -> &Control {
        &self.control
    }
}

impl Rhs for ControlledSystem<'_> {
    type Error = EvalError;

    fn state_len(&self) -> usize {
        2 * self.model.n() + 1
    }

    fn has_control(&self) -> bool {
        self.control.is_active()
    }

    fn eval(&mut self, x: &[f64], t: f64, f: &mut [f64], u: Option<&mut [f64]>) -> Result<(), EvalError> {
        let n = self.model.n();
        let (q, v, e) = split_state(x, n);
        self.evaluations += 1;
        self.dynamics.evaluate(self.model, q, v, t).map_err(|b| match b {
            Breakdown::Singular(row) => EvalError::Singular { t, row },
            Breakdown::NonFinite => EvalError::NonFinite { t },
        })?;
        let e_dot = energy::energy_input(&self.dynamics);
        f[..n].copy_from_slice(v);
        f[n..2 * n].copy_from_slice(&self.dynamics.acc);
        f[2 * n] = e_dot;
        if let Some(u) = u {
            let psi = energy::psi(self.model, v, self.dynamics.potential, e, self.e0);
            let (u_q, rest) = u.split_at_mut(n);
            let (u_v, u_e) = rest.split_at_mut(n);
            u_e[0] = 0.0;
            self.control.terms(self.model, &self.dynamics, v, psi, e_dot, u_q, u_v, &mut self.scratch);
        }
        Ok(())
    }
}
