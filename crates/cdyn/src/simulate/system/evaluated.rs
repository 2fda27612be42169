//! One evaluation of a general model's dynamics as the control laws read
//! it ([`Evaluation`]), with its mass matrix.

use crate::control::evaluation::Evaluation;
use crate::dynamics::Dynamics;
use crate::dynamics::momentum::Momenta;
use crate::linalg::mass::MassMatrix;
use crate::model::Model;
use std::cell::Cell;

/// One evaluation of a general model, as the control laws read it, with
/// its mass matrix `M` (a kind, or [`MassAt`] where either will do).
pub(super) struct Evaluated<'a, M> {
    pub(super) model: &'a Model,
    pub(super) dynamics: &'a Dynamics,
    pub(super) mass: &'a M,
    pub(super) momenta: &'a Momenta,
    /// `A` without its constraint forces, where the evaluation left them
    /// ([`Dynamics::evaluate_but_reaction`]): the first pair of products
    /// the laws take subtracts `M⁻¹Φ_qᵀλ` from it in the same pass over the
    /// Jacobian, and takes it.
    pub(super) reaction: Cell<Option<&'a mut [f64]>>,
}

impl<'a, M> Evaluated<'a, M> {
    pub(super) fn new(model: &'a Model, dynamics: &'a Dynamics, mass: &'a M, momenta: &'a Momenta) -> Self {
        Self { model, dynamics, mass, momenta, reaction: Cell::new(None) }
    }
}

impl<M: MassMatrix> Evaluation for Evaluated<'_, M> {
    type Mass = M;
    fn mass(&self) -> &M {
        self.mass
    }
    fn phi(&self) -> &[f64] {
        self.dynamics.phi()
    }
    fn phi_dot(&self) -> &[f64] {
        self.dynamics.phi_dot()
    }
    fn grad_potential(&self) -> &[f64] {
        self.dynamics.psi_q()
    }
    fn acc(&self) -> &[f64] {
        self.dynamics.acc()
    }
    fn row(&self, r: usize) -> (&[f64], &[u32]) {
        let (pattern, range) = (self.model.pattern(), self.model.pattern().row(r));
        (&self.dynamics.jac()[range.clone()], &pattern.cols[range])
    }
    fn solve_many(&self, b: &mut [&mut [f64]]) {
        self.dynamics.solve_many(b);
    }
    fn add_weighted_jt(&self, y: &[f64], scale: f64, out: &mut [f64]) {
        self.dynamics.add_weighted_jt(self.model, y, scale, out);
    }
    fn phi_t(&self) -> &[f64] {
        self.dynamics.phi_t()
    }
    fn jac_mul(&self, x: &[f64], out: &mut [f64]) {
        self.dynamics.jac_mul(self.model, x, out);
    }
    #[inline]
    fn add_weighted_jt_pair(&self, [y0, y1]: [&[f64]; 2], [out0, out1]: [&mut [f64]; 2]) {
        let (model, dynamics) = (self.model, self.dynamics);
        match self.reaction.take() {
            Some(acc) => dynamics.add_weighted_jt_many(model, [dynamics.lambda(), y0, y1], [acc, out0, out1]),
            None => dynamics.add_weighted_jt_many(model, [y0, y1], [out0, out1]),
        }
    }
    #[inline]
    fn kept_potential_rate(&self) -> Option<&[f64]> {
        self.dynamics.potential_rate()
    }
    fn unit_vectors(&self) -> &[crate::model::unit_vector::UnitVector] {
        self.model.unit_vectors()
    }
    fn momenta(&self) -> &Momenta {
        self.momenta
    }
}
