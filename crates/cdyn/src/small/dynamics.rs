//! A small system's evaluation of its dynamics in arrays: its own dual
//! passes of the constraints, the potential and the force.

use super::{SmallSystem, Whole};
use crate::linalg::Breakdown;
use crate::linalg::mass::MassMatrix;
use crate::model::constraint::local;
use crate::model::force::{Force, Potential};
use crate::simulate::system::ArrayDynamics;

impl<const N: usize, const M: usize> ArrayDynamics<N, M> {
    /// As [`Dynamics::evaluate`](crate::dynamics::Dynamics::evaluate).
    #[inline(always)]
    pub(super) fn evaluate<S: SmallSystem<N, M>>(
        &mut self,
        system: &Whole<S, N, M>,
        q: [f64; N],
        v: [f64; N],
        t: f64,
    ) -> Result<(), Breakdown> {
        let (potential, grad) = system.energy_and_gradient(q);
        let force = system.force(q, v, t);
        self.potential = potential;
        self.grad_potential = grad;
        self.force_power = (0..N).map(|i| force[i] * v[i]).sum();
        let applied: [f64; N] = std::array::from_fn(|i| force[i] - grad[i]);
        let mut acc = [0.0; N];
        self.mass.solve(&applied, &mut acc);
        let l = local(system, q, v, acc, t);
        (self.phi, self.phi_dot, self.phi_t, self.jac) = (l.phi, l.phi_dot, l.phi_t, l.jac);
        self.finish(l.rhs, acc)
    }
}
