//! Saving a simulation and going back to it: a [`Snapshot`] holds the
//! state, the step count, the scheme's history, the gains chosen, every
//! buffer a step reads and the values of the model's inputs, so that a
//! simulation restored to it repeats the steps that followed bit for bit.

use crate::error::{Error, Result};
use crate::simulate::Simulation;

/// A saved [`Simulation`] ([`Simulation::snapshot`]).
#[derive(Clone)]
pub struct Snapshot<'m> {
    simulation: Simulation<'m>,
    inputs: Vec<f64>,
}

impl<'m> Simulation<'m> {
    /// Everything needed to come back to this point of the run.
    pub fn snapshot(&self) -> Snapshot<'m> {
        let inputs = self.model().inputs().iter().map(|u| u.value()).collect();
        Snapshot { simulation: self.clone(), inputs }
    }

    /// Goes back to `snapshot`, which must be of a simulation of the same model.
    pub fn restore(&mut self, snapshot: &Snapshot<'m>) -> Result<()> {
        if !std::ptr::eq(self.model(), snapshot.simulation.model()) {
            return Err(Error::Unsupported("a snapshot restores a simulation of the model it was taken of"));
        }
        self.clone_from(&snapshot.simulation);
        snapshot.set_inputs();
        Ok(())
    }
}

impl Simulation<'_> {
    /// Puts the simulation at positions `q`, velocities `v` and `∫Ė = e`
    /// (as [`q`](Self::q), [`v`](Self::v), [`energy_input`](Self::energy_input)
    /// read them), at the same time and step; the scheme starts again
    /// from there. Nothing is projected: a state off the constraints is
    /// pulled back by the control law, as any violation is.
    pub fn set_state(&mut self, q: &[f64], v: &[f64], e: f64) -> Result<()> {
        crate::simulate::simulation::check_initial_state(self.model().n(), q, v)?;
        crate::error::finite("energy input", e)?;
        self.replace_state(q, v, e);
        Ok(())
    }
}

impl<'m> Snapshot<'m> {
    /// Steps taken when it was taken.
    pub fn steps(&self) -> u64 {
        self.simulation.steps()
    }

    /// The simulation it saved, its model's inputs set back: to go back to
    /// it from a simulation of another model ([`crate::stops`]).
    pub(crate) fn resume(&self) -> Simulation<'m> {
        self.set_inputs();
        self.simulation.clone()
    }

    fn set_inputs(&self) {
        for (u, &value) in self.simulation.model().inputs().iter().zip(&self.inputs) {
            u.set(value);
        }
    }
}
