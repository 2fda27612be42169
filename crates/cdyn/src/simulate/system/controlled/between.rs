//! What changes between steps from outside a run: an input
//! ([`Simulation::set_input`](crate::Simulation::set_input)), and the
//! state an impact leaves ([`crate::stops`]).

use super::ControlledSystem;
use crate::control::projection::Failure;
use crate::dynamics::momentum::Kind;
use crate::simulate::system::{System, split_state, split_state_mut};

impl ControlledSystem<'_> {
    /// Changes an input by `set` at the state `x`, time `t`; returns how much `∫Ė` must move so that `Ψ` stays (see
    /// [`Simulation::set_input`](crate::Simulation::set_input)): the jump of
    /// `V`, or where the constraints moved (a drive's target), the change
    /// of `T + V` as `(q, v)` are projected onto them at once.
    pub(crate) fn change_input(&mut self, x: &mut [f64], t: f64, set: impl FnOnce()) -> Result<f64, Failure> {
        let (model, n) = (self.model, self.model.n());
        let (q, v, _) = split_state_mut(x, n);
        let (before, after) = (&mut self.projection.rows, &mut self.projection.rows_2);
        let energy = model.kinetic(q, v) + model.potential(q, None);
        model.constraint_values(q, t, before);
        set();
        model.constraint_values(q, t, after);
        if before.iter().zip(after.iter()).all(|(a, b)| a.to_bits() == b.to_bits()) {
            return Ok(model.kinetic(q, v) + model.potential(q, None) - energy);
        }
        let tolerance = 256.0 * f64::EPSILON * q.iter().fold(1.0_f64, |a, q| a.max(q.abs()));
        let (d, work) = (&mut self.dynamics, &mut self.projection);
        crate::dynamics::manifold::positions(model, d, q, v, t, tolerance, 50, work)?;
        crate::dynamics::manifold::velocities(model, d, v, work);
        Ok(model.kinetic(q, v) + model.potential(q, None) - energy)
    }

    /// [`System::hold_from`]: `∫Ė` so that `Ψ = 0` at `x`, and the held
    /// momenta's targets their values there.
    pub(super) fn hold_at(&mut self, x: &mut [f64]) {
        let n = self.model.n();
        let (q, v, _) = split_state(x, n);
        let energy = self.model.kinetic(q, v) + self.model.potential(q, None);
        x[2 * n] = energy - self.e0;
        if !self.held.is_empty() {
            let kept = &self.symmetries.kept;
            let held: Vec<usize> = (0..kept.len()).filter(|&j| kept[j].kind != Kind::Constant).collect();
            let targets: Vec<f64> = held.into_iter().map(|j| self.momentum(j, x)).collect();
            self.held.set_targets(&targets);
        }
    }
}
